// From a pose file's groups to rigid handles of one cage and transfer mesh, and the posed cage.
#include "repose/mesh/TetAdjacency.h"
#include "repose/cage/ArapDeformer.h"
#include "repose/pose/Pose.h"
#include "repose/util/Error.h"

#include <algorithm>
#include <array>
#include <limits>
#include <map>
#include <set>

namespace repose {
namespace {

// Per cage vertex: the body part of the nearest TM surface vertex (the most common label of
// the tets around it), so "select the forearm's cage vertices" means the cage over the forearm.
std::vector<int> cageVertexParts(const TriangleMesh& cage, const TransferMesh& mesh) {
  const std::vector<char> surface = surfaceVertices(mesh);
  std::vector<std::map<int, int>> labelsAround(mesh.vertices.rows());
  for (Eigen::Index t = 0; t < mesh.tets.rows(); ++t)
    for (int k = 0; k < 4; ++k)
      if (surface[mesh.tets(t, k)]) ++labelsAround[mesh.tets(t, k)][mesh.labels[t]];
  std::vector<int> part(cage.vertices.rows(), 0);
  for (Eigen::Index c = 0; c < cage.vertices.rows(); ++c) {
    double best = std::numeric_limits<double>::max();
    Eigen::Index nearest = -1;
    for (Eigen::Index v = 0; v < mesh.vertices.rows(); ++v) {
      if (!surface[v]) continue;
      const double d = (mesh.vertices.row(v) - cage.vertices.row(c)).squaredNorm();
      if (d < best) best = d, nearest = v;
    }
    if (nearest < 0) continue;
    int count = 0;
    for (const auto& [label, n] : labelsAround[nearest])
      if (n > count) count = n, part[c] = label;
  }
  return part;
}

int partLabel(const LabelTable& partLabels, const std::string& name, const std::string& where) {
  for (const Label& l : partLabels.labels())
    if (l.name == name) return l.value;
  throw Error(where + ": no body part named \"" + name + "\" in S's label table");
}

}  // namespace

std::vector<LimbSeparation> resolveSeparations(const Pose& pose, const LabelTable& partLabels) {
  std::vector<LimbSeparation> out;
  for (std::size_t i = 0; i < pose.separations.size(); ++i) {
    const PoseSeparation& s = pose.separations[i];
    int label[2];
    for (int k = 0; k < 2; ++k)
      label[k] = s.partNames[k].empty() ? s.parts[k]
                                        : partLabel(partLabels, s.partNames[k],
                                                    "pose separation " + std::to_string(i));
    out.push_back({label[0], label[1], s.region});
  }
  return out;
}

bool sameHandleGroups(const Pose& a, const Pose& b) {
  auto sameRegion = [](const std::optional<Region>& x, const std::optional<Region>& y) {
    if (x.has_value() != y.has_value()) return false;
    return !x || (x->shape == y->shape && x->a == y->a && x->b == y->b);
  };
  return a.groups.size() == b.groups.size() &&
         std::equal(a.groups.begin(), a.groups.end(), b.groups.begin(),
                    [&](const PoseGroup& x, const PoseGroup& y) {
                      return x.name == y.name && x.fixed == y.fixed &&
                             x.select.cageVertices == y.select.cageVertices &&
                             sameRegion(x.select.region, y.select.region) &&
                             x.select.parts == y.select.parts &&
                             x.select.partNames == y.select.partNames &&
                             x.select.rest == y.select.rest;
                    });
}

std::vector<RigidHandle> resolveHandles(const Pose& pose, const TriangleMesh& cage,
                                        const TransferMesh& mesh, const LabelTable& partLabels) {
  const Eigen::Index nc = cage.vertices.rows();
  std::vector<RigidHandle> handles(pose.groups.size());
  std::vector<int> owner(nc, -1);
  std::vector<int> vertexPart;  // computed on the first part selection
  std::set<int> claimedParts;
  std::set<int> meshParts(mesh.labels.data(), mesh.labels.data() + mesh.labels.size());
  int restGroup = -1;
  auto claim = [&](std::size_t g, int v) {
    if (owner[v] >= 0 && owner[v] != int(g))
      throw Error("pose groups \"" + pose.groups[owner[v]].name + "\" and \"" +
                  pose.groups[g].name + "\" both select cage vertex " + std::to_string(v));
    owner[v] = int(g);
  };
  for (std::size_t g = 0; g < pose.groups.size(); ++g) {
    const PoseSelection& s = pose.groups[g].select;
    if (s.rest) {
      restGroup = int(g);
      continue;
    }
    for (const int v : s.cageVertices) {
      if (v >= nc)
        throw Error("pose group \"" + pose.groups[g].name + "\": cage vertex " + std::to_string(v) +
                    " out of range (the cage has " + std::to_string(nc) + ")");
      claim(g, v);
    }
    if (s.region)
      for (Eigen::Index v = 0; v < nc; ++v)
        if (s.region->contains(cage.vertices.row(v).transpose())) claim(g, int(v));
    std::vector<int> parts = s.parts;
    for (const std::string& name : s.partNames)
      parts.push_back(partLabel(partLabels, name, "pose group \"" + pose.groups[g].name + "\""));
    // A part too small to have tets of its own is carried by its neighbours' tets.
    for (const int p : parts) {
      claimedParts.insert(p);
    }
    if (!parts.empty()) {
      if (vertexPart.empty()) vertexPart = cageVertexParts(cage, mesh);
      for (Eigen::Index v = 0; v < nc; ++v)
        if (std::find(parts.begin(), parts.end(), vertexPart[v]) != parts.end()) claim(g, int(v));
    }
    handles[g].parts = parts;
    handles[g].widen = pose.groups[g].widen;
  }
  if (restGroup >= 0) {
    for (Eigen::Index v = 0; v < nc; ++v)
      if (owner[v] < 0) owner[v] = restGroup;
    // The rest owns the unclaimed parts only when every other group is a set of parts: beside a
    // group decided by the cage it must be decided by the cage too, or it would own that
    // group's tissue as well.
    const bool allByParts = std::all_of(handles.begin(), handles.end(), [&](const RigidHandle& h) {
      return &h == &handles[restGroup] || !h.parts.empty();
    });
    if (allByParts)
      for (const int p : meshParts)
        if (!claimedParts.count(p)) handles[restGroup].parts.push_back(p);
  }
  for (Eigen::Index v = 0; v < nc; ++v)
    if (owner[v] >= 0) handles[owner[v]].cageVertices.push_back(int(v));
  for (std::size_t g = 0; g < handles.size(); ++g)
    if (handles[g].cageVertices.empty())
      throw Error("pose group \"" + pose.groups[g].name + "\" selects no cage vertex");
  return handles;
}

void setMotions(std::vector<RigidHandle>& handles, const std::vector<Eigen::Isometry3d>& motions) {
  if (motions.size() != handles.size()) throw Error("one motion per handle group is needed");
  for (std::size_t g = 0; g < handles.size(); ++g) handles[g].motion = motions[g];
}

Eigen::MatrixX3d poseCage(const TriangleMesh& cage, const std::vector<RigidHandle>& handles) {
  Eigen::MatrixX3d moved = moveHandles(cage.vertices, handles);
  std::vector<int> fixedVertices;
  for (const RigidHandle& h : handles)
    fixedVertices.insert(fixedVertices.end(), h.cageVertices.begin(), h.cageVertices.end());
  if (fixedVertices.empty()) throw Error("a pose needs at least one handle vertex");
  if (Eigen::Index(fixedVertices.size()) == cage.vertices.rows()) return moved;
  // Free cage vertices follow as rigidly as possible (the seed's coarse scale).
  ArapDeformer arap(cage);
  arap.setHandles(fixedVertices);
  Eigen::MatrixX3d targets(fixedVertices.size(), 3);
  for (std::size_t i = 0; i < fixedVertices.size(); ++i)
    targets.row(Eigen::Index(i)) = moved.row(fixedVertices[i]);
  return arap.solve(targets).positions;
}

}  // namespace repose
