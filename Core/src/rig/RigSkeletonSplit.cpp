// A skeleton given as one label (a CT's bone threshold, a coarse map's "skeleton") split into the
// rig's bones by geometry, from its pieces (SkeletonPieces.h: components, touching bones parted by
// one voxel's erosion, contacts through the space between them). The pieces are told apart by
// where they are and what they touch: the pieces across the midline that chain through their
// contacts are the axial skeleton, the largest piece at the top the skull; straight long pieces
// reaching the axial skeleton's upper third are the humeri, those touching its lower half the
// femora; the pieces at a long bone's distal end are the next segment's, and those beyond the
// hand's or foot's; the pieces reaching out to the humeral head are the girdle. The axial
// skeleton is cut into the pelvis (below the iliac crests, beside the spine's column) and the
// spine with the ribs.
#include "SkeletonPieces.h"

#include "repose/util/Error.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <sstream>

namespace repose::rig {
namespace {
// A humerus or femur is a shaft: its second principal spread is under a quarter of its first
// (0.07-0.09 on the phantom's grids; a scapula's 0.3, the ribs' 0.5).
constexpr double kLongBoneSpread = 0.25;

// Voxel counts per slice band of `step` mm along z (RAS superior), from `z0`.
std::vector<double> widthProfile(const Piece& p, const Grid& grid, double z0, double step,
                                 std::size_t bands) {
  std::vector<double> lo(bands, 1e300), hi(bands, -1e300);
  for (const std::int64_t v : p.voxels) {
    const V r = grid.ras(v);
    const double t = (r.z() - z0) / step;
    if (t < 0 || t >= double(bands)) continue;
    const std::size_t b = std::size_t(t);
    lo[b] = std::min(lo[b], r.x()), hi[b] = std::max(hi[b], r.x());
  }
  std::vector<double> w(bands, 0);
  for (std::size_t b = 0; b < bands; ++b) w[b] = hi[b] >= lo[b] ? hi[b] - lo[b] : 0;
  return w;
}

}  // namespace

SkeletonSplit splitSkeleton(const std::vector<std::int64_t>& voxels, const Grid& grid,
                            const std::string& source) {
  SkeletonSplit out;
  if (voxels.empty()) return out;
  double zMin = 1e300, zMax = -1e300;
  V lo = V::Constant(1e300), hi = V::Constant(-1e300);
  std::vector<double> xs;
  xs.reserve(voxels.size() / 16 + 1);
  for (std::size_t i = 0; i < voxels.size(); ++i) {
    const V r = grid.ras(voxels[i]);
    lo = lo.cwiseMin(r), hi = hi.cwiseMax(r);
    if (i % 16 == 0) xs.push_back(r.x());
  }
  zMin = lo.z(), zMax = hi.z();
  std::nth_element(xs.begin(), xs.begin() + std::ptrdiff_t(xs.size() / 2), xs.end());
  const double midX = xs[xs.size() / 2], H = zMax - zMin;
  if (!(H > 0)) throw Error(source + ": the skeleton label has no height to split");
  // The split reads the file's RAS frame as the body's: head up (+S), arms below the shoulders.
  // A skeleton that is not tallest along S (a file whose orientation is wrong, a body lying
  // along another axis of its frame) is refused rather than split into nonsense.
  const V extent = hi - lo;
  if (H < 0.8 * std::max(extent.x(), extent.y()))
    throw Error(source + ": the skeleton label is " + std::to_string(std::lround(H)) +
                " mm tall along S but " +
                std::to_string(std::lround(std::max(extent.x(), extent.y()))) + " mm along " +
                (extent.x() > extent.y() ? "R-L" : "A-P") +
                ": it can be split into bones only upright in the file's frame (check its "
                "orientation)");
  // The split tells bones apart by where they lie in a whole body: a skeleton of part of one (a
  // chest CT's ribs and spine) would have its ribs taken for arms.
  constexpr double kWholeBodyMm = 700;  // a two-year-old's skeleton; any adult's is over 1,400
  if (H < kWholeBodyMm)
    throw Error(source + ": the skeleton label spans " + std::to_string(std::lround(H)) +
                " mm along S: it is split into bones only in a whole body (at least " +
                std::to_string(std::lround(kWholeBodyMm)) +
                " mm); name each bone's label instead (--labels FILE.csv)");
  // Only now the box around the skeleton: a refused map does not pay for it.
  SkeletonPieces split(voxels, grid);
  split.findPieces(midX, H);
  std::vector<Piece>& P = split.pieces();

  // The skull: the largest piece reaching within 30 mm of the highest point (on thick slices its
  // shell breaks and the crown may be a piece of its own); cut off the spine below it where it is
  // joined to it (where the slices narrow to 40 % of the skull's widest, going down).
  int skull = -1;
  for (const Piece& p : P) {
    const double near = std::max(30.0, 3 * grid.spacing.maxCoeff());
    if (p.top < zMax - near) continue;
    if (skull < 0 || p.voxels.size() > P[std::size_t(skull)].voxels.size())
      skull = int(&p - P.data());
  }
  if (P[std::size_t(skull)].top - P[std::size_t(skull)].bottom > 0.25 * H) {
    const double step = std::max(grid.spacing.z(), 2.0);
    const std::size_t bands = std::size_t(std::ceil(0.3 * H / step));
    const double z0 = P[std::size_t(skull)].top - double(bands) * step;
    const std::vector<double> w = widthProfile(P[std::size_t(skull)], grid, z0, step, bands);
    std::size_t widest = bands - 1;
    for (std::size_t b = bands; b-- > bands / 2;)
      if (w[b] > w[widest]) widest = b;
    std::size_t cut = widest;
    while (cut > 0 && w[cut] >= 0.4 * w[widest]) --cut;
    const double level = z0 + (double(cut) + 1) * step;
    const int top = split.carve(skull, [&](std::int64_t v) { return grid.ras(v).z() >= level; });
    if (top >= 0) skull = top;
  }
  P[std::size_t(skull)].kind = BoneKind::Skull, P[std::size_t(skull)].assigned = true;

  // The axial piece: the largest across the midline.
  int axial = -1;
  for (int i = 0; i < int(P.size()); ++i) {
    const Piece& p = P[std::size_t(i)];
    if (p.assigned || p.xMin > midX || p.xMax < midX) continue;
    if (axial < 0 || p.voxels.size() > P[std::size_t(axial)].voxels.size()) axial = i;
  }
  if (axial < 0)
    throw Error(source + ": the skeleton label has no spine (no piece of it crosses the midline)");
  P[std::size_t(axial)].kind = BoneKind::Spine, P[std::size_t(axial)].assigned = true;
  // A spine the discs part into vertebrae (1 mm grids), a pelvis apart from the sacrum: the
  // pieces across the midline chained to the largest through their contacts are one axial
  // skeleton, but for the sternum in front (more than 50 mm ahead of the largest's centre) and
  // the rest of a skull broken on thick slices (centred above the skull's lowest point).
  split.findContacts();
  {
    std::vector<int> chain{axial};
    bool grew = false;
    const double front = P[std::size_t(axial)].centroid.y() + 50;
    for (std::size_t q = 0; q < chain.size(); ++q)
      for (int i = 0; i < int(P.size()); ++i) {
        const Piece& p = P[std::size_t(i)];
        if (p.assigned || p.voxels.empty() || p.xMin > midX || p.xMax < midX ||
            p.centroid.y() > front || !split.contact(i, chain[q]) ||
            p.centroid.z() > P[std::size_t(skull)].bottom)
          continue;
        P[std::size_t(i)].assigned = true;
        chain.push_back(i);
      }
    for (std::size_t q = 1; q < chain.size(); ++q) split.merge(axial, chain[q]), grew = true;
    if (grew) split.findContacts();
  }
  // A skull the grid breaks into pieces (a thin shell on thick slices): every piece centred above
  // the skull's lowest point.
  for (Piece& p : P)
    if (!p.assigned && !p.voxels.empty() && p.centroid.z() > P[std::size_t(skull)].bottom)
      p.kind = BoneKind::Skull, p.assigned = true;
  const double axialMid = 0.5 * (P[std::size_t(axial)].top + P[std::size_t(axial)].bottom);
  auto sideOf = [&](const Piece& p) { return p.centroid.x() < midX ? -1 : +1; };

  // The sternum: a piece in front of the axial piece at the midline. Clavicles that reach the
  // midline over the manubrium are one piece with it: parted by the erosion (the largest part
  // across the midline is the sternum), and what crosses the midline of the rest cut there.
  const double axialTop = P[std::size_t(axial)].top, axialBottom = P[std::size_t(axial)].bottom;
  for (int i = 0; i < int(P.size()); ++i) {
    const Piece& p = P[std::size_t(i)];
    if (p.assigned || p.xMin > midX || p.xMax < midX ||
        p.centroid.y() <= P[std::size_t(axial)].centroid.y() || p.centroid.z() <= axialMid)
      continue;
    const std::vector<int> parts = split.partPiece(i, 0.05);
    P[std::size_t(i)].kind = BoneKind::Sternum, P[std::size_t(i)].assigned = true;
    for (std::size_t k = 1; k < parts.size(); ++k) {
      const Piece& q = P[std::size_t(parts[k])];
      if (q.xMin < midX && q.xMax > midX)
        split.carve(parts[k], [&](std::int64_t v) { return grid.ras(v).x() > midX; });
    }
    break;
  }

  // Per side: the femur and the humerus hanging from the axial piece, then their segments.
  std::vector<std::string> merged;
  std::map<int, V> heads;  // per side, the humeral head's end
  bool recontact = false;
  for (const int side : {-1, +1}) {
    const std::string word = side < 0 ? "left" : "right";
    auto candidates = [&](double minLength) {
      std::vector<int> c;
      for (int i = 0; i < int(P.size()); ++i)
        if (!P[std::size_t(i)].assigned && sideOf(P[std::size_t(i)]) == side &&
            P[std::size_t(i)].length >= minLength)
          c.push_back(i);
      return c;
    };
    auto take = [&](int i, BoneKind kind) {
      P[std::size_t(i)].kind = kind, P[std::size_t(i)].side = side;
      P[std::size_t(i)].assigned = true;
    };
    // The femur: the longest piece touching the axial piece in its lower half.
    int femur = -1;
    for (const int i : candidates(0.12 * H)) {
      const Contact* c = split.contact(i, axial);
      if (!c || c->at.z() > axialMid || P[std::size_t(i)].top > axialMid ||
          P[std::size_t(i)].spread > kLongBoneSpread)
        continue;
      if (femur < 0 || P[std::size_t(i)].length > P[std::size_t(femur)].length) femur = i;
    }
    if (femur >= 0) take(femur, BoneKind::Femur);
    // The humerus: the longest near-vertical piece reaching above the axial piece's middle,
    // touching it or a piece that touches it (the scapula).
    int humerus = -1;
    for (const int i : candidates(0.1 * H)) {
      const Piece& p = P[std::size_t(i)];
      // At the shoulders: its top in the axial piece's upper third (an arm held away from the
      // trunk touches nothing there).
      if (p.top < axialTop - (axialTop - axialBottom) / 3 || std::fabs(p.axis.z()) < 0.5 ||
          p.spread > kLongBoneSpread)
        continue;
      if (humerus < 0 || p.length > P[std::size_t(humerus)].length) humerus = i;
    }
    // A humerus the grid joined to its scapula at the glenoid: parted where the erosion parts
    // them, the humerus then the longest near-vertical part.
    if (humerus >= 0) {
      const std::vector<int> parts = split.partPiece(humerus, 0.1);
      for (const int i : parts)
        if (std::fabs(P[std::size_t(i)].axis.z()) >= 0.5 &&
            P[std::size_t(i)].length > P[std::size_t(humerus)].length)
          humerus = i;
      if (parts.size() > 1) recontact = true;
      take(humerus, BoneKind::Humerus);
    }
    // A root bone far longer than its bone is two bones joined across a joint (on coarse
    // grids the elbow's and the knee's joint spaces close): cut where it is thinnest about
    // where the joint lies in proportion (the humerus 56 % of the arm to the wrist, the femur
    // half the leg to the ankle; Drillis and Contini's segment lengths), else refuse.
    auto cutAtJoint = [&](int bone, double longest, double lo, double hi, BoneKind distal,
                          const std::string& what, const std::string& joint) {
      if (bone < 0 || P[std::size_t(bone)].length <= longest * H) return;
      const V u = P[std::size_t(bone)].axis.z() > 0 ? V(-P[std::size_t(bone)].axis)
                                                    : P[std::size_t(bone)].axis;
      const int d = split.cutAcross(bone, u, lo, hi);
      if (d < 0 || P[std::size_t(bone)].length > longest * H) {
        merged.push_back("the " + word + " " + what + " (no gap at the " + joint + ")");
        return;
      }
      take(d, distal);
      out.notes.push_back("the " + word + " " + what + " are one piece: cut at the " + joint +
                          "'s narrowest");
      recontact = true;
    };
    cutAtJoint(femur, 0.34, 0.4, 0.6, BoneKind::Shank, "femur and tibia", "knee");
    cutAtJoint(humerus, 0.27, 0.45, 0.68, BoneKind::Forearm, "humerus and forearm", "elbow");
    if (recontact) split.findContacts(), recontact = false;

    // A limb's segments beyond its root bone: the pieces at its distal end, then what lies
    // beyond them.
    auto limb = [&](int root, BoneKind second, BoneKind third) {
      if (root < 0) return;
      const Piece& r = P[std::size_t(root)];
      // Distal: away from the end the root hangs from (its higher end: arms and legs hang down
      // in the rest postures a split map can be rigged in).
      const V u = r.axis.z() > 0 ? V(-r.axis) : r.axis;
      double far = -1e300;
      for (const std::int64_t v : r.voxels) far = std::max(far, grid.ras(v).dot(u));
      std::vector<int> seg;
      for (int i = 0; i < int(P.size()); ++i)  // cut off the root at the joint
        if (P[std::size_t(i)].kind == second && P[std::size_t(i)].side == side) seg.push_back(i);
      for (int i = 0; i < int(P.size()); ++i) {
        const Piece& p = P[std::size_t(i)];
        const Contact* c = split.contact(i, root);
        if (p.assigned || !c || sideOf(p) != side) continue;
        if (c->at.dot(u) < far - 0.25 * r.length) continue;  // not at the distal end
        take(i, second), seg.push_back(i);
      }
      if (seg.empty()) return;
      // Long pieces beside the segment's (the fibula beside the tibia, the ulna beside the
      // radius when only one touches the root).
      int longest = seg[0];
      for (const int i : seg)
        if (P[std::size_t(i)].length > P[std::size_t(longest)].length) longest = i;
      const V u2 = P[std::size_t(longest)].axis.dot(u) >= 0 ? P[std::size_t(longest)].axis
                                                            : V(-P[std::size_t(longest)].axis);
      const V base = P[std::size_t(longest)].centroid;
      const double half = 0.5 * P[std::size_t(longest)].length;
      for (int i = 0; i < int(P.size()); ++i) {
        const Piece& p = P[std::size_t(i)];
        if (p.assigned || sideOf(p) != side || p.length < 0.5 * half) continue;
        bool beside = false;
        for (const int s : seg) beside = beside || split.contact(i, s);
        if (beside && std::fabs((p.centroid - base).dot(u2)) < 0.5 * half) take(i, second);
      }
      for (int i = 0; i < int(P.size()); ++i)
        if (P[std::size_t(i)].kind == second && P[std::size_t(i)].side == side &&
            std::find(seg.begin(), seg.end(), i) == seg.end())
          seg.push_back(i);
      // Beyond: every piece reached from the segment past its middle, and on from those.
      std::vector<int> front = seg;
      while (!front.empty()) {
        std::vector<int> nextFront;
        for (const int s : front)
          for (int i = 0; i < int(P.size()); ++i) {
            const Piece& p = P[std::size_t(i)];
            if (p.assigned || sideOf(p) != side || !split.contact(i, s)) continue;
            if ((p.centroid - base).dot(u2) <= 0) continue;
            take(i, third), nextFront.push_back(i);
          }
        front.swap(nextFront);
      }
    };
    limb(humerus, BoneKind::Forearm, BoneKind::Hand);
    limb(femur, BoneKind::Shank, BoneKind::Foot);

    // The girdle: pieces about the shoulder's height that reach out as far as the humeral
    // head (the clavicle to the acromion, the scapula to the glenoid; the ribs stay inside),
    // for now all as the scapula: front and back are told apart once the pieces that touch
    // them have joined them.
    if (humerus >= 0) {
      const Piece& h = P[std::size_t(humerus)];
      const V head = h.axis.z() > 0 ? V(h.centroid + 0.5 * h.length * h.axis)
                                    : V(h.centroid - 0.5 * h.length * h.axis);
      heads[side] = head;
      const double headOut = double(side) * (head.x() - midX);
      for (int i = 0; i < int(P.size()); ++i) {
        const Piece& p = P[std::size_t(i)];
        if (p.assigned || sideOf(p) != side) continue;
        if (std::fabs(p.centroid.z() - head.z()) > 0.1 * H) continue;
        const double out = side < 0 ? midX - p.xMin : p.xMax - midX;
        if (out >= 0.75 * headOut) take(i, BoneKind::Scapula);
      }
      // A clavicle the grid breaks in its thin middle: the pieces on the line from the girdle's
      // front end nearest the midline to the sternum's top.
      V front = V::Zero();
      double best = -1e300;
      for (const Piece& p : P)
        if (p.kind == BoneKind::Scapula && p.side == side)
          for (const std::int64_t v : p.voxels) {
            const V r = grid.ras(v);
            if (r.y() > head.y() && -double(side) * (r.x() - midX) > best)
              best = -double(side) * (r.x() - midX), front = r;
          }
      const Piece* sternum = nullptr;
      for (const Piece& p : P)
        if (p.kind == BoneKind::Sternum) sternum = &p;
      if (best > -1e300 && sternum) {
        V top = sternum->centroid;
        for (const std::int64_t v : sternum->voxels)
          if (grid.ras(v).z() > top.z()) top = grid.ras(v);
        const V ab = top - front;
        const double reach = std::max(20.0, 3 * grid.spacing.maxCoeff());
        for (int i = 0; i < int(P.size()); ++i) {
          const Piece& p = P[std::size_t(i)];
          if (p.assigned || sideOf(p) != side) continue;
          const double t = std::clamp((p.centroid - front).dot(ab) / ab.squaredNorm(), 0.0, 1.0);
          if ((p.centroid - (front + t * ab)).norm() <= reach) take(i, BoneKind::Scapula);
        }
      }
    }
  }
  if (!merged.empty()) {
    std::string list;
    for (const std::string& m : merged) list += (list.empty() ? "" : ", ") + m;
    throw Error(source + ": the skeleton label cannot be split into bones: it joins " + list);
  }

  // The pelvis: the axial piece below the iliac crests, beside the spine. The lumbar spine is the
  // narrowest stretch of the axial piece between its bottom and its middle; the crests are the
  // highest level below it at least twice as wide; the spine's column there is the lumbar
  // stretch's footprint.
  {
    Piece& a = P[std::size_t(axial)];
    const double step = std::max(grid.spacing.z(), 4.0);
    const std::size_t bands = std::size_t(std::ceil((axialMid - a.bottom) / step));
    const std::vector<double> w = widthProfile(a, grid, a.bottom, step, bands);
    std::size_t narrow = bands;
    for (std::size_t b = bands / 4; b < bands; ++b)
      if (w[b] > 0 && (narrow == bands || w[b] < w[narrow])) narrow = b;
    std::size_t crest = bands;
    if (narrow < bands)
      for (std::size_t b = narrow; b-- > 0;)
        if (w[b] >= 2 * w[narrow]) {
          crest = b;
          break;
        }
    if (crest < bands) {
      const double zCrest = a.bottom + (double(crest) + 1) * step,
                   zLumbar = a.bottom + (double(narrow) + 1) * step;
      Eigen::Vector2d c = Eigen::Vector2d::Zero();
      int count = 0;
      for (const std::int64_t v : a.voxels) {
        const V r = grid.ras(v);
        if (r.z() >= zLumbar - step && r.z() < zLumbar) c += r.head<2>(), ++count;
      }
      if (count > 0) {
        c /= double(count);
        // The column's radius: the vertebral body's and arch's, not the transverse
        // processes' (which would take in the sacroiliac region beside it).
        std::vector<double> reach;
        for (const std::int64_t v : a.voxels) {
          const V r = grid.ras(v);
          if (r.z() >= zLumbar - step && r.z() < zLumbar) reach.push_back((r.head<2>() - c).norm());
        }
        std::nth_element(reach.begin(), reach.begin() + std::ptrdiff_t(reach.size() / 2),
                         reach.end());
        const double radius = reach[reach.size() / 2] + grid.spacing.head<2>().maxCoeff();
        // Below the crests the column is the spine only where a slice of it is a vertebra's
        // section (at least half the lumbar slices' mean): in a disc's gap, what lies within the
        // column's radius is the pelvis's.
        const double dz = grid.spacing.z();
        auto slice = [&](double z) { return std::int64_t(std::floor(z / dz)); };
        std::map<std::int64_t, int> lumbarSlices, columnSlices;
        for (const std::int64_t v : a.voxels) {
          const V r = grid.ras(v);
          if ((r.head<2>() - c).norm() > radius) continue;
          if (r.z() >= zLumbar - step && r.z() < zLumbar) ++lumbarSlices[slice(r.z())];
          if (r.z() < zCrest) ++columnSlices[slice(r.z())];
        }
        double lumbarMean = 0;
        for (const auto& [k, n] : lumbarSlices) lumbarMean += n;
        lumbarMean /= double(std::max<std::size_t>(1, lumbarSlices.size()));
        const int pelvis = split.carve(axial, [&](std::int64_t v) {
          const V r = grid.ras(v);
          if (r.z() >= zCrest) return false;
          return (r.head<2>() - c).norm() > radius || columnSlices[slice(r.z())] < 0.5 * lumbarMean;
        });
        if (pelvis >= 0 && pelvis != axial)
          P[std::size_t(pelvis)].kind = BoneKind::Pelvis, P[std::size_t(pelvis)].assigned = true;
      }
    }
  }

  // The rest (ribs apart from the spine, a mandible, small pieces) goes with the nearest of the
  // trunk's and head's bones where it touches them (a first rib under the clavicle touches both
  // it and the spine), else with what it touches nearest.
  auto axialKind = [](BoneKind k) {
    return k == BoneKind::Spine || k == BoneKind::Sternum || k == BoneKind::Pelvis ||
           k == BoneKind::Skull;
  };
  for (int round = 0; round < 4; ++round)
    for (int i = 0; i < int(P.size()); ++i) {
      Piece& p = P[std::size_t(i)];
      if (p.assigned) continue;
      const Contact* best = nullptr;
      int with = -1;
      bool trunk = false;
      for (int j = 0; j < int(P.size()); ++j) {
        const Contact* c = j == i || !P[std::size_t(j)].assigned ? nullptr : split.contact(i, j);
        if (!c) continue;
        const bool t = axialKind(P[std::size_t(j)].kind);
        if (!best || (t && !trunk) || (t == trunk && c->distance < best->distance))
          best = c, with = j, trunk = trunk || t;
      }
      if (with >= 0) p.kind = P[std::size_t(with)].kind, p.side = P[std::size_t(with)].side;
      if (with >= 0) p.assigned = true;
    }
  // Pieces too far from any other for a contact (a toe's phalanges): with the piece nearest
  // their centre.
  for (Piece& p : P) {
    if (p.assigned) continue;
    double best = 1e300;
    const Piece* with = nullptr;
    for (const Piece& q : P) {
      if (!q.assigned) continue;
      const std::size_t stride = std::max<std::size_t>(1, q.voxels.size() / 4096);
      for (std::size_t k = 0; k < q.voxels.size(); k += stride) {
        const double d = (grid.ras(q.voxels[k]) - p.centroid).squaredNorm();
        if (d < best) best = d, with = &q;
      }
    }
    if (with) p.kind = with->kind, p.side = with->side, p.assigned = true;
  }
  for (Piece& p : P) {
    if (!p.assigned) p.kind = BoneKind::Spine, p.side = 0;
    if (p.kind == BoneKind::Scapula && heads.count(p.side)) {
      // The girdle in front of the humeral head is the clavicle's (its medial end is the
      // sternoclavicular joint's), behind it the scapula's.
      const double y = heads[p.side].y();
      for (const std::int64_t v : p.voxels)
        out.bones[{grid.ras(v).y() > y ? BoneKind::Clavicle : BoneKind::Scapula, p.side}].push_back(
            v);
      continue;
    }
    auto& dst = out.bones[{p.kind, p.side}];
    dst.insert(dst.end(), p.voxels.begin(), p.voxels.end());
  }
  std::ostringstream note;
  note << "the skeleton label split into " << out.bones.size() << " bones from " << P.size()
       << " pieces";
  out.pieces = int(P.size());
  out.notes.push_back(note.str());
  return out;
}

}  // namespace repose::rig
