// Scan conversion of deformed tets onto an output grid (seed §4.3), the engine behind the label,
// image, coverage and slice rasterizers.
//
// Everything happens in the output grid's continuous IJK space, where voxel (i,j,k)'s centre is
// the point (i,j,k). For each tet and each row (j,k) of its bounding box the voxels inside form
// one interval, found from the four face planes and then checked voxel by voxel at its ends, so
// the interval is exactly the set the inside predicate accepts. The rest position (input IJK) is
// affine in the output position, so along a row it advances by a constant step.
//
// Tie rule: each face plane is computed from its three vertices in increasing index order, so the
// two tets sharing a face evaluate bit-identical plane values at every voxel centre. A centre on a
// plane is decided as if moved by (e, e^2, e^3) for an infinitesimal e (simulation of
// simplicity): the sign of the value, else of the normal's x, y, z. Every centre then lies strictly
// inside or outside each tet, and one inside a conforming mesh is in exactly one tet. This is
// exact when the plane values are (vertices on the grid, as for an identity or a whole-voxel
// shift: RasterizerTest). A centre exactly on a face or edge through vertices at arbitrary
// positions is decided by the rounded value, which can write it twice or not at all; for a
// deformed mesh that is a measure-zero event (exact predicates would remove it at some cost).
// (ReposeCore is compiled with -ffp-contract=off so no fused multiply-add breaks that identity.)
#pragma once

#include "repose/mesh/TransferMesh.h"
#include "repose/volume/VolumeGeometry.h"

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <Eigen/LU>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

