#include "repose/pose/PoseRig.h"

#include "repose/cage/ArapDeformer.h"
#include "repose/mesh/RigidHandles.h"
#include "repose/mesh/VolumeRestoration.h"
#include "repose/pose/EncasedTissue.h"
#include "repose/util/Error.h"

#include <Eigen/LU>
#include <cstdio>
#include <cstdlib>

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <mutex>
#include <optional>
#include <set>

namespace repose {

namespace {
// labelsMovingWhole, with the encased labels among them apart (`encased`, sorted).
std::vector<int> wholeLabels(const Volume& organs, const Volume& parts, const RigSettings& settings,
                             std::vector<int>& encased) {
  if (organs.dims() != parts.dims())
    throw Error("the label map is not on the grid of the body-part map");
  std::set<int> whole(settings.rigidLabels.begin(), settings.rigidLabels.end());
  if (settings.wholeOrgans) {
    // Voxels of each label of G per body part of S, and how many of them face another part.
    std::map<int, std::map<int, std::int64_t>> counts;
    std::map<int, std::int64_t> atBorder;
    const auto& d = organs.dims();
    const std::int64_t step[3] = {1, d[0], d[0] * d[1]};
    for (std::int64_t k = 0; k < d[2]; ++k)
      for (std::int64_t j = 0; j < d[1]; ++j)
        for (std::int64_t i = 0; i < d[0]; ++i) {
          const std::int64_t at = organs.index(i, j, k);
          const double label = organs.valueAsDouble(at), part = parts.valueAsDouble(at);
          if (!(label > 0 && part > 0)) continue;
          ++counts[int(label)][int(part)];
          const std::int64_t ijk[3] = {i, j, k};
          bool border = false;
          for (int a = 0; a < 3 && !border; ++a)
            for (const int s : {-1, 1}) {
              const std::int64_t n = ijk[a] + s;
              if (n < 0 || n >= d[a]) continue;
              const double other = parts.valueAsDouble(at + s * step[a]);
              border = border || (other > 0 && other != part);
            }
          atBorder[int(label)] += border;
        }
    for (const auto& [label, perPart] : counts) {
      std::int64_t total = 0, most = 0;
      for (const auto& [part, n] : perPart) total += n, most = std::max(most, n);
      // An organ lies in one part and clear of its borders: a vessel of the trunk that runs on
      // into a limb as the limb's vessels touches the joint and must bend there.
      if (double(most) >= kWholeOrganShare * double(total) &&
          double(atBorder[label]) <= kWholeOrganBorderShare * double(total))
        whole.insert(label);
    }
    // A soft label inside a ring of bone (the spinal cord in its canal) moves with that bone,
    // whatever parts it spans: each part's share of it is a piece of that part, as the spine is.
    for (const int label : labelsEncasedInBone(organs, settings.rigidLabels))
      if (!whole.count(label)) whole.insert(label), encased.push_back(label);
  }
  std::vector<int> out;
  for (const int label : whole)
    if (label > 0 && label <= 65535) out.push_back(label);
  return out;
}
}  // namespace

std::vector<int> labelsMovingWhole(const Volume& organs, const Volume& parts,
                                   const RigSettings& settings) {
  std::vector<int> encased;
  return wholeLabels(organs, parts, settings, encased);
}

std::map<int, int> bonePiecesOf(const TissueTable& table) {
  std::map<std::string, int> first;  // bone name -> its smallest rigid label (the table is sorted)
  std::map<int, int> out;
  for (const auto& [label, tissue] : table) {
    if (!tissue.rigid || tissue.bone.empty()) continue;
    out[label] = first.try_emplace(tissue.bone, label).first->second;
  }
  return out;
}

namespace {
// Seam half-width in voxels. Mesh_3 follows subdomain borders only to within a voxel, so a mesh
// vertex can still land on both pieces' surfaces; demotePiecesAcrossJoints catches those.
constexpr int kSeamVoxels = 1;

// A soft vertex that caps a face of one part's piece and, across it, a face of another's (a joint
// space one vertex thick: clavicle to first rib, humeral head to glenoid) is squeezed between two
// rigid motions: its tets on those faces turn over as the faces meet, and it can only move
// between them. One part's piece tets at the corners of its faces go soft, so the space gets a
// second layer; its bone is still placed by PieceGhosts. A corner it frees capped no face of
// the other part (that tet would have been pinned, and loosened before), so the layers do not
// cascade through a thin bone, and a second call finds nothing
// (PoseRig.EveryPieceMovesExactlyWithOneGroupInEveryFrame). `pieceAt` is, per vertex, the piece
// volume of each part around it; the (vertex, part) pairs to loosen are appended to `loosen`.
void loosenSqueezedVertices(const TransferMesh& mesh,
                            const std::vector<std::map<int, double>>& pieceAt,
                            std::vector<std::pair<int, int>>& loosen) {
  // Per vertex, the piece tets at it; per part, how many piece tets it has.
  std::vector<std::vector<int>> pieceTetsAt(std::size_t(mesh.vertices.rows()));
  std::map<int, int> pieceTets;
  for (Eigen::Index t = 0; t < mesh.tets.rows(); ++t) {
    if (!mesh.rigid[std::size_t(t)]) continue;
    ++pieceTets[mesh.labels[t]];
    for (int c = 0; c < 4; ++c) pieceTetsAt[std::size_t(mesh.tets(t, c))].push_back(int(t));
  }
  // Per soft vertex, per part: the faces of that part's piece it caps.
  std::vector<std::map<int, std::vector<std::array<int, 3>>>> capped(
      std::size_t(mesh.vertices.rows()));
  for (Eigen::Index t = 0; t < mesh.tets.rows(); ++t) {
    if (mesh.rigid[std::size_t(t)]) continue;
    for (int apex = 0; apex < 4; ++apex) {
      const int w = mesh.tets(t, apex);
      if (!pieceAt[std::size_t(w)].empty()) continue;
      std::array<int, 3> face{};
      int n = 0;
      for (int c = 0; c < 4; ++c)
        if (c != apex) face[std::size_t(n++)] = mesh.tets(t, c);
      for (const auto& [part, volume] : pieceAt[std::size_t(face[0])])
        if (pieceAt[std::size_t(face[1])].count(part) && pieceAt[std::size_t(face[2])].count(part))
          capped[std::size_t(w)][part].push_back(face);
    }
  }
  // The unit normal of a face, turned towards the vertex that caps it.
  const auto towards = [&](const std::array<int, 3>& f, int w) {
    const Eigen::Vector3d a = mesh.vertices.row(f[0]).transpose();
    Eigen::Vector3d n =
        (mesh.vertices.row(f[1]).transpose() - a).cross(mesh.vertices.row(f[2]).transpose() - a);
    if (n.dot(mesh.vertices.row(w).transpose() - a) < 0) n = -n;
    return Eigen::Vector3d(n.normalized());
  };
  for (std::size_t w = 0; w < capped.size(); ++w) {
    const auto& parts = capped[w];
    if (parts.size() < 2) continue;
    // Only faces that face a face of another part across the vertex squeeze it: their normals
    // towards it point apart. A vertex at the rim of a joint may cap two bones' faces side by
    // side and still move away from both.
    std::map<int, std::vector<std::array<int, 3>>> facing;
    for (auto p = parts.begin(); p != parts.end(); ++p)
      for (auto q = std::next(p); q != parts.end(); ++q)
        for (const auto& fp : p->second)
          for (const auto& fq : q->second)
            if (towards(fp, int(w)).dot(towards(fq, int(w))) < 0) {
              facing[p->first].push_back(fp);
              facing[q->first].push_back(fq);
            }
    if (facing.size() < 2) continue;
    // The part that would give up the largest share of its piece tets keeps them, so a thin
    // bone (a humerus two tets thick on a coarse mesh) is spared and a large one gives.
    int keep = -1;
    double most = -1;
    for (const auto& [part, faces] : facing) {
      std::vector<int> corners;
      for (const auto& f : faces) corners.insert(corners.end(), f.begin(), f.end());
      std::sort(corners.begin(), corners.end());
      corners.erase(std::unique(corners.begin(), corners.end()), corners.end());
      std::vector<int> lost;
      for (const int corner : corners)
        for (const int t : pieceTetsAt[std::size_t(corner)])
          if (mesh.labels[t] == part) lost.push_back(t);
      std::sort(lost.begin(), lost.end());
      const double share =
          double(std::unique(lost.begin(), lost.end()) - lost.begin()) / pieceTets[part];
      if (share > most) most = share, keep = part;
    }
    for (const auto& [part, faces] : facing)
      if (part != keep)
        for (const auto& f : faces)
          for (const int corner : f) loosen.emplace_back(corner, part);
  }
}
}  // namespace

int demotePiecesAcrossJoints(TransferMesh& mesh) {
  if (mesh.rigid.empty()) return 0;
  // Per vertex, the volume of the piece tets of each body part around it.
  std::vector<std::map<int, double>> around(std::size_t(mesh.vertices.rows()));
  for (Eigen::Index t = 0; t < mesh.tets.rows(); ++t) {
    if (!mesh.rigid[std::size_t(t)]) continue;
    const double v = std::fabs(tetVolume(mesh.vertices, mesh.tets.row(t)));
    for (int c = 0; c < 4; ++c) around[std::size_t(mesh.tets(t, c))][mesh.labels[t]] += v;
  }
  // Where pieces of two parts share a vertex, the part with more piece volume there keeps it
  // (ties: the smaller label) and the other parts' piece tets at it become soft tissue: one bone
  // end bends instead of both (with both soft, a humerus meshed as one piece with its marrow
  // lost more than RigCommand.AThickSliceBodyPosedOntoAFinerGridKeepsEveryBone allows).
  std::vector<int> keeper(std::size_t(mesh.vertices.rows()), -1);
  for (std::size_t v = 0; v < around.size(); ++v) {
    if (around[v].size() < 2) continue;
    double most = -1;
    for (const auto& [part, volume] : around[v])
      if (volume > most) most = volume, keeper[v] = part;
  }
  int demoted = 0;
  for (Eigen::Index t = 0; t < mesh.tets.rows(); ++t) {
    if (!mesh.rigid[std::size_t(t)]) continue;
    bool joint = false;
    for (int c = 0; c < 4; ++c) {
      const int k = keeper[std::size_t(mesh.tets(t, c))];
      joint |= k != -1 && k != mesh.labels[t];
    }
    if (joint) mesh.rigid[std::size_t(t)] = 0, ++demoted;
  }
  // A soft tet whose four vertices all lie on pieces, of two parts (a joint space thinner than
  // one tet: humerus to ulna, femur to tibia), has no vertex that may move: it follows two rigid
  // motions that disagree and turns inside out when the joint bends, with nothing the restoration
  // can do. The part with more piece volume at its vertices keeps them; the other part's piece
  // tets at them go soft, so the joint space has a free layer that bends (their bone is still
  // placed by the piece's own motion: PieceGhosts.h).
  for (int pass = 0; pass < 8; ++pass) {
    std::vector<std::map<int, double>> pieceAt(std::size_t(mesh.vertices.rows()));
    for (Eigen::Index t = 0; t < mesh.tets.rows(); ++t) {
      if (!mesh.rigid[std::size_t(t)]) continue;
      const double v = std::fabs(tetVolume(mesh.vertices, mesh.tets.row(t)));
      for (int c = 0; c < 4; ++c) pieceAt[std::size_t(mesh.tets(t, c))][mesh.labels[t]] += v;
    }
    std::vector<std::pair<int, int>> loosen;  // (vertex, part whose piece tets at it go soft)
    for (Eigen::Index t = 0; t < mesh.tets.rows(); ++t) {
      if (mesh.rigid[std::size_t(t)]) continue;
      std::map<int, double> parts;
      bool pinned = true;
      for (int c = 0; c < 4 && pinned; ++c) {
        const auto& at = pieceAt[std::size_t(mesh.tets(t, c))];
        pinned = !at.empty();
        for (const auto& [part, volume] : at) parts[part] += volume;
      }
      if (!pinned || parts.size() < 2) continue;
      int keep = -1;
      double most = -1;
      for (const auto& [part, volume] : parts)
        if (volume > most) most = volume, keep = part;
      for (int c = 0; c < 4; ++c)
        for (const auto& [part, volume] : pieceAt[std::size_t(mesh.tets(t, c))])
          if (part != keep) loosen.emplace_back(mesh.tets(t, c), part);
    }
    loosenSqueezedVertices(mesh, pieceAt, loosen);
    if (loosen.empty()) break;
    std::sort(loosen.begin(), loosen.end());
    loosen.erase(std::unique(loosen.begin(), loosen.end()), loosen.end());
    std::vector<std::vector<int>> partsToLoosen(std::size_t(mesh.vertices.rows()));
    for (const auto& [v, part] : loosen) partsToLoosen[std::size_t(v)].push_back(part);
    for (Eigen::Index t = 0; t < mesh.tets.rows(); ++t) {
      if (!mesh.rigid[std::size_t(t)]) continue;
      bool go = false;
      for (int c = 0; c < 4 && !go; ++c)
        for (const int part : partsToLoosen[std::size_t(mesh.tets(t, c))])
          go = go || part == mesh.labels[t];
      if (go) mesh.rigid[std::size_t(t)] = 0, ++demoted;
    }
  }
  return demoted;
}

Volume wholePieceMap(const Volume& organs, const Volume& parts, const RigSettings& settings) {
  std::vector<int> encased;
  const std::vector<int> whole = wholeLabels(organs, parts, settings, encased);
  if (whole.empty()) return Volume();
  Volume pieces(parts.geometry(), ScalarType::UInt16);
  // Per label: the piece it is meshed in (0: none).
  std::vector<std::uint16_t> pieceOf(65536, 0);
  for (const int label : whole) {
    const auto bone = settings.bonePieces.find(label);
    pieceOf[std::size_t(label)] =
        std::uint16_t(bone != settings.bonePieces.end() ? bone->second : label);
  }
  std::uint16_t* piece = pieces.data<std::uint16_t>();
  for (std::int64_t i = 0; i < parts.numVoxels(); ++i) {
    const double label = organs.valueAsDouble(i);
    if (label > 0 && label <= 65535) piece[i] = pieceOf[std::size_t(label)];
  }
  // Where pieces of two body parts touch (bones at a joint) a seam of soft tissue is left between
  // them, so no mesh vertex belongs to both: each moves whole with its own part's group and the
  // seam takes the bend, as a joint's cartilage and capsule do.
  const auto& d = parts.dims();
  std::vector<std::int64_t> seam;
  for (std::int64_t k = 0; k < d[2]; ++k)
    for (std::int64_t j = 0; j < d[1]; ++j)
      for (std::int64_t i = 0; i < d[0]; ++i) {
        const std::int64_t at = parts.index(i, j, k);
        const std::uint16_t own = piece[at];
        if (own == 0) continue;
        const double part = parts.valueAsDouble(at);
        auto other = [&](std::int64_t di, std::int64_t dj, std::int64_t dk) {
          const std::int64_t a = i + di, b = j + dj, c = k + dk;
          if (a < 0 || b < 0 || c < 0 || a >= d[0] || b >= d[1] || c >= d[2]) return false;
          const std::int64_t n = parts.index(a, b, c);
          return piece[n] != 0 && piece[n] != own && parts.valueAsDouble(n) != part;
        };
        bool near = false;
        for (int s = 1; s <= kSeamVoxels && !near; ++s)
          near = other(-s, 0, 0) || other(s, 0, 0) || other(0, -s, 0) || other(0, s, 0) ||
                 other(0, 0, -s) || other(0, 0, s);
        if (near) seam.push_back(at);
      }
  for (const std::int64_t at : seam) piece[at] = 0;
  // An encased label (the spinal cord) crosses the joints its bone is parted at (the neck, the
  // lumbosacral disc): there it stays soft tissue and bends with the joint's band, as the disc
  // beside it does, instead of two rigid halves meeting at a seam (sitting's pelvic tilt ran
  // them into each other).
  softenEncasedNearOtherParts(organs, parts, encased, kEncasedJointBandMm, piece);
  return pieces;
}

SizingField rigSizingField(const Volume& parts, const RigSettings& settings) {
  SizingField field = initialSizingField(parts, settings.meshMm);
  if (settings.refineJoints.empty()) return field;
  const auto& d = field.grid.dims;
  for (std::int64_t k = 0; k < d[2]; ++k)
    for (std::int64_t j = 0; j < d[1]; ++j)
      for (std::int64_t i = 0; i < d[0]; ++i) {
        const Eigen::Vector3d p = field.grid.voxelToRas(double(i), double(j), double(k));
        float& size = field.sizeMm[std::size_t(i + d[0] * (j + d[1] * k))];
        for (const JointRefinement& r : settings.refineJoints) {
          if (!(r.radiusMm > 0) || !(r.sizeMm > 0)) continue;
          // sizeMm inside the ball, growing linearly to the default at twice its radius.
          const double t = std::clamp(((p - r.centre).norm() - r.radiusMm) / r.radiusMm, 0.0, 1.0);
          size = std::min(size, float(r.sizeMm + t * (double(size) - r.sizeMm)));
        }
      }
  return field;
}

RigGeometry buildRigGeometry(const Volume& parts, const std::vector<LimbSeparation>& separations,
                             const RigSettings& settings, const ProgressFn& progress,
                             const Volume* organs) {
  auto scaled = [&](double from, double to) -> ProgressFn {
    if (!progress) return {};
    return
        [=](double f, const std::string& stage) { return progress(from + (to - from) * f, stage); };
  };
  CageOptions co;
  co.targetVertices = settings.cageVertices;
  co.dilateMm = settings.dilateMm;
  co.separations = separations;
  co.threads = settings.threads;
  co.progress = scaled(0, 0.5);
  RigGeometry g;
  g.cage = buildCageTrying(parts, co, &g.cageChoice).mesh;
  TransferMeshOptions to;
  to.sizeMm = settings.meshMm;
  to.progress = scaled(0.5, 1);
  const SizingField sizing = rigSizingField(parts, settings);
  if (!settings.refineJoints.empty()) to.sizing = &sizing;
  std::optional<Volume> pieces;
  if (organs) {
    pieces = wholePieceMap(*organs, parts, settings);
    if (pieces->numVoxels() > 0) to.rigidTissue = &*pieces;
  }
  g.mesh = buildTransferMesh(parts, to);
  demotePiecesAcrossJoints(g.mesh);
  for (const LimbSeparation& s : separations) separateLabels(g.mesh, s.labelA, s.labelB, s.region);
  reportProgress(progress, 1, "rig built");
  return g;
}

TransferMesh refineRigMesh(const Volume& parts, const TriangleMesh& cage,
                           const Eigen::MatrixX3d& posedCage,
                           const std::vector<LimbSeparation>& separations,
                           const RigSettings& settings, int iterations, const ProgressFn& progress,
                           const Volume* organs, std::vector<RefinementStep>* steps) {
  if (posedCage.rows() != cage.vertices.rows())
    throw Error("refining the transfer mesh: the posed cage has " +
                std::to_string(posedCage.rows()) + " vertices, the cage " +
                std::to_string(cage.vertices.rows()));
  RefinementOptions ro;
  ro.initialSizeMm = settings.meshMm;
  ro.threads = settings.threads;
  ro.progress = progress;
  ro.maxIterations = std::max(1, iterations);
  ro.uniformity = 0;  // every round asked for
  std::optional<Volume> pieces;
  if (organs) {
    pieces = wholePieceMap(*organs, parts, settings);
    if (pieces->numVoxels() > 0) ro.rigidTissue = &*pieces;
  }
  RefinementResult result = refineTransferMesh(parts, cage, posedCage, ro);
  demotePiecesAcrossJoints(result.mesh);
  for (const LimbSeparation& s : separations)
    separateLabels(result.mesh, s.labelA, s.labelB, s.region);
  if (steps) *steps = result.steps;
  return std::move(result.mesh);
}

struct PoseRig::CageArap {
  explicit CageArap(const TriangleMesh& cage) : deformer(cage) {}
  ArapDeformer deformer;
  std::vector<int> held;  // the groups' cage vertices, in the order of the solve's targets
  double jump = 0;        // kLiveCageStep of the rest cage's diagonal, in mm
  mutable std::mutex mutex;
  Eigen::MatrixX3d lastLive;  // empty before the first live frame
  int lastIterations = 0;
};

PoseRig::PoseRig(RigGeometry geometry, const Pose& pose, const LabelTable& partLabels, int threads,
                 int jointRings, const std::vector<BendJoint>& bends)
    : geometry_(std::move(geometry)), pose_(pose), userPose_(pose) {
  deformation_ = std::make_unique<CageDeformation>(geometry_.mesh, geometry_.cage, threads,
                                                   geometry_.coordinatesFile);
  handles_ = resolveHandles(pose_, geometry_.cage, geometry_.mesh, partLabels);
  std::vector<int> held;
  for (const RigidHandle& h : handles_)
    held.insert(held.end(), h.cageVertices.begin(), h.cageVertices.end());
  if (!held.empty() && Eigen::Index(held.size()) < geometry_.cage.vertices.rows()) {
    arap_ = std::make_unique<CageArap>(geometry_.cage);
    arap_->deformer.setHandles(held);
    arap_->held = std::move(held);
    const Eigen::MatrixX3d& c = geometry_.cage.vertices;
    arap_->jump = kLiveCageStep * (c.colwise().maxCoeff() - c.colwise().minCoeff()).norm();
  }
  influence_ = computeHandleInfluence(geometry_.mesh, geometry_.cage, handles_, threads,
                                      jointRings >= 0 ? jointRings : pose_.jointRings);
  bends_ = JointBends(geometry_.mesh, handles_, bends);
  frames_ = pose_.frames();
  // Whole pieces stay exactly rigid: the restoration moves only the soft tissue's vertices.
  const TransferMesh& m = geometry_.mesh;
  movable_.assign(std::size_t(m.vertices.rows()), 1);
  if (!m.rigid.empty())
    for (Eigen::Index t = 0; t < m.tets.rows(); ++t)
      if (m.rigid[std::size_t(t)])
        for (int k = 0; k < 4; ++k) movable_[std::size_t(m.tets(t, k))] = 0;
  contacts_ = std::make_unique<SelfContactFinder>(m);
}

PoseRig::~PoseRig() = default;

VolumeRestorationReport PoseRig::restoreFrameVolumes(Eigen::MatrixX3d& deformed,
                                                     const std::vector<RigidHandle>& handles,
                                                     const std::atomic<bool>* cancel) const {
  if (!restoreVolumes_) return {};
  const TransferMesh& m = geometry_.mesh;
  std::vector<char> zone = bends_.empty() ? std::vector<char>(std::size_t(m.vertices.rows()), 0)
                                          : bends_.zone(handles, m.vertices.rows());
  // The transitions between two groups that carry jointed parts and move apart this frame.
  if (!jointedParts_.empty()) {
    const Eigen::Index groups = influence_.membership.cols();
    std::vector<std::vector<char>> jointed(std::size_t(groups),
                                           std::vector<char>(std::size_t(groups), 0));
    for (const auto& [a, b] : jointedParts_) {
      const int ga = handleGroupOfPart(handles, a), gb = handleGroupOfPart(handles, b);
      if (ga < 0 || gb < 0 || ga == gb) continue;
      if (handles[std::size_t(ga)].motion.isApprox(handles[std::size_t(gb)].motion, 1e-12))
        continue;
      jointed[std::size_t(ga)][std::size_t(gb)] = jointed[std::size_t(gb)][std::size_t(ga)] = 1;
    }
    for (Eigen::Index v = 0; v < m.vertices.rows(); ++v)
      for (Eigen::Index g = 0; g < groups && !zone[std::size_t(v)]; ++g) {
        if (influence_.membership(v, g) < 0.01) continue;
        for (Eigen::Index h = g + 1; h < groups; ++h)
          if (influence_.membership(v, h) >= 0.01 && jointed[std::size_t(g)][std::size_t(h)]) {
            zone[std::size_t(v)] = 1;
            break;
          }
      }
  }
  // One ring of tets around the bends: the tets that span the bend's reach.
  std::vector<char> grown = zone;
  for (Eigen::Index t = 0; t < m.tets.rows(); ++t) {
    bool any = false;
    for (int k = 0; k < 4; ++k) any = any || zone[std::size_t(m.tets(t, k))];
    if (any)
      for (int k = 0; k < 4; ++k) grown[std::size_t(m.tets(t, k))] = 1;
  }
  bool anything = false;
  for (std::size_t v = 0; v < grown.size(); ++v) {
    grown[v] = grown[v] && movable_[v];
    anything = anything || grown[v];
  }
  if (!anything) return {};
  std::vector<char> held = bends_.empty() ? std::vector<char>() : bends_.reachTets(m, handles);
  VolumeRestorationOptions options;
  options.cancel = cancel;
  options.contacts = contacts_.get();
  return restoreVolumes(m, grown, deformed, options, held, tissues_.empty() ? nullptr : &tissues_);
}

std::vector<std::pair<std::string, int>> PoseRig::invertedTetsByJoint(
    const Eigen::MatrixX3d& deformed) const {
  const TransferMesh& m = geometry_.mesh;
  std::vector<int> count(std::max<std::size_t>(1, jointSites_.size()), 0);
  for (Eigen::Index t = 0; t < m.tets.rows(); ++t) {
    Eigen::Matrix3d E;
    for (int c = 0; c < 3; ++c)
      E.col(c) = (deformed.row(m.tets(t, c + 1)) - deformed.row(m.tets(t, 0))).transpose();
    if (E.determinant() > 0) continue;
    Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
    for (int k = 0; k < 4; ++k) centroid += m.vertices.row(m.tets(t, k)).transpose() / 4;
    std::size_t nearest = 0;
    for (std::size_t j = 1; j < jointSites_.size(); ++j)
      if ((jointSites_[j].centre - centroid).squaredNorm() <
          (jointSites_[nearest].centre - centroid).squaredNorm())
        nearest = j;
    ++count[nearest];
  }
  std::vector<std::pair<std::string, int>> out;
  for (std::size_t j = 0; j < count.size(); ++j)
    if (count[j] > 0) out.emplace_back(jointSites_.empty() ? "" : jointSites_[j].name, count[j]);
  return out;
}

PoseRig::Frame PoseRig::frame(std::size_t index, GreenPrecision precision,
                              FrameMaps tetMaps) const {
  if (index >= frames_.size())
    throw Error("pose " + pose_.name + " has " + std::to_string(frames_.size()) + " frames, not " +
                std::to_string(index + 1));
  return solveFrame(frames_[index].first, frames_[index].second, precision, tetMaps);
}

PoseRig::Frame PoseRig::frame(const Pose& edited, std::size_t index, GreenPrecision precision,
                              FrameMaps tetMaps) const {
  return solveEdited(edited, index, precision, tetMaps, CageStart::Rest);
}

PoseRig::Frame PoseRig::liveFrame(const Pose& edited, std::size_t index) const {
  return solveEdited(edited, index, GreenPrecision::Preview, FrameMaps::Without,
                     CageStart::LastLiveFrame);
}

PoseRig::Frame PoseRig::solveEdited(const Pose& edited, std::size_t index, GreenPrecision precision,
                                    FrameMaps tetMaps, CageStart start) const {
  if (!sameHandleGroups(edited, userPose_))
    throw Error("pose " + edited.name + ": its groups are not those the rig was prepared for");
  const auto frames = rhythms_.apply(edited).frames();
  if (index >= frames.size())
    throw Error("pose " + edited.name + " has " + std::to_string(frames.size()) + " frames, not " +
                std::to_string(index + 1));
  return solveFrame(frames[index].first, frames[index].second, precision, tetMaps, start);
}

int PoseRig::lastCageIterations() const {
  if (!arap_) return 0;
  std::lock_guard<std::mutex> lock(arap_->mutex);
  return arap_->lastIterations;
}

Eigen::MatrixX3d PoseRig::posedCage(const std::vector<RigidHandle>& handles,
                                    CageStart start) const {
  if (!arap_) return poseCage(geometry_.cage, handles);  // every cage vertex is in a group
  const Eigen::MatrixX3d moved = moveHandles(geometry_.cage.vertices, handles);
  Eigen::MatrixX3d targets(Eigen::Index(arap_->held.size()), 3);
  for (std::size_t i = 0; i < arap_->held.size(); ++i)
    targets.row(Eigen::Index(i)) = moved.row(arap_->held[i]);
  std::lock_guard<std::mutex> lock(arap_->mutex);
  // Warm only for a step of a drag: after a jump (an undo, another keyframe) a few iterations from
  // the last cage would leave it far off with no next event to converge it, so the cage is solved
  // from rest, as frame() solves it.
  bool warm = start == CageStart::LastLiveFrame && arap_->lastLive.rows() > 0;
  for (std::size_t i = 0; i < arap_->held.size() && warm; ++i)
    warm =
        (targets.row(Eigen::Index(i)) - arap_->lastLive.row(arap_->held[i])).norm() <= arap_->jump;
  ArapOptions options;
  if (warm) options.maxIterations = kLiveCageIterations;
  ArapResult r = arap_->deformer.solve(targets, warm ? &arap_->lastLive : nullptr, options);
  arap_->lastIterations = r.iterations;
  if (start == CageStart::LastLiveFrame) arap_->lastLive = r.positions;
  return std::move(r.positions);
}

PoseRig::Frame PoseRig::solveFrame(const std::string& name,
                                   const std::vector<Eigen::Isometry3d>& motions,
                                   GreenPrecision precision, FrameMaps tetMaps,
                                   CageStart start) const {
  Frame f;
  f.name = name;
  f.handles = handles_;
  std::vector<Eigen::Isometry3d> cleared = motions;
  f.clearances = clearance_.apply(cleared);
  setMotions(f.handles, cleared);
  f.cage = posedCage(f.handles, start);
  f.deformed = deformation_->deform(f.cage, influence_, f.handles,
                                    tetMaps == FrameMaps::With ? &f.tetMaps : nullptr, precision);
  // Tissue a group carries alone moves with it exactly, also where the cage misses it (the crotch
  // beside a cut between the thighs): the rigidity solver would drag it along with its moving
  // neighbours otherwise.
  int carriedOutside = 0;
  {
    const TransferMesh& m = geometry_.mesh;
    const std::vector<char>& inside = deformation_->embedding().inside;
    const GroupMotions motions(f.handles);
    for (Eigen::Index v = 0; v < m.vertices.rows(); ++v) {
      if (inside[std::size_t(v)] || influence_.weight[std::size_t(v)] < 1) continue;
      f.deformed.row(v) =
          (motions.of(influence_.membership.row(v)) * Eigen::Vector3d(m.vertices.row(v)))
              .transpose();
      ++carriedOutside;
    }
  }
  const JointBendReport bent = bends_.apply(geometry_.mesh, f.handles, f.deformed);
  // Soft tissue keeps its volume (VolumeRestoration.h): every frame but the live preview's.
  if (start == CageStart::Rest) f.restoration = restoreFrameVolumes(f.deformed, f.handles);
  // The bends, the carried vertices and the restoration moved vertices after the solver: their
  // tets' maps follow.
  if (tetMaps == FrameMaps::With &&
      (bent.vertices > 0 || carriedOutside > 0 || f.restoration.freeVertices > 0)) {
    const TransferMesh& m = geometry_.mesh;
    for (Eigen::Index t = 0; t < m.tets.rows(); ++t) {
      Eigen::Matrix3d D, E;
      for (int c = 0; c < 3; ++c) {
        D.col(c) = (m.vertices.row(m.tets(t, c + 1)) - m.vertices.row(m.tets(t, 0))).transpose();
        E.col(c) = (f.deformed.row(m.tets(t, c + 1)) - f.deformed.row(m.tets(t, 0))).transpose();
      }
      f.tetMaps[std::size_t(t)] = E * D.inverse();
    }
  }
  return f;
}

}  // namespace repose
