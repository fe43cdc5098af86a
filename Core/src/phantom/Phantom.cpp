// The phantom evaluated on a grid: per-point classification (depth under the skin -> skin, fat,
// muscle; bones and organs inside their body part) and the culled, threaded slice filler.
//
// Organ labels of G (values are stable; see PhantomLabels.h):
//   1 skin  2 subcutaneous_fat  3 muscle  4 skull  5 brain  6 eye  7 vertebrae  8 ribs
//   9 sternum  10 pelvis  11 humerus  12 radius_ulna  13 hand_bones  14 femur  15 tibia_fibula
//   16 foot_bones  17 lung_left  18 lung_right  19 heart  20 liver  21 kidney_left
//   22 kidney_right  23 stomach  24 spleen  25 urinary_bladder  26 small_bowel  27 spinal_cord
// Part labels of S are the PhantomPart values of Phantom.h.
#include "repose/phantom/Phantom.h"

#include "PhantomBody.h"
#include "PhantomIcrp.h"
#include "PhantomLabels.h"

#include "repose/util/Error.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <thread>

namespace repose {

using phantom::Segment;
using phantom::Structure;

struct Phantom::Impl {
  PhantomOptions options;
  phantom::BodyModel model;
  VolumeGeometry geometry;
  int threads = 1;
  bool anisotropic = false;
  std::unique_ptr<phantom::IcrpLabeller> icrp;