namespace repose::raster {

// floor and ceil as integers without a call into libm (the x86-64 baseline has no rounding
// instruction, and these run per voxel and per row). Exact for |x| < 2^52; beyond, where every
// double is a whole number far outside any grid, saturated at +-2^52 (NaN goes low), so the
// callers' clamps to the grid decide as before and no conversion overflows.
constexpr double kWholeLimit = 4503599627370496.0;  // 2^52
inline std::int64_t floorToInt(double x) {
  if (!(x > -kWholeLimit)) return -static_cast<std::int64_t>(kWholeLimit);
  if (!(x < kWholeLimit)) return static_cast<std::int64_t>(kWholeLimit);
  const auto t = static_cast<std::int64_t>(x);
  return t - (static_cast<double>(t) > x ? 1 : 0);
}
inline std::int64_t ceilToInt(double x) {
  if (!(x > -kWholeLimit)) return -static_cast<std::int64_t>(kWholeLimit);
  if (!(x < kWholeLimit)) return static_cast<std::int64_t>(kWholeLimit);
  const auto t = static_cast<std::int64_t>(x);
  return t + (static_cast<double>(t) < x ? 1 : 0);
}

// Vertex positions mapped once into the grids the scan works in.
struct ScanInput {
  const Eigen::MatrixX4i* tets = nullptr;
  const std::vector<int>* pieces = nullptr;   // TransferMesh::rigid (may be empty)
  std::vector<Eigen::Vector3d> out;           // deformed positions in output IJK
  std::vector<Eigen::Vector3d> rest;          // rest positions in input IJK
  std::array<std::int64_t, 3> dims{0, 0, 0};  // output grid
};

inline ScanInput makeScanInput(const TransferMesh& mesh, const Eigen::MatrixX3d& deformed,
                               const VolumeGeometry& input, const VolumeGeometry& output) {
  ScanInput s;
  s.tets = &mesh.tets;
  s.pieces = &mesh.rigid;
  s.dims = output.dims;
  const Eigen::Matrix4d toOut = output.ijkToRas.inverse(), toIn = input.ijkToRas.inverse();
  s.out.resize(static_cast<std::size_t>(deformed.rows()));
  s.rest.resize(s.out.size());
  for (Eigen::Index v = 0; v < deformed.rows(); ++v) {
    s.out[v] = toOut.block<3, 3>(0, 0) * deformed.row(v).transpose() + toOut.block<3, 1>(0, 3);
    s.rest[v] = toIn.block<3, 3>(0, 0) * mesh.vertices.row(v).transpose() + toIn.block<3, 1>(0, 3);
  }
  return s;
}

struct Plane {
  Eigen::Vector3d n;
  double d = 0;
  int side = 0;  // +1 or -1: the sign the tet's inside has
  double at(double i, double j, double k) const {
    return ((n.x() * i + n.y() * j) + n.z() * k) - d;
  }
  // Sign at (i,j,k) after the infinitesimal shift (e, e^2, e^3).
  int sign(double i, double j, double k) const {
    const double s = at(i, j, k);
    if (s != 0) return s > 0 ? 1 : -1;
    if (n.x() != 0) return n.x() > 0 ? 1 : -1;
    if (n.y() != 0) return n.y() > 0 ? 1 : -1;
    return n.z() > 0 ? 1 : (n.z() < 0 ? -1 : 0);
  }
  bool accepts(double i, double j, double k) const { return sign(i, j, k) == side; }
};

// A tet's four vertex indices, in the mesh's order.
using TetVertices = std::array<int, 4>;

// One deformed tet ready to scan. The map back to rest positions is made when the scan first
// finds a voxel inside (mapToRest): most tets a live slice prepares hold none, and the rest
// positions are the second half of the vertex data a tet reads.
struct ScanTet {
  std::array<Plane, 4> faces;
  Eigen::Matrix3d D;                   // output edges from vertex 0 (columns)
  Eigen::Matrix3d A;                   // d(rest input IJK) / d(output IJK), once mapped
  Eigen::Vector3d q0, r0;              // vertex 0: output and rest positions, once mapped
  std::array<std::int64_t, 3> lo, hi;  // voxel-centre bounding box, clipped to the grid
  double signedVolume = 0;             // in output IJK units; < 0 for a tet turned inside out
  const std::vector<Eigen::Vector3d>* rest = nullptr;
  TetVertices v{0, 0, 0, 0};
  bool mapped = false;
  void mapToRest() {
    if (mapped) return;
    Eigen::Matrix3d R;
    for (int c = 0; c < 3; ++c) R.col(c) = (*rest)[v[c + 1]] - (*rest)[v[0]];
    A = R * D.inverse();
    r0 = (*rest)[v[0]];
    mapped = true;
  }
};

inline TetVertices tetVertices(const ScanInput& in, Eigen::Index t) {
  const Eigen::MatrixX4i& T = *in.tets;
  return {T(t, 0), T(t, 1), T(t, 2), T(t, 3)};
}

// False for a tet whose deformed volume is zero (no voxel can be inside it) or whose box misses
// the grid. Taking the vertex indices (a candidate list keeps them beside the tet's number)
// spares the four reads from the mesh's index columns, which for the few tets a slice meets
// are scattered cache misses.
inline bool prepareTet(const ScanInput& in, const TetVertices& v, ScanTet& s,
                       const std::array<double, 3>& boxGrowth = {0, 0, 0}) {
  const Eigen::Vector3d &p0 = in.out[v[0]], &p1 = in.out[v[1]], &p2 = in.out[v[2]],
                        &p3 = in.out[v[3]];
  for (int c = 0; c < 3; ++c) {
    const double mn = std::min(std::min(p0[c], p1[c]), std::min(p2[c], p3[c]));
    const double mx = std::max(std::max(p0[c], p1[c]), std::max(p2[c], p3[c]));
    s.lo[c] = std::max<std::int64_t>(0, ceilToInt(mn - boxGrowth[c]));
    s.hi[c] = std::min<std::int64_t>(in.dims[c] - 1, floorToInt(mx + boxGrowth[c]));
    if (s.lo[c] > s.hi[c]) return false;
  }
  s.D.col(0) = p1 - p0, s.D.col(1) = p2 - p0, s.D.col(2) = p3 - p0;
  s.signedVolume = s.D.determinant() / 6;
  if (!(s.signedVolume != 0) || !std::isfinite(s.signedVolume)) return false;
  // Face f is opposite vertex f; its plane from the other three in increasing index order.
  for (int f = 0; f < 4; ++f) {
    int a = v[f == 0 ? 1 : 0], b = v[f <= 1 ? 2 : 1], c = v[f <= 2 ? 3 : 2];
    if (a > b) std::swap(a, b);
    if (b > c) std::swap(b, c);
    if (a > b) std::swap(a, b);
    const Eigen::Vector3d &pa = in.out[a], &pb = in.out[b], &pc = in.out[c];
    Plane& p = s.faces[f];
    p.n = (pb - pa).cross(pc - pa);
    p.d = (p.n.x() * pa.x() + p.n.y() * pa.y()) + p.n.z() * pa.z();
    const double opposite = p.at(in.out[v[f]].x(), in.out[v[f]].y(), in.out[v[f]].z());
    if (opposite == 0) return false;  // flat in floating point
    p.side = opposite > 0 ? 1 : -1;
  }
  s.q0 = p0;
  s.rest = &in.rest;
  s.v = v;
  s.mapped = false;
  return true;
}

inline bool prepareTet(const ScanInput& in, Eigen::Index t, ScanTet& s,
                       const std::array<double, 3>& boxGrowth = {0, 0, 0}) {
  return prepareTet(in, tetVertices(in, t), s, boxGrowth);
}

// The tet grown beyond its outer faces (bits of `outer`, face f opposite vertex f) by `shell` mm
// (`normalToMm` = M^-T for the output's IJK->RAS linear part M, so |M^-T n| turns a plane value
// into mm), clipped to its box grown by `boxGrowth` voxels per axis. For the voxels just outside
// the mesh's surface, which Mesh_3 places only to within a voxel of the label boundary.
inline bool prepareShell(const ScanInput& in, const TetVertices& v, unsigned outer, double shell,
                         const Eigen::Matrix3d& normalToMm, const std::array<double, 3>& boxGrowth,
                         ScanTet& s) {
  if (!prepareTet(in, v, s, boxGrowth)) return false;
  for (int f = 0; f < 4; ++f)
    if (outer & (1u << f)) {
      Plane& p = s.faces[f];
      p.d -= p.side * shell * (normalToMm * p.n).norm();
    }
  return true;
}

inline bool prepareShell(const ScanInput& in, Eigen::Index t, unsigned outer, double shell,
                         const Eigen::Matrix3d& normalToMm, const std::array<double, 3>& boxGrowth,
                         ScanTet& s) {
  return prepareShell(in, tetVertices(in, t), outer, shell, normalToMm, boxGrowth, s);
}

inline bool inside(const ScanTet& s, double i, double j, double k) {
  return s.faces[0].accepts(i, j, k) && s.faces[1].accepts(i, j, k) &&
         s.faces[2].accepts(i, j, k) && s.faces[3].accepts(i, j, k);
}

// Calls span(k, j, i0, i1, rest0, step) for every row interval [i0, i1] of voxels inside the tet
// with k in [k0, k1) and j in [j0, j1); rest0 is the rest position (input IJK) of voxel i0 and
// step its change per voxel along i.
template <class Span>
void scanTet(ScanTet& s, std::int64_t k0, std::int64_t k1, std::int64_t j0, std::int64_t j1,
             Span&& span) {
  const std::int64_t kb = std::max(k0, s.lo[2]), ke = std::min(k1 - 1, s.hi[2]);
  const std::int64_t jb = std::max(j0, s.lo[1]), je = std::min(j1 - 1, s.hi[1]);
  // Along a row each face's signed value is slope * i + c(j, k); the real interval is where all
  // four are positive. A rounded root more than kSettle from a whole number decides like the exact
  // predicate (the rounding error is ~1e-12 voxel); only an end within kSettle of a voxel centre is
  // settled by the predicate itself, one voxel either way.
  constexpr double kSettle = 1e-7;
  std::array<double, 4> slope, negInv;
  for (int f = 0; f < 4; ++f) {
    slope[f] = s.faces[f].side * s.faces[f].n.x();
    negInv[f] = slope[f] != 0 ? -1.0 / slope[f] : 0.0;
  }
  const double lo = double(s.lo[0]), hi = double(s.hi[0]);
  for (std::int64_t k = kb; k <= ke; ++k)
    for (std::int64_t j = jb; j <= je; ++j) {
      const double dj = double(j), dk = double(k);
      double a = -std::numeric_limits<double>::infinity(), b = -a;
      bool empty = false;
      for (int f = 0; f < 4; ++f) {
        const Plane& p = s.faces[f];
        if (slope[f] == 0) {
          empty = empty || !p.accepts(0, dj, dk);
          continue;
        }
        const double root = p.side * p.at(0, dj, dk) * negInv[f];
        if (slope[f] > 0)
          a = std::max(a, root);
        else
          b = std::min(b, root);
      }
      if (empty || a > b + 1 || a > hi + 1 || b < lo - 1) continue;
      std::int64_t i0 = s.lo[0], i1 = s.hi[0];
      if (a >= lo - kSettle) {
        i0 = ceilToInt(a);
        if (double(i0) - a < kSettle) {
          if (!inside(s, double(i0), dj, dk)) ++i0;
        } else if (a - double(i0 - 1) < kSettle && i0 - 1 >= s.lo[0] &&
                   inside(s, double(i0 - 1), dj, dk)) {
          --i0;
        }
        i0 = std::max(i0, s.lo[0]);
      }
      if (b <= hi + kSettle) {
        i1 = floorToInt(b);
        if (b - double(i1) < kSettle) {
          if (!inside(s, double(i1), dj, dk)) --i1;
        } else if (double(i1 + 1) - b < kSettle && i1 + 1 <= s.hi[0] &&
                   inside(s, double(i1 + 1), dj, dk)) {
          ++i1;
        }
        i1 = std::min(i1, s.hi[0]);
      }
      if (i0 > i1) continue;
      s.mapToRest();
      const Eigen::Vector3d x{double(i0), dj, dk};
      span(k, j, i0, i1, Eigen::Vector3d(s.r0 + s.A * (x - s.q0)), Eigen::Vector3d(s.A.col(0)));
    }
}

}  // namespace repose::raster
