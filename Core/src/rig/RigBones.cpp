// The rig's first stage: G's bones by kind and side, and the body's frame.
#include "RigInternal.h"

#include "repose/util/Error.h"

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>

namespace repose::rig {

Grid::Grid(const VolumeGeometry& g) : geometry(&g), dims(g.dims), spacing(g.spacing()) {}

V Grid::ras(std::int64_t index) const {
  const std::int64_t i = index % dims[0], j = (index / dims[0]) % dims[1],
                     k = index / (dims[0] * dims[1]);
  return geometry->voxelToRas(double(i), double(j), double(k));
}

V Bone::extreme(const V& towards) const {
  // The mean of the boundary points within a millimetre of the furthest one: a tip of a few
  // voxels at the same height is its middle, not whichever voxel came first.
  double most = -1e300;
  for (const V& p : boundary) most = std::max(most, p.dot(towards));
  V sum = V::Zero();
  int n = 0;
  for (const V& p : boundary)
    if (p.dot(towards) >= most - 1.0) sum += p, ++n;
  return n ? V(sum / n) : centroid;
}

const Bone* Bones::find(BoneKind kind, int side) const {
  const auto it = byKind.find({kind, side});
  return it == byKind.end() || it->second.voxels.empty() ? nullptr : &it->second;
}

namespace {

bool sided(BoneKind k) {
  switch (k) {
    case BoneKind::Humerus:
    case BoneKind::Forearm:
    case BoneKind::Hand:
    case BoneKind::Femur:
    case BoneKind::Shank:
    case BoneKind::Foot:
    case BoneKind::Clavicle:
    case BoneKind::Scapula:
      return true;
    default:
      return false;
  }
}

// Centroid, principal axis, length and boundary of a bone's voxels; `owner` marks every voxel
// with its bone's id (id + 1), so the boundary is where a face leaves the bone.
void describe(Bone& b, const Grid& grid, const std::vector<std::int32_t>& owner, std::int32_t id) {
  b.centroid = V::Zero();
  for (const std::int64_t v : b.voxels) b.centroid += grid.ras(v);
  b.centroid /= double(b.voxels.size());
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  for (const std::int64_t v : b.voxels) {
    const V d = grid.ras(v) - b.centroid;
    cov += d * d.transpose();
  }
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(cov / double(b.voxels.size()));
  b.axis = eig.eigenvectors().col(2).normalized();
  double lo = 1e300, hi = -1e300;
  const auto& d = grid.dims;
  for (const std::int64_t v : b.voxels) {
    const V p = grid.ras(v);
    lo = std::min(lo, (p - b.centroid).dot(b.axis));
    hi = std::max(hi, (p - b.centroid).dot(b.axis));
    const std::int64_t i = v % d[0], j = (v / d[0]) % d[1], k = v / (d[0] * d[1]);
    const std::int64_t ijk[3] = {i, j, k}, step[3] = {1, d[0], d[0] * d[1]};
    // The surface is where a face leaves the bone: its centre, not the voxel's, half a voxel
    // further out (four millimetres on 8 mm slices would bias every fit of an articular end).
    for (int a = 0; a < 3; ++a)
      for (int s : {-1, 1}) {
        const std::int64_t n = ijk[a] + s;
        if (n >= 0 && n < d[a] && owner[std::size_t(v + s * step[a])] == id + 1) continue;
        double at[3] = {double(i), double(j), double(k)};
        at[a] += 0.5 * s;
        b.boundary.push_back(grid.geometry->voxelToRas(at[0], at[1], at[2]));
        b.faceSize.push_back(grid.spacing[a]);
      }
  }
  b.length = hi - lo;
}

}  // namespace

Bones findBones(const Volume& organs, const LabelConvention& convention, const Grid& grid,
                const std::string& source) {
  Bones out;
  out.voxelMm = grid.spacing.maxCoeff();
  // Voxels per (kind, side given by the label).
  std::map<std::pair<BoneKind, int>, std::vector<std::int64_t>> raw;
  std::vector<std::int64_t> body;
  double bodyX = 0;
  std::int64_t bodyCount = 0;
  std::map<int, const LabelRole*> role;
  for (const auto& [v, r] : convention.roles) role[v] = &r;
  std::vector<const LabelRole*> fast(65536, nullptr);
  for (const auto& [v, r] : role)
    if (v > 0 && v < 65536) fast[std::size_t(v)] = r;
  dispatchScalar(organs.scalarType(), [&](auto* tag) {
    using T = std::remove_pointer_t<decltype(tag)>;
    if constexpr (std::is_integral_v<T>) {
      const T* g = organs.data<T>();
      for (std::int64_t i = 0; i < organs.numVoxels(); ++i) {
        if (g[i] <= 0 || double(g[i]) >= 65536) continue;
        const LabelRole* r = fast[std::size_t(g[i])];
        if (!r) continue;
        const std::int64_t x = i % grid.dims[0];
        bodyX += grid.geometry->voxelToRas(double(x), 0, 0).x(), ++bodyCount;
        if (r->bone == BoneKind::None || r->bone == BoneKind::Teeth) continue;
        const BoneKind kind = r->bone == BoneKind::Patella ? BoneKind::Shank : r->bone;
        raw[{kind, sided(kind) ? r->side : 0}].push_back(i);
        if (kind == BoneKind::Spine && r->boneName == "sacrum") out.sacrum.push_back(grid.ras(i));
      }
    }
  });
  // A skeleton in one label: its bones by geometry.
  if (const auto it = raw.find({BoneKind::Skeleton, 0}); it != raw.end()) {
    SkeletonSplit split = splitSkeleton(it->second, grid, source);
    raw.erase(it);
    for (auto& [key, voxels] : split.bones) {
      auto& dst = raw[key];
      dst.insert(dst.end(), voxels.begin(), voxels.end());
    }
    out.split = split.pieces;
    out.splitNotes = split.notes;
  }
  // The midline: the axial skeleton's mean x, else the body's.
  double axialX = 0;
  std::int64_t axialCount = 0;
  for (const BoneKind k : {BoneKind::Spine, BoneKind::Sternum})
    for (const std::int64_t v : raw[{k, 0}]) axialX += grid.ras(v).x(), ++axialCount;
  out.frame.midlineX =
      axialCount ? axialX / double(axialCount) : (bodyCount ? bodyX / double(bodyCount) : 0);

  // Bones whose labels do not tell the side: each 26-connected piece by its side of the midline.
  std::vector<char> seen(std::size_t(grid.count()), 0);
  const auto& d = grid.dims;
  for (auto& [key, voxels] : raw) {
    const auto [kind, side] = key;
    if (!sided(kind) || side != 0) {
      auto& dst = out.byKind[{kind, side}].voxels;
      dst.insert(dst.end(), voxels.begin(), voxels.end());
      continue;
    }
    for (const std::int64_t v : voxels) seen[std::size_t(v)] = 1;  // 1: of this kind
    for (const std::int64_t start : voxels) {
      if (seen[std::size_t(start)] != 1) continue;
      std::vector<std::int64_t> piece{start}, stack{start};
      seen[std::size_t(start)] = 2;
      while (!stack.empty()) {
        const std::int64_t v = stack.back();
        stack.pop_back();
        const std::int64_t i = v % d[0], j = (v / d[0]) % d[1], k = v / (d[0] * d[1]);
        for (int dk = -1; dk <= 1; ++dk)
          for (int dj = -1; dj <= 1; ++dj)
            for (int di = -1; di <= 1; ++di) {
              const std::int64_t a = i + di, b = j + dj, c = k + dk;
              if (a < 0 || b < 0 || c < 0 || a >= d[0] || b >= d[1] || c >= d[2]) continue;
              const std::int64_t n = a + d[0] * (b + d[1] * c);
              if (seen[std::size_t(n)] != 1) continue;
              seen[std::size_t(n)] = 2;
              piece.push_back(n), stack.push_back(n);
            }
      }
      double x = 0;
      for (const std::int64_t v : piece) x += grid.ras(v).x();
      // RAS: +x is the body's right.
      const int pieceSide = x / double(piece.size()) < out.frame.midlineX ? -1 : +1;
      auto& dst = out.byKind[{kind, pieceSide}].voxels;
      dst.insert(dst.end(), piece.begin(), piece.end());
    }
    for (const std::int64_t v : voxels) seen[std::size_t(v)] = 0;
  }
  // Allocated only now: a skeleton split above needs its memory first (325M voxels: 1.3 GB).
  std::vector<std::int32_t> owner(std::size_t(grid.count()), 0);
  std::int32_t id = 0;
  std::vector<Bone*> list;
  for (auto& [key, bone] : out.byKind) {
    bone.kind = key.first;
    bone.side = key.second;
    for (const std::int64_t v : bone.voxels) owner[std::size_t(v)] = id + 1;
    list.push_back(&bone);
    ++id;
  }
  for (std::size_t b = 0; b < list.size(); ++b)
    if (!list[b]->voxels.empty()) describe(*list[b], grid, owner, std::int32_t(b));

  // The body's frame: superior from the pelvis (or spine) to the skull; anterior is the file's
  // (RAS +y), checked against the sternum lying in front of the spine.
  BodyFrame& f = out.frame;
  const Bone* skull = out.find(BoneKind::Skull, 0);
  const Bone* pelvis = out.find(BoneKind::Pelvis, 0);
  const Bone* spine = out.find(BoneKind::Spine, 0);
  const Bone* sternum = out.find(BoneKind::Sternum, 0);
  const Bone* low = pelvis ? pelvis : spine;
  if (skull && low && (skull->centroid - low->centroid).norm() > 1) {
    f.superior = (skull->centroid - low->centroid).normalized();
    if (f.superior.z() < 0.5)
      f.warnings.push_back(
          "the skull lies below the pelvis in the file's RAS frame: check its "
          "orientation (the joints' left and right follow it)");
    if (f.superior.z() < 0) f.superior = V::UnitZ();
  }
  f.anterior = (V::UnitY() - V::UnitY().dot(f.superior) * f.superior).normalized();
  if (sternum && spine) {
    const V forward = sternum->centroid - spine->centroid;
    if (forward.dot(f.anterior) < 0)
      f.warnings.push_back(
          "the sternum lies behind the spine in the file's RAS frame: check its "
          "orientation (left and right may be swapped)");
  }
  return out;
}

}  // namespace repose::rig