  // Classifies p against candidate segments and structures (indices) whose boxes hold p's row.
  void evaluate(const Eigen::Vector3d& p, const std::vector<int>& segs,
                const std::vector<int>& structs, std::uint8_t& organ, std::uint8_t& part) const;
  void fillRow(std::int64_t j, std::int64_t k, std::uint8_t* organ, std::uint8_t* part,
               std::vector<int>& segs, std::vector<int>& structs) const;
  double bodyDistance(const Eigen::Vector3d& p, const std::vector<int>& segs) const;
  // The skin's thickness at a surface point: one voxel along the surface's normal on a
  // thick-slice grid, so a horizontal surface still gets its layer of skin.
  double skinAt(const Eigen::Vector3d& p, const std::vector<int>& segs) const;
};

double Phantom::Impl::bodyDistance(const Eigen::Vector3d& p, const std::vector<int>& segs) const {
  phantom::BlendedDistance body;
  for (int i : segs) {
    const Segment& s = model.segments[i];
    if (s.box.containsX(p.x())) body.add(s, s.shape.distance(p), model.blendMm);
  }
  return body.value();
}

double Phantom::Impl::skinAt(const Eigen::Vector3d& p, const std::vector<int>& segs) const {
  const double h = 0.25;
  Eigen::Vector3d n;
  for (int c = 0; c < 3; ++c) {
    Eigen::Vector3d d = Eigen::Vector3d::Zero();
    d[c] = h;
    n[c] = bodyDistance(p + d, segs) - bodyDistance(p - d, segs);
  }
  if (n.norm() < 1e-12) return model.skinMm;
  n.normalize();
  return std::max(2.0, 1.05 * n.cwiseProduct(model.spacing).norm());
}

void Phantom::Impl::evaluate(const Eigen::Vector3d& p, const std::vector<int>& segs,
                             const std::vector<int>& structs, std::uint8_t& organ,
                             std::uint8_t& part) const {
  organ = part = 0;
  phantom::BlendedDistance blended;
  double best = 1e300;
  std::uint8_t owner = 0;
  for (int i : segs) {
    const Segment& s = model.segments[i];
    if (!s.box.containsX(p.x())) continue;
    const double d = s.shape.distance(p);
    blended.add(s, d, model.blendMm);
    if (d < best) {
      best = d;
      owner = s.cut && (p - s.cutPoint).dot(s.cutNormal) < 0 ? s.cutOwner : s.part;
      if (s.neckSplit)
        owner = (p - model.neckCentre).dot(model.neckNormal) > 0 ? kPartHead : kPartTorso;
    }
  }
  const double body = blended.value();
  if (!(body < 0)) return;
  part = owner;
  const double depth = -body;
  const double skin =
      anisotropic && depth < 1.05 * model.spacing.maxCoeff() ? skinAt(p, segs) : model.skinMm;
  if (depth < skin) {
    organ = phantom::kSkin;
  } else if (depth < skin + model.fatMm[part]) {
    organ = phantom::kFat;
  } else {
    organ = phantom::kMuscle;
    for (int i : structs) {
      const Structure& s = model.structures[i];
      if (!(s.part == part || s.claimsPart || s.anyPart)) continue;
      if (!s.box.containsX(p.x()) || !s.contains(p, depth)) continue;
      organ = s.label;
      if (s.claimsPart) part = s.part;  // a bone's end across its joint is still its part's
      if (s.anyPart) organ = phantom::vesselLabel(part);
      break;
    }
  }
  if (icrp) organ = icrp->label(organ, part, p);
  if (options.labels == PhantomLabelling::Coarse) organ = phantom::coarseLabel(organ);
}

void Phantom::Impl::fillRow(std::int64_t j, std::int64_t k, std::uint8_t* organ, std::uint8_t* part,
                            std::vector<int>& segs, std::vector<int>& structs) const {
  const std::int64_t nx = geometry.dims[0];
  // Axis-aligned grid, possibly running against x and y (ICRP's array order).
  const double dx = geometry.ijkToRas(0, 0);
  const Eigen::Vector3d o = geometry.origin();
  const double y = o.y() + double(j) * geometry.ijkToRas(1, 1);
  const double z = o.z() + double(k) * geometry.ijkToRas(2, 2);
  segs.clear();
  structs.clear();
  double xlo = 1e300, xhi = -1e300;
  for (int i = 0; i < static_cast<int>(model.segments.size()); ++i) {
    const phantom::Box& b = model.segments[i].box;
    if (!b.containsY(y) || !b.containsZ(z)) continue;
    segs.push_back(i);
    xlo = std::min(xlo, b.lo.x());
    xhi = std::max(xhi, b.hi.x());
  }
  std::fill(organ, organ + nx, 0);
  std::fill(part, part + nx, 0);
  if (segs.empty()) return;
  for (int i = 0; i < static_cast<int>(model.structures.size()); ++i) {
    const phantom::Box& b = model.structures[i].box;
    if (b.containsY(y) && b.containsZ(z)) structs.push_back(i);
  }
  const double ia = (xlo - o.x()) / dx, ib = (xhi - o.x()) / dx;
  const std::int64_t i0 =
      std::max<std::int64_t>(0, static_cast<std::int64_t>(std::floor(std::min(ia, ib))));
  const std::int64_t i1 =
      std::min<std::int64_t>(nx - 1, static_cast<std::int64_t>(std::ceil(std::max(ia, ib))));
  for (std::int64_t i = i0; i <= i1; ++i)
    evaluate({o.x() + double(i) * dx, y, z}, segs, structs, organ[i], part[i]);
}

Phantom::Phantom(const PhantomOptions& options) : impl_(std::make_unique<Impl>()) {
  if (!std::isfinite(options.voxelMm) || options.voxelMm <= 0)
    throw Error("phantom: the voxel size must be a positive number of mm, not " +
                std::to_string(options.voxelMm));
  const Eigen::Vector3d spacing = options.spacing();
  if (!spacing.allFinite() || spacing.minCoeff() <= 0)
    throw Error("phantom: every voxel spacing must be a positive number of mm");
  if (options.armsTouching && options.armsResting)
    throw Error("phantom: the arms either touch the hips or rest along the body, not both");
  for (const double gap : {options.handGapMm, options.forearmGapMm})
    if (!std::isfinite(gap) || gap < 0 || gap > 100)
      throw Error("phantom: a gap must be 0 to 100 mm, not " + std::to_string(gap));
  if ((options.handGapMm > 0 || options.forearmGapMm > 0) && !options.armsResting)
    throw Error("phantom: the hands' and forearms' gaps are those of the arms-resting posture");
  if (!std::isfinite(options.limbVesselMm) || options.limbVesselMm < 0 || options.limbVesselMm > 20)
    throw Error("phantom: the limb vessels' diameter must be 0 to 20 mm, not " +
                std::to_string(options.limbVesselMm));
  if (options.limbVesselMm > 0 && !options.armsResting)
    throw Error("phantom: the limb vessels are those of the arms-resting posture");
  if (options.girdlesTouching && !options.armsResting)
    throw Error("phantom: the shoulder girdles are those of the arms-resting posture");
  if (!std::isfinite(options.marginMm) || options.marginMm < 0)
    throw Error("phantom: the margin must be zero or more mm");
  if (options.threads < 0) throw Error("phantom: the thread count cannot be negative");
  impl_->options = options;
  impl_->model = phantom::buildBody(options);
  impl_->anisotropic = spacing.maxCoeff() > spacing.minCoeff() * (1 + 1e-9);
  if (options.labels == PhantomLabelling::Icrp110)
    impl_->icrp = std::make_unique<phantom::IcrpLabeller>(impl_->model);
  const unsigned hw = std::max(1u, std::thread::hardware_concurrency());
  impl_->threads = options.threads > 0 ? options.threads : static_cast<int>(hw);

  // Centred on the body; x is centred on exactly 0 so the grid is mirror-symmetric like the body.
  const phantom::Box& b = impl_->model.bounds;
  Eigen::Vector3d centre = 0.5 * (b.lo + b.hi), origin;
  centre.x() = 0;
  std::array<std::int64_t, 3> dims{};
  for (int w = 0; w < 3; ++w) {
    const double extent = std::max(b.hi[w] - centre[w], centre[w] - b.lo[w]) * 2;
    const double n = std::ceil((extent + 2 * options.marginMm) / spacing[w]);
    if (n > 1e6)
      throw Error("phantom: a voxel of " + std::to_string(spacing[w]) +
                  " mm makes the grid too large");
    dims[w] = static_cast<std::int64_t>(n);
    origin[w] = centre[w] - 0.5 * double(dims[w] - 1) * spacing[w];
  }
  impl_->geometry = VolumeGeometry::make(dims, spacing, origin);
  if (options.labels == PhantomLabelling::Icrp110) {
    // ICRP's array order: columns from the body's right (+x) to its left, rows front to back.
    for (int w = 0; w < 2; ++w) {
      impl_->geometry.ijkToRas(w, w) = -spacing[w];
      impl_->geometry.ijkToRas(w, 3) = centre[w] + 0.5 * double(dims[w] - 1) * spacing[w];
    }
  }
}

Phantom::~Phantom() = default;

const PhantomOptions& Phantom::options() const {
  return impl_->options;
}
const VolumeGeometry& Phantom::geometry() const {
  return impl_->geometry;
}
const std::vector<Joint>& Phantom::joints() const {
  return impl_->model.joints;
}

const Joint& Phantom::joint(const std::string& name) const {
  for (const Joint& j : impl_->model.joints)
    if (j.name == name) return j;
  throw Error("phantom: no joint named '" + name + "'");
}

LabelTable Phantom::organLabels() const {
  if (impl_->options.labels != PhantomLabelling::Phantom) return LabelTable();  // IDs only
  return phantom::makeOrganLabels(impl_->options.armsResting);
}
LabelTable Phantom::partLabels() const {
  return phantom::makePartLabels();
}

void Phantom::classify(const Eigen::Vector3d& ras, std::uint8_t& organ, std::uint8_t& part) const {
  std::vector<int> segs, structs;
  for (int i = 0; i < static_cast<int>(impl_->model.segments.size()); ++i)
    if (impl_->model.segments[i].box.contains(ras)) segs.push_back(i);
  for (int i = 0; i < static_cast<int>(impl_->model.structures.size()); ++i)
    if (impl_->model.structures[i].box.contains(ras)) structs.push_back(i);
  impl_->evaluate(ras, segs, structs, organ, part);
}

void Phantom::fillSlices(std::int64_t k0, std::int64_t k1, std::uint8_t* organ,
                         std::uint8_t* part) const {
  const auto& dims = impl_->geometry.dims;
  if (k0 < 0 || k1 > dims[2] || k0 > k1)
    throw Error("phantom: slices [" + std::to_string(k0) + ", " + std::to_string(k1) +
                ") are outside the grid of " + std::to_string(dims[2]) + " slices");
  const std::int64_t rows = (k1 - k0) * dims[1];
  const std::int64_t chunk =
      8;  // rows per work item: small enough to balance, big enough to be cheap
  std::atomic<std::int64_t> next{0};
  auto work = [&] {
    std::vector<int> segs, structs;
    for (std::int64_t r0; (r0 = next.fetch_add(chunk)) < rows;) {
      for (std::int64_t r = r0; r < std::min(rows, r0 + chunk); ++r) {
        const std::int64_t j = r % dims[1], k = k0 + r / dims[1];
        const std::int64_t offset = r * dims[0];
        impl_->fillRow(j, k, organ + offset, part + offset, segs, structs);
      }
    }
  };
  const int n = static_cast<int>(std::min<std::int64_t>(impl_->threads, rows / chunk + 1));
  std::vector<std::thread> pool;
  for (int t = 1; t < n; ++t) pool.emplace_back(work);
  work();
  for (auto& t : pool) t.join();
}

std::pair<Volume, Volume> Phantom::makeVolumes(const ProgressFn& progress) const {
  std::pair<Volume, Volume> maps{Volume(geometry(), ScalarType::UInt8),
                                 Volume(geometry(), ScalarType::UInt8)};
  maps.first.setLabelMap(true);
  maps.second.setLabelMap(true);
  maps.first.labels() = organLabels();
  maps.second.labels() = partLabels();
  const auto& dims = geometry().dims;
  const std::int64_t sliceVoxels = dims[0] * dims[1];
  const std::int64_t step = std::max<std::int64_t>(1, (8 << 20) / sliceVoxels);
  auto* g = maps.first.data<std::uint8_t>();
  auto* s = maps.second.data<std::uint8_t>();
  reportProgress(progress, 0.0, "phantom");
  for (std::int64_t k = 0; k < dims[2]; k += step) {
    const std::int64_t k1 = std::min(dims[2], k + step);
    fillSlices(k, k1, g + k * sliceVoxels, s + k * sliceVoxels);
    reportProgress(progress, double(k1) / dims[2], "phantom");
  }
  return maps;
}

Skeleton Phantom::skeleton() const {
  const LabelTable parts = partLabels();
  auto partName = [&](std::uint8_t p) {
    const Label* l = parts.find(p);
    return l ? l->name : std::string();
  };
  Skeleton out;
  for (const Joint& j : impl_->model.joints) {
    SkeletonJoint s;
    s.name = j.name;
    s.parent = j.parent;
    s.centre = j.ras;
    s.method = "phantom";
    for (const auto& [name, info] : impl_->model.jointInfo) {
      if (name != j.name) continue;
      s.axes = jointAxes(info.kind, info.distal, Eigen::Vector3d::UnitY(), Eigen::Vector3d::UnitZ(),
                         info.side, info.palmar);
      s.parts = {partName(info.proximal), partName(info.distalPart)};
      s.radiusMm = info.radiusMm;
    }
    out.joints.push_back(s);
  }
  return out;
}

std::string Phantom::skeletonJson() const {
  const PhantomOptions& o = impl_->options;
  const Eigen::Vector3d sp = o.spacing();
  nlohmann::json made = {{"made_by", "repose phantom"},
                         {"armsTouching", o.armsTouching},
                         {"armsResting", o.armsResting},
                         {"handGapMm", o.handGapMm},
                         {"forearmGapMm", o.forearmGapMm},
                         {"limbVesselMm", o.limbVesselMm},
                         {"girdlesTouching", o.girdlesTouching},
                         {"labels", o.labels == PhantomLabelling::Icrp110  ? "icrp110"
                                    : o.labels == PhantomLabelling::Coarse ? "coarse"
                                                                           : "phantom"},
                         {"spacing_mm", {sp.x(), sp.y(), sp.z()}}};
  return skeletonToJson(skeleton(), made.dump());
}

}  // namespace repose
