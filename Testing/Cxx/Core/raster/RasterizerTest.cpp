// The rasterizer (seed §4.3): every voxel centre written exactly once under the tie rule, exact
// identity / quarter-turn / whole-voxel translation on the phantom, a rigid forearm under elbow
// flexion, images with trilinear interpolation, a grid that never clips, folds reported.
#include "RasterFixtures.h"
#include "TestPaths.h"
#include "TestTetMeshes.h"

#include "repose/cage/CageBuilder.h"
#include "repose/io/SliceCache.h"
#include "repose/io/VolumeIO.h"
#include "repose/mesh/RigiditySolver.h"
#include "repose/mesh/TransferMesh.h"
#include "repose/phantom/Phantom.h"
#include "repose/phantom/PhantomPoses.h"
#include "repose/raster/RasterFile.h"
#include "repose/raster/Rasterizer.h"
#include "repose/util/Error.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cstring>
#include <map>
#include <numeric>
#include <random>

using namespace repose;
using namespace repose::test;

namespace {

// Voxel centres on many faces, edges and vertices: a box of 6x5x4 cells of 2 voxels each.
TransferMesh alignedBox() {
  return tetBox({2, 2, 2}, {14, 12, 10}, {6, 5, 4});
}

// Under the tie rule a centre on the boundary counts as inside iff moving it by (+e, +e^2, +e^3)
// enters the box: the half-open box [lo, hi) in every axis.
void expectHalfOpenBox(const Volume& coverage, const Eigen::Vector3i& lo,
                       const Eigen::Vector3i& hi) {
  const std::uint8_t* c = coverage.data<std::uint8_t>();
  const auto d = coverage.dims();
  int wrong = 0;
  for (std::int64_t k = 0; k < d[2]; ++k)
    for (std::int64_t j = 0; j < d[1]; ++j)
      for (std::int64_t i = 0; i < d[0]; ++i) {
        const bool in =
            i >= lo.x() && i < hi.x() && j >= lo.y() && j < hi.y() && k >= lo.z() && k < hi.z();
        wrong += c[coverage.index(i, j, k)] != (in ? 1 : 0);
      }
  EXPECT_EQ(wrong, 0);
}

// Expected output: the label of G at the rest position rest(c) of each output voxel centre c.
template <class RestOf>
Volume mapDirectly(const Volume& G, const VolumeGeometry& out, RestOf&& restOf) {
  Volume v(out, G.scalarType());
  const auto d = out.dims;
  for (std::int64_t k = 0; k < d[2]; ++k)
    for (std::int64_t j = 0; j < d[1]; ++j)
      for (std::int64_t i = 0; i < d[0]; ++i) {
        const Eigen::Vector3d p = G.geometry().rasToVoxel(restOf(out.voxelToRas(i, j, k)));
        const Eigen::Vector3d r = (p.array() + 0.5).floor();
        if ((r.array() < 0).any() || r.x() >= G.dims()[0] || r.y() >= G.dims()[1] ||
            r.z() >= G.dims()[2])
          continue;
        v.data<std::uint8_t>()[v.index(i, j, k)] = G.data<std::uint8_t>()[G.index(
            std::int64_t(r.x()), std::int64_t(r.y()), std::int64_t(r.z()))];
      }
  return v;
}

std::int64_t countDifferent(const Volume& a, const Volume& b) {
  EXPECT_EQ(a.dims(), b.dims());
  std::int64_t n = 0;
  for (std::int64_t v = 0; v < a.numVoxels(); ++v)
    n += a.data<std::uint8_t>()[v] != b.data<std::uint8_t>()[v];
  return n;
}

}  // namespace

TEST(Rasterizer, EveryCentreOnSharedFacesEdgesAndVerticesIsWrittenOnce) {
  const TransferMesh box = alignedBox();
  const Volume coverage = rasterizeCoverage(box, box.vertices, unitGrid({18, 16, 14}));
  expectHalfOpenBox(coverage, {2, 2, 2}, {14, 12, 10});
}

// The ownership rule where faces, edges and vertices pass through many centres at other scales
// and offsets: boxes of Kuhn-split cells of 0.5 to 3 voxels (anisotropic too), shifted by whole,
// half and quarter voxels, so diagonal faces cut the grid through rows of centres. Every centre
// is claimed by exactly one tet inside, by none outside, and the outer boundary follows the tie
// rule: the half-open box [lo, hi) on every axis.
TEST(Rasterizer, EveryCentreHasOneOwnerOnScaledAndShiftedMeshes) {
  struct Case {
    Eigen::Vector3d cell, shift;
  };
  int cases = 0;
  for (const Case& c : {Case{{3, 3, 3}, {1, 2, 3}}, Case{{0.5, 0.5, 0.5}, {0.5, 0.25, 0}},
                        Case{{1.5, 2, 0.75}, {0.25, 0.5, 1}}, Case{{2, 1, 3}, {-0.5, 0, 0.5}},
                        Case{{1, 1, 1}, {0.75, 0.75, 0.25}}}) {
    const std::array<int, 3> n{5, 4, 3};
    const Eigen::Vector3d lo = Eigen::Vector3d(3, 3, 3) + c.shift;
    const Eigen::Vector3d hi = lo + c.cell.cwiseProduct(Eigen::Vector3d(n[0], n[1], n[2]));
    const TransferMesh box = tetBox(lo, hi, n);
    const VolumeGeometry grid =
        unitGrid({std::int64_t(hi.x()) + 3, std::int64_t(hi.y()) + 3, std::int64_t(hi.z()) + 3});
    const Volume coverage = rasterizeCoverage(box, box.vertices, grid);
    const std::uint8_t* count = coverage.data<std::uint8_t>();
    std::int64_t wrong = 0, inside = 0, onAFace = 0;
    for (std::int64_t k = 0; k < grid.dims[2]; ++k)
      for (std::int64_t j = 0; j < grid.dims[1]; ++j)
        for (std::int64_t i = 0; i < grid.dims[0]; ++i) {
          const Eigen::Vector3d p{double(i), double(j), double(k)};
          const bool in = (p.array() >= lo.array()).all() && (p.array() < hi.array()).all();
          inside += in;
          wrong += count[coverage.index(i, j, k)] != (in ? 1 : 0);
          // Centres on a cell's face plane (axis-aligned) or on its diagonal planes.
          const Eigen::Vector3d u = (p - lo).cwiseQuotient(c.cell);
          const Eigen::Vector3d f = u - u.array().floor().matrix();
          onAFace +=
              in && ((f.array() == 0).any() || f.x() == f.y() || f.y() == f.z() || f.x() == f.z());
        }
    EXPECT_EQ(wrong, 0) << "cell " << c.cell.transpose() << ", shift " << c.shift.transpose();
    EXPECT_GT(onAFace, inside / 10) << "the case must put many centres on faces";
    // A grid one slice thick takes its tets from their cross-sections with the plane, which
    // here pass through vertices, edges and faces: each plane equals that of the full grid.
    const std::int64_t area = grid.dims[0] * grid.dims[1];
    for (std::int64_t k = 0; k < grid.dims[2]; ++k) {
      VolumeGeometry plane = grid;
      plane.dims[2] = 1;
      plane.ijkToRas.block<3, 1>(0, 3) = grid.voxelToRas(0, 0, double(k));
      const Volume one = rasterizeCoverage(box, box.vertices, plane);
      EXPECT_TRUE(
          std::equal(one.data<std::uint8_t>(), one.data<std::uint8_t>() + area, count + k * area))
          << "plane " << k << ", cell " << c.cell.transpose() << ", shift " << c.shift.transpose();
    }
    ++cases;
  }
  EXPECT_EQ(cases, 5);
}

// Interior vertices in general position: no crack and no double write across any shared face.
// (The grid is offset by a fraction of a voxel so no centre lies exactly on a face or edge through
// a moved vertex: there the plane value is rounding noise, see TetScan.h.)
TEST(Rasterizer, NoCrackOrOverlapWhenInteriorVerticesMove) {
  TransferMesh box = alignedBox();
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> jitter(-0.3, 0.3);
  Eigen::MatrixX3d moved = box.vertices;
  for (Eigen::Index v = 0; v < moved.rows(); ++v) {
    const Eigen::RowVector3d p = moved.row(v);
    const bool interior =
        p.x() > 2 && p.x() < 14 && p.y() > 2 && p.y() < 12 && p.z() > 2 && p.z() < 10;
    if (interior) moved.row(v) += Eigen::RowVector3d(jitter(rng), jitter(rng), jitter(rng));
  }
  RasterReport report;
  const VolumeGeometry grid =
      VolumeGeometry::make({18, 16, 14}, {1, 1, 1}, {0.6234, 0.5567, 0.5891});
  const Volume coverage = rasterizeCoverage(box, moved, grid);
  expectHalfOpenBox(coverage, {2, 2, 2}, {14, 12, 10});
  // Same through the label path, which also reports: no fold, every covered voxel once.
  Volume G(grid, ScalarType::UInt8);
  std::fill(G.data<std::uint8_t>(), G.data<std::uint8_t>() + G.numVoxels(), 3);
  rasterizeLabels(G, box, moved, G.geometry(), {}, &report);
  EXPECT_EQ(report.voxelWrites, 12 * 10 * 8);
  EXPECT_EQ(report.invertedTets, 0);
  EXPECT_EQ(report.flatTets, 0);
}

TEST(Rasterizer, FoldsAreCountedAndResolvedTheSameWayEveryRun) {
  TransferMesh box = alignedBox();
  Eigen::MatrixX3d folded = box.vertices;
  // Push one interior vertex through its neighbours: some tets turn inside out.
  for (Eigen::Index v = 0; v < folded.rows(); ++v)
    if (folded.row(v) == Eigen::RowVector3d(8, 6, 6)) folded(v, 0) += 5;
  Volume G(unitGrid({18, 16, 14}), ScalarType::UInt8);
  for (std::int64_t v = 0; v < G.numVoxels(); ++v)
    G.data<std::uint8_t>()[v] = std::uint8_t(v % 7 + 1);
  RasterReport r1, r2;
  RasterOptions one, two;
  one.threads = 1, two.threads = 2;
  const Volume a = rasterizeLabels(G, box, folded, G.geometry(), one, &r1);
  const Volume b = rasterizeLabels(G, box, folded, G.geometry(), two, &r2);
  EXPECT_GT(r1.invertedTets, 0);
  EXPECT_GT(r1.voxelWrites, 12 * 10 * 8);  // the fold covers some centres twice
  EXPECT_EQ(r1.invertedTets, r2.invertedTets);
  EXPECT_EQ(a.bytes(), b.bytes());
  const Volume c = rasterizeCoverage(box, folded, G.geometry());
  EXPECT_GT(*std::max_element(c.data<std::uint8_t>(), c.data<std::uint8_t>() + c.numVoxels()), 1);
}

TEST(Rasterizer, OutputGridKeepsAxesAndSpacingShiftsByWholeVoxelsAndNeverClips) {
  const VolumeGeometry in = VolumeGeometry::make(
      {20, 30, 40}, {1.5, 1.5, 3}, {-10, 4, 7},
      Eigen::AngleAxisd(0.3, Eigen::Vector3d(1, 1, 0).normalized()).toRotationMatrix());
  Eigen::MatrixX3d pts(3, 3);
  pts << -200, 5, 9, 300, 40, -60, 0, 0, 500;
  const VolumeGeometry out = deformedGrid(in, pts);
  const Eigen::Matrix3d Min = in.ijkToRas.block<3, 3>(0, 0), Mout = out.ijkToRas.block<3, 3>(0, 0);
  EXPECT_TRUE(Mout.isApprox(Min));
  const Eigen::Vector3d shift = in.rasToVoxel(out.origin());
  EXPECT_LT((shift - shift.array().round().matrix()).norm(), 1e-9);
  for (int p = 0; p < 3; ++p) {
    const Eigen::Vector3d v = out.rasToVoxel(pts.row(p).transpose());
    for (int c = 0; c < 3; ++c) {
      EXPECT_GE(v[c], 0);
      EXPECT_LE(v[c], out.dims[c] - 1);
    }
  }
  const VolumeGeometry coarse = deformedGrid(in, pts, 2.0);
  EXPECT_TRUE(coarse.spacing().isApprox(Eigen::Vector3d(2, 2, 2)));
  EXPECT_TRUE(coarse.directions().isApprox(in.directions()));
}

// A thick-slice input posed onto a finer grid (--spacing-mm): no output centre may lie on an input
// voxel's face, where nearest-neighbour sampling is a tie that rounding noise breaks either way.
// With the output's centres on the input's centres plus whole millimetres, 8 mm slices at 1 mm
// met a face every eighth slice, and a reference phantom's static foot bone changed by 1.5 %.
TEST(Rasterizer, AFinerOutputGridsCentresKeepOffTheInputVoxelsFaces) {
  for (const Eigen::Vector3d& spacing :
       {Eigen::Vector3d(2.137, 2.137, 8), Eigen::Vector3d(1.8, 1.8, 4.8),
        Eigen::Vector3d(2.4, 2.4, 6)}) {
    const VolumeGeometry in = VolumeGeometry::make(
        {60, 40, 30}, spacing, {-101.3, 17.9, -1234.5},
        Eigen::AngleAxisd(0.2, Eigen::Vector3d(0, 1, 1).normalized()).toRotationMatrix());
    Eigen::MatrixX3d pts(2, 3);
    pts.row(0) = in.voxelToRas(0, 0, 0).transpose();
    pts.row(1) = in.voxelToRas(59, 39, 29).transpose();
    for (const double mm : {1.0, 1.2, 0.5, 0.6}) {
      const VolumeGeometry out = deformedGrid(in, pts, mm);
      for (int c = 0; c < 3; ++c) {
        SCOPED_TRACE(testing::Message()
                     << spacing.transpose() << " at " << mm << " mm, axis " << c);
        double nearest = 1;  // the least distance of an output centre from an input face (voxels)
        for (std::int64_t k = 0; k < out.dims[c]; ++k) {
          Eigen::Vector3d ijk(0, 0, 0);
          ijk[c] = double(k);
          const double u = in.rasToVoxel(out.voxelToRas(ijk[0], ijk[1], ijk[2]))[c];
          nearest = std::min(nearest, std::fabs(u - std::floor(u) - 0.5));
        }
        // A ratio p/q of the spacings: the centres half a step of s/q clear of the faces (8/1,
        // 6/1.2: half an output voxel, each input voxel subdivided; 1.8/1.2 = 3/2: a quarter);
        // 2.137 mm has no small ratio to any of these: only off the faces.
        const double ratio = spacing[c] / mm;
        double least = 1e-6;
        for (int q = 1; q <= 4; ++q)
          if (std::fabs(q * ratio - std::round(q * ratio)) < 1e-9) {
            least = 0.5 / (q * ratio) - 1e-9;
            break;
          }
        EXPECT_GE(nearest, least);
      }
    }
  }
}

// An identity posed onto a grid a whole number of times finer: every output voxel takes the label
// of the input voxel it lies in, so each label has that many times its voxels (the resampling
// floor of a label that does not move is 0). Where a finer voxel's centre lies beyond the mesh's
// surface in a corner of a surface voxel, the shell decides: one voxel of the 4 mm phantom at
// 2 mm. With the output's centres on the input's faces (before: every other centre at a whole
// ratio), 22,455 voxels took a neighbour's label and every label's count moved.
TEST(Rasterizer, IdentityOntoAWholeTimesFinerGridSubdividesEveryVoxel) {
  const PhantomScene& s = phantomScene();
  std::map<std::int64_t, std::int64_t> rest;
  for (std::int64_t v = 0; v < s.organs.numVoxels(); ++v)
    ++rest[std::int64_t(s.organs.valueAsDouble(v))];
  const Volume out = rasterizeLabels(s.organs, s.mesh, s.mesh.vertices,
                                     deformedGrid(s.organs.geometry(), s.mesh.vertices, 2.0), {});
  std::map<std::int64_t, std::int64_t> posed;
  std::int64_t different = 0;
  const auto d = out.dims();
  for (std::int64_t k = 0; k < d[2]; ++k)
    for (std::int64_t j = 0; j < d[1]; ++j)
      for (std::int64_t i = 0; i < d[0]; ++i) {
        const double label = out.valueAsDouble(out.index(i, j, k));
        ++posed[std::int64_t(label)];
        const Eigen::Vector3d u =
            s.organs.geometry().rasToVoxel(out.geometry().voxelToRas(i, j, k));
        const Eigen::Vector3d r = (u.array() + 0.5).floor().matrix();
        const bool inside = (r.array() >= 0).all() && r[0] < s.organs.dims()[0] &&
                            r[1] < s.organs.dims()[1] && r[2] < s.organs.dims()[2];
        const double was = inside ? s.organs.valueAsDouble(s.organs.index(
                                        std::int64_t(r[0]), std::int64_t(r[1]), std::int64_t(r[2])))
                                  : 0.0;
        different += label != was;
      }
  EXPECT_LE(different, 4);
  for (const auto& [label, n] : rest) {
    if (label == 0) continue;  // the grid's margin adds background
    EXPECT_NEAR(double(posed[label]), double(8 * n), 4) << "label " << label;
  }
}

TEST(Rasterizer, IdentityReproducesThePhantomVoxelForVoxel) {
  const PhantomScene& s = phantomScene();
  RasterReport report;
  const Volume out =
      rasterizeLabels(s.organs, s.mesh, s.mesh.vertices, s.organs.geometry(), {}, &report);
  EXPECT_EQ(countDifferent(out, s.organs), 0);
  EXPECT_EQ(report.invertedTets, 0);
  EXPECT_EQ(out.labels().size(), s.organs.labels().size());
}

TEST(Rasterizer, QuarterTurnOfTheCageEqualsTheRotatedLabelMap) {
  const PhantomScene& s = phantomScene();
  // 90 degrees about z through a voxel centre near the body's middle.
  const Eigen::Vector3d pivot = s.organs.geometry().voxelToRas(40, 20, 100);
  const Eigen::Matrix3d R =
      Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  const Eigen::MatrixX3d cage =
      ((s.cage.vertices.rowwise() - pivot.transpose()) * R.transpose()).rowwise() +
      pivot.transpose();
  const Eigen::MatrixX3d deformed = s.deformation->deform(cage);
  const VolumeGeometry grid = deformedGrid(s.organs.geometry(), deformed);
  const Volume out = rasterizeLabels(s.organs, s.mesh, deformed, grid);
  const Volume expected = mapDirectly(s.organs, grid, [&](const Eigen::Vector3d& c) {
    return Eigen::Vector3d(R.transpose() * (c - pivot) + pivot);
  });
  EXPECT_EQ(countDifferent(out, expected), 0);
}

TEST(Rasterizer, WholeVoxelTranslationEqualsTheShiftedLabelMap) {
  const PhantomScene& s = phantomScene();
  const Eigen::Vector3d t =
      s.organs.geometry().ijkToRas.block<3, 3>(0, 0) * Eigen::Vector3d(3, -5, 11);
  const Eigen::MatrixX3d deformed =
      s.deformation->deform(s.cage.vertices.rowwise() + t.transpose());
  const VolumeGeometry grid = deformedGrid(s.organs.geometry(), deformed);
  const Volume out = rasterizeLabels(s.organs, s.mesh, deformed, grid);
  const Volume expected =
      mapDirectly(s.organs, grid, [&](const Eigen::Vector3d& c) { return Eigen::Vector3d(c - t); });
  EXPECT_EQ(countDifferent(out, expected), 0);
}

std::uint8_t labelValue(const Volume& v, const std::string& name) {
  for (const Label& l : v.labels().labels())
    if (l.name == name) return std::uint8_t(l.value);
  ADD_FAILURE() << "no label " << name;
  return 0;
}

// Dice of the voxels where G == organ and S == part in two pairs of maps on one grid.
double dice(const Volume& G1, const Volume& S1, const Volume& G2, const Volume& S2,
            std::uint8_t organ, std::uint8_t part) {
  std::int64_t a = 0, b = 0, both = 0;
  for (std::int64_t v = 0; v < G1.numVoxels(); ++v) {
    const bool x = G1.data<std::uint8_t>()[v] == organ && S1.data<std::uint8_t>()[v] == part;
    const bool y = G2.data<std::uint8_t>()[v] == organ && S2.data<std::uint8_t>()[v] == part;
    a += x, b += y, both += x && y;
  }
  return a + b == 0 ? 0.0 : 2.0 * double(both) / double(a + b);
}

// The seed's rigid-structure requirement: under a 90-degree elbow flexion the forearm bones are a
// rigid copy of themselves (Dice >= 0.95 with the bones turned analytically about the elbow), and
// so are the hand's. Green coordinates alone bend them (the wrist lags, see RigidHandles.h);
// the handle group's influence makes the tissue it encloses follow it.
TEST(Rasterizer, ElbowFlexionKeepsTheForearmBonesARigidCopy) {
  const PhantomScene& s = phantomScene();
  const std::vector<RigidHandle> handles = phantomElbowFlexionHandles(s.phantom, s.cage, 90);
  const HandleInfluence influence = computeHandleInfluence(s.mesh, s.cage, handles);
  const Eigen::MatrixX3d cage = moveHandles(s.cage.vertices, handles);
  const Eigen::MatrixX3d green = s.deformation->deform(cage);
  const Eigen::MatrixX3d withHandles = s.deformation->deform(cage, influence, handles);
  const auto identity = [](const Eigen::Vector3d& c) { return c; };
  const auto turnedBack = [&](const Eigen::Vector3d& c) {
    return Eigen::Vector3d(handles[0].motion.inverse() * c);
  };
  int greenInverted = 0;
  for (const auto* deformed : {&green, &withHandles}) {
    const VolumeGeometry grid = deformedGrid(s.organs.geometry(), *deformed);
    RasterReport report;
    const Volume G = rasterizeLabels(s.organs, s.mesh, *deformed, grid, {}, &report);
    const Volume S = rasterizeLabels(s.parts, s.mesh, *deformed, grid);
    const Volume turnedG = mapDirectly(s.organs, grid, turnedBack),
                 turnedS = mapDirectly(s.parts, grid, turnedBack);
    const Volume restG = mapDirectly(s.organs, grid, identity),
                 restS = mapDirectly(s.parts, grid, identity);
    const double forearmBones = dice(G, S, turnedG, turnedS, labelValue(s.organs, "radius_ulna"),
                                     kPartForearmLeft),
                 handBones = dice(G, S, turnedG, turnedS, labelValue(s.organs, "hand_bones"),
                                  kPartHandLeft),
                 humerus =
                     dice(G, S, restG, restS, labelValue(s.organs, "humerus"), kPartUpperArmLeft);
    std::cout << (deformed == &green ? "Green coordinates alone" : "with the handles' influence")
              << ": Dice radius/ulna " << forearmBones << ", hand bones " << handBones
              << ", humerus " << humerus << "; inverted tets " << report.invertedTets << "\n";
    if (deformed == &green) {
      greenInverted = report.invertedTets;
      continue;
    }
    EXPECT_GE(forearmBones, 0.95);
    EXPECT_GE(handBones, 0.95);
    EXPECT_GE(humerus, 0.95);
    // The handles do not fold the mesh wholesale (a few tets either way with each mesh).
    EXPECT_LE(report.invertedTets, greenInverted + greenInverted / 4 + 2);
  }
}

TEST(Rasterizer, ImagesAreInterpolatedTrilinearly) {
  // A linear ramp is reproduced exactly by trilinear interpolation under any affine map.
  const TransferMesh box = alignedBox();
  Volume I(unitGrid({18, 16, 14}), ScalarType::Float32);
  for (std::int64_t k = 0; k < 14; ++k)
    for (std::int64_t j = 0; j < 16; ++j)
      for (std::int64_t i = 0; i < 18; ++i)
        I.data<float>()[I.index(i, j, k)] = float(2 * i - j + 3 * k);
  const Eigen::RowVector3d shift(0.5, 0.25, 0);  // half a voxel: values between centres
  const Eigen::MatrixX3d moved = box.vertices.rowwise() + shift;
  const Volume out = rasterizeImage(I, box, moved, I.geometry(), -1000);
  int checked = 0;
  for (std::int64_t k = 0; k < 14; ++k)
    for (std::int64_t j = 0; j < 16; ++j)
      for (std::int64_t i = 0; i < 18; ++i) {
        const float v = out.data<float>()[out.index(i, j, k)];
        const bool inside = i >= 3 && i < 15 && j >= 3 && j < 13 && k >= 2 && k < 10;
        if (!inside) {
          EXPECT_TRUE(v == -1000 || std::fabs(v - (2 * (i - 0.5) - (j - 0.25) + 3 * k)) < 1e-4);
          continue;
        }
        EXPECT_NEAR(v, 2 * (i - 0.5) - (j - 0.25) + 3 * k, 1e-4);
        ++checked;
      }
  EXPECT_GT(checked, 500);
  // Integer images are rounded and clamped.
  Volume ct(unitGrid({18, 16, 14}), ScalarType::Int16);
  std::fill(ct.data<std::int16_t>(), ct.data<std::int16_t>() + ct.numVoxels(), std::int16_t(-1024));
  const Volume posed = rasterizeImage(ct, box, box.vertices, ct.geometry(), -40000);
  EXPECT_EQ(posed.data<std::int16_t>()[posed.index(17, 15, 13)], -32768);  // clamped background
  EXPECT_EQ(posed.data<std::int16_t>()[posed.index(5, 5, 5)], -1024);      // interpolated
}

TEST(Rasterizer, RefusesMismatchedOrNonFiniteDeformations) {
  const TransferMesh box = alignedBox();
  Volume G(unitGrid({18, 16, 14}), ScalarType::UInt8);
  EXPECT_THROW(rasterizeLabels(G, box, Eigen::MatrixX3d::Zero(3, 3), G.geometry()), Error);
  Eigen::MatrixX3d bad = box.vertices;
  bad(4, 1) = std::nan("");
  EXPECT_THROW(rasterizeLabels(G, box, bad, G.geometry()), Error);
  RasterOptions cancel;
  cancel.progress = [](double, const std::string&) { return false; };
  EXPECT_THROW(rasterizeLabels(G, box, box.vertices, G.geometry(), cancel), Cancelled);
}

// The shell: voxels up to shellMm outside the mesh's outer faces follow the boundary tets' maps
// (the skin Mesh_3 leaves just outside the TM); faces shared by two tets or cut by a label
// separation get none; shellMm = 0 writes only voxels inside tets.
TEST(Rasterizer, ShellCoversVoxelsJustOutsideTheOuterFacesOnly) {
  const TransferMesh box = alignedBox();  // [2, 14) x [2, 12) x [2, 10)
  const std::vector<std::uint8_t> outer = outerFaces(box);
  int outerCount = 0;
  for (std::uint8_t m : outer) outerCount += __builtin_popcount(m);
  EXPECT_EQ(outerCount, 2 * 2 * (6 * 5 + 6 * 4 + 5 * 4));  // two triangles per boundary square
  Volume G(unitGrid({18, 16, 14}), ScalarType::UInt8);
  std::fill(G.data<std::uint8_t>(), G.data<std::uint8_t>() + G.numVoxels(), 5);
  RasterOptions none, shell;
  none.shellMm = 0;
  shell.shellMm = 1.5;
  RasterReport r0, r1;
  const Volume inside = rasterizeLabels(G, box, box.vertices, G.geometry(), none, &r0);
  const Volume grown = rasterizeLabels(G, box, box.vertices, G.geometry(), shell, &r1);
  EXPECT_EQ(r0.shellVoxels, 0);
  EXPECT_EQ(r1.voxelWrites, r0.voxelWrites);
  // Inside tets: [2, 14) etc. With a 1.5 mm shell: one more layer below (x = 1) and the face
  // layer above (x = 14), along each axis; corners within 1.5 mm of the box too.
  std::int64_t faceLayers = 0;
  for (std::int64_t k = 0; k < 14; ++k)
    for (std::int64_t j = 0; j < 16; ++j)
      for (std::int64_t i = 0; i < 18; ++i) {
        const std::int64_t at = G.index(i, j, k);
        const bool in = i >= 2 && i < 14 && j >= 2 && j < 12 && k >= 2 && k < 10;
        EXPECT_EQ(inside.data<std::uint8_t>()[at], in ? 5 : 0);
        if (in) {
          EXPECT_EQ(grown.data<std::uint8_t>()[at], 5);
        }
        const bool layer = i >= 1 && i <= 14 && j >= 2 && j < 12 && k >= 2 && k < 10;
        if (layer && !in) {
          EXPECT_EQ(grown.data<std::uint8_t>()[at], 5) << i << " " << j << " " << k;
          ++faceLayers;
        }
        const double dx = std::max({2.0 - i, i - 14.0, 0.0}),
                     dy = std::max({2.0 - j, j - 12.0, 0.0}),
                     dz = std::max({2.0 - k, k - 10.0, 0.0});
        if (std::sqrt(dx * dx + dy * dy + dz * dz) > 1.5 * std::sqrt(3.0) + 1e-9) {
          EXPECT_EQ(grown.data<std::uint8_t>()[at], 0) << i << " " << j << " " << k;
        }
      }
  EXPECT_EQ(faceLayers, 2 * 10 * 8);
  EXPECT_GE(r1.shellVoxels, faceLayers);
  // Two boxes side by side that were separated (vertices duplicated at x = 14): the cut faces
  // are not outer, so neither side grows into the other.
  const TransferMesh cut = concatenate(alignedBox(), tetBox({14, 2, 2}, {16, 12, 10}, {1, 5, 4}));
  const std::vector<std::uint8_t> cutOuter = outerFaces(cut);
  int cutCount = 0;
  for (std::uint8_t m : cutOuter) cutCount += __builtin_popcount(m);
  EXPECT_EQ(cutCount, 2 * 2 * (7 * 5 + 7 * 4 + 5 * 4));
}

// outerFaces against the definition, written plainly (a map of every face's sorted vertices, a
// map of every boundary face's rest place): a face is outer when one tet has it and no other
// boundary face lies where it does. On the phantom's transfer mesh, on a box whose tets and
// vertex numbers are shuffled, and on two boxes separated by a cut.
TEST(Rasterizer, OuterFacesAreTheFacesOfOneTetAwayFromCuts) {
  auto reference = [](const TransferMesh& m) {
    std::map<std::array<int, 3>, int> uses;
    auto key = [&](Eigen::Index t, int f) {
      std::array<int, 3> k;
      for (int c = 0, n = 0; c < 4; ++c)
        if (c != f) k[std::size_t(n++)] = m.tets(t, c);
      std::sort(k.begin(), k.end());
      return k;
    };
    auto place = [&](const std::array<int, 3>& k) {
      std::vector<std::array<double, 3>> p;
      for (const int v : k) p.push_back({m.vertices(v, 0), m.vertices(v, 1), m.vertices(v, 2)});
      std::sort(p.begin(), p.end());
      return p;
    };
    for (Eigen::Index t = 0; t < m.tets.rows(); ++t)
      for (int f = 0; f < 4; ++f) ++uses[key(t, f)];
    std::map<std::vector<std::array<double, 3>>, int> places;
    for (const auto& [k, n] : uses)
      if (n == 1) ++places[place(k)];
    std::vector<std::uint8_t> out(std::size_t(m.tets.rows()), 0);
    for (Eigen::Index t = 0; t < m.tets.rows(); ++t)
      for (int f = 0; f < 4; ++f)
        if (uses[key(t, f)] == 1 && places[place(key(t, f))] == 1)
          out[std::size_t(t)] |= std::uint8_t(1u << f);
    return out;
  };
  const TransferMesh& phantomMesh = phantomScene().mesh;
  EXPECT_EQ(outerFaces(phantomMesh), reference(phantomMesh));
  TransferMesh shuffled = tetBox({0, 0, 0}, {5, 4, 3}, {5, 4, 3});
  std::mt19937 random(7);
  std::vector<int> renumber(std::size_t(shuffled.vertices.rows()));
  std::iota(renumber.begin(), renumber.end(), 0);
  std::shuffle(renumber.begin(), renumber.end(), random);
  Eigen::MatrixX3d vertices(shuffled.vertices.rows(), 3);
  for (Eigen::Index v = 0; v < vertices.rows(); ++v)
    vertices.row(renumber[std::size_t(v)]) = shuffled.vertices.row(v);
  shuffled.vertices = vertices;
  std::vector<Eigen::Index> order(std::size_t(shuffled.tets.rows()));
  std::iota(order.begin(), order.end(), 0);
  std::shuffle(order.begin(), order.end(), random);
  Eigen::MatrixX4i tets(shuffled.tets.rows(), 4);
  for (Eigen::Index t = 0; t < tets.rows(); ++t)
    for (int c = 0; c < 4; ++c)
      tets(t, c) = renumber[std::size_t(shuffled.tets(order[std::size_t(t)], c))];
  shuffled.tets = tets;
  EXPECT_EQ(outerFaces(shuffled), reference(shuffled));
  const TransferMesh cut = concatenate(alignedBox(), tetBox({14, 2, 2}, {16, 12, 10}, {1, 5, 4}));
  EXPECT_EQ(outerFaces(cut), reference(cut));
}

// A live slice is the rasterizer on a one-voxel-thick grid: on the full output's own voxel
// centres it gives exactly that slice of the full output.
TEST(Rasterizer, SliceEqualsThatPlaneOfTheFullOutput) {
  const PhantomScene& s = phantomScene();
  const Eigen::Vector3d t(12, -30, 40);
  const Eigen::MatrixX3d deformed =
      s.deformation->deform(s.cage.vertices.rowwise() + t.transpose());
  const VolumeGeometry full = deformedGrid(s.organs.geometry(), deformed);
  const Volume out = rasterizeLabels(s.organs, s.mesh, deformed, full);
  const std::int64_t k = full.dims[2] / 2;
  VolumeGeometry plane = full;
  plane.dims[2] = 1;
  plane.ijkToRas.block<3, 1>(0, 3) = full.voxelToRas(0, 0, double(k));
  const Volume slice = rasterizeLabels(s.organs, s.mesh, deformed, plane);
  const std::int64_t n = full.dims[0] * full.dims[1];
  EXPECT_TRUE(std::equal(slice.data<std::uint8_t>(), slice.data<std::uint8_t>() + n,
                         out.data<std::uint8_t>() + k * n));
  // The view grids: square pixels, RAS-aligned, on the requested plane.
  const Eigen::Vector3d lo(-100, -50, 0), hi(100, 50, 1000);
  const VolumeGeometry axial = slicePlaneGrid(SliceOrientation::Axial, 700, lo, hi, 512);
  EXPECT_EQ(axial.dims, (std::array<std::int64_t, 3>{512, 512, 1}));
  EXPECT_NEAR(axial.voxelToRas(0, 0, 0).z(), 700, 1e-9);
  EXPECT_NEAR(axial.spacing()[0], 200.0 / 512, 1e-12);
  const VolumeGeometry coronal = slicePlaneGrid(SliceOrientation::Coronal, 5, lo, hi, 512);
  EXPECT_NEAR(coronal.voxelToRas(3, 7, 0).y(), 5, 1e-9);
  EXPECT_NEAR(coronal.spacing()[1], 1000.0 / 512, 1e-12);
  const VolumeGeometry sagittal = slicePlaneGrid(SliceOrientation::Sagittal, -20, lo, hi, 256);
  EXPECT_NEAR(sagittal.voxelToRas(9, 2, 0).x(), -20, 1e-9);
  const Volume live = rasterizeLabels(s.organs, s.mesh, deformed, sagittal);
  EXPECT_GT(
      *std::max_element(live.data<std::uint8_t>(), live.data<std::uint8_t>() + live.numVoxels()),
      0);
}

// A slice keeps only the tets whose vertices' outcodes do not put them wholly on one side, and its
// bands of rows go to whichever thread is free: on any thread count, every plane of a bent body's
// full output (first, last, and through the trunk) comes out voxel for voxel, shell included.
TEST(Rasterizer, SlicesEqualTheFullOutputOnAnyNumberOfThreads) {
  const PhantomScene& s = phantomScene();
  Eigen::MatrixX3d posed = s.cage.vertices;
  for (Eigen::Index v = 0; v < posed.rows(); ++v)  // a smooth bend, not an affine map
    posed(v, 1) += 1e-3 * posed(v, 2) * posed(v, 2) + 0.1 * posed(v, 0);
  const Eigen::MatrixX3d deformed = s.deformation->deform(posed);
  const VolumeGeometry full = deformedGrid(s.organs.geometry(), deformed);
  const Volume out = rasterizeLabels(s.organs, s.mesh, deformed, full);
  const std::int64_t n = full.dims[0] * full.dims[1];
  int planes = 0;
  for (const std::int64_t k :
       {std::int64_t(0), full.dims[2] / 3, full.dims[2] / 2, full.dims[2] - 1}) {
    VolumeGeometry plane = full;
    plane.dims[2] = 1;
    plane.ijkToRas.block<3, 1>(0, 3) = full.voxelToRas(0, 0, double(k));
    for (const int threads : {1, 2, 3}) {
      RasterOptions o;
      o.threads = threads;
      const Volume slice = rasterizeLabels(s.organs, s.mesh, deformed, plane, o);
      EXPECT_TRUE(std::equal(slice.data<std::uint8_t>(), slice.data<std::uint8_t>() + n,
                             out.data<std::uint8_t>() + k * n))
          << "plane " << k << " on " << threads << " threads";
    }
    planes +=
        std::count_if(out.data<std::uint8_t>() + k * n, out.data<std::uint8_t>() + (k + 1) * n,
                      [](std::uint8_t v) { return v != 0; }) > 0;
  }
  EXPECT_GE(planes, 2);  // the test looked at the body, not only at empty planes
}

// The same with the output's slices stacked front to back (k along A, as a coronal view's
// planes are): a slice keeps only the tets whose cross-section with its plane holds a voxel
// centre, over the rows that section spans: every third coronal plane of the full output of a
// flexed elbow and of a shifted rest mesh comes out voxel for voxel. (Planes through vertices,
// edges and faces: Rasterizer.EveryCentreHasOneOwnerOnScaledAndShiftedMeshes.)
TEST(Rasterizer, CoronalSlicesEqualTheFullOutputOnOneAndTwoThreads) {
  const PhantomScene& s = phantomScene();
  const Eigen::MatrixX3d raised = s.deformation->deform(phantomElbowFlexion(s.phantom, s.cage, 60));
  const Eigen::MatrixX3d shifted = s.mesh.vertices.rowwise() + Eigen::RowVector3d(4, 8, -6);
  for (const Eigen::MatrixX3d* deformed : {&raised, &shifted}) {
    const VolumeGeometry axial = deformedGrid(s.organs.geometry(), *deformed);
    // The same voxels with j and k swapped: k runs along A.
    VolumeGeometry full = axial;
    full.dims = {axial.dims[0], axial.dims[2], axial.dims[1]};
    full.ijkToRas.col(1) = axial.ijkToRas.col(2);
    full.ijkToRas.col(2) = axial.ijkToRas.col(1);
    const Volume out = rasterizeLabels(s.organs, s.mesh, *deformed, full);
    const std::int64_t n = full.dims[0] * full.dims[1];
    std::int64_t body = 0;
    for (std::int64_t k = 0; k < full.dims[2]; k += 3) {
      VolumeGeometry plane = full;
      plane.dims[2] = 1;
      plane.ijkToRas.block<3, 1>(0, 3) = full.voxelToRas(0, 0, double(k));
      for (const int threads : {1, 2}) {
        RasterOptions o;
        o.threads = threads;
        const Volume slice = rasterizeLabels(s.organs, s.mesh, *deformed, plane, o);
        ASSERT_TRUE(std::equal(slice.data<std::uint8_t>(), slice.data<std::uint8_t>() + n,
                               out.data<std::uint8_t>() + k * n))
            << "plane " << k << " on " << threads << " threads";
      }
      body +=
          std::count_if(out.data<std::uint8_t>() + k * n, out.data<std::uint8_t>() + (k + 1) * n,
                        [](std::uint8_t v) { return v != 0; });
    }
    EXPECT_GT(body, 1000);  // the planes went through the body
  }
}

// Out of core: the input read in place through a small slice cache, the output written in slabs;
// the file equals the in-core result voxel for voxel, for gzip and plain NIfTI inputs.
TEST(Rasterizer, OutOfCoreEqualsInCoreVoxelForVoxel) {
  const PhantomScene& s = phantomScene();
  const Eigen::MatrixX3d deformed =
      s.deformation->deform(phantomElbowFlexion(s.phantom, s.cage, 60));
  const VolumeGeometry grid = deformedGrid(s.organs.geometry(), deformed);
  RasterReport inCoreReport;
  const Volume inCore = rasterizeLabels(s.organs, s.mesh, deformed, grid, {}, &inCoreReport);
  ScratchDir dir;
  for (const std::string& name : {std::string("G.nii.gz"), std::string("G.nii")}) {
    const std::string in = dir.file(name), out = dir.file("posed_" + name);
    writeVolume(s.organs, in);
    const std::size_t slice = std::size_t(s.organs.dims()[0] * s.organs.dims()[1]);
    SliceCache cache(in, 6 * slice);  // a few slices of a 331-slice volume
    RasterReport report;
    rasterizeLabelsToFile(cache, s.mesh, deformed, grid, out,
                          std::size_t(grid.dims[0] * grid.dims[1]) * 7, {}, &report);
    const Volume back = readVolume(out);
    ASSERT_EQ(back.dims(), inCore.dims());
    EXPECT_TRUE(back.geometry().ijkToRas.isApprox(grid.ijkToRas, 1e-6));  // NIfTI stores floats
    EXPECT_EQ(countDifferent(back, inCore), 0) << name;
    EXPECT_EQ(report.voxelWrites, inCoreReport.voxelWrites);
    EXPECT_EQ(report.shellVoxels, inCoreReport.shellVoxels);
    EXPECT_GT(cache.blockReads(), 3);  // the cache really cycled
    EXPECT_EQ(back.labels().size(), s.organs.labels().size());
  }
  EXPECT_THROW(SliceCache(dir.file("G.nii"), 10), Error);  // cannot hold two slices
}

// In-core slabs (LabelSlabs, what a frame too large for memory is made of): every slab size and
// thread count gives the whole grid's voxels and counts, with whole pieces, their rims and ghosts
// and soft tissue kept from copying a piece (a bone end in soft tets, pieces' map given), and on
// the 4 mm phantom's elbow flexion, a map of two layers included.
TEST(Rasterizer, InCoreSlabsEqualTheWholeGridWithPiecesAndRims) {
  auto check = [](const Volume& G, const TransferMesh& mesh, const Eigen::MatrixX3d& deformed,
                  const VolumeGeometry& grid, RasterOptions options, const std::string& what) {
    for (const int threads : {1, 2}) {
      options.threads = threads;
      RasterReport whole;
      const Volume expected = rasterizeLabels(G, mesh, deformed, grid, options, &whole);
      const LabelSlabs slabs(G, mesh, deformed, grid, options);
      const std::int64_t plane = grid.dims[0] * grid.dims[1], nz = grid.dims[2];
      ASSERT_EQ(slabs.sliceBytes(), plane * G.layers() * std::int64_t(scalarSize(G.scalarType())));
      for (const std::int64_t size : {1, 3, 7}) {
        Volume assembled(grid, G.scalarType(), G.layers());
        RasterReport sum;
        std::vector<std::uint8_t> slab(std::size_t(slabs.sliceBytes() * size));
        const std::int64_t valueBytes = std::int64_t(scalarSize(G.scalarType()));
        for (std::int64_t k0 = 0; k0 < nz; k0 += size) {
          const std::int64_t k1 = std::min(nz, k0 + size);
          slabs.rasterize(k0, k1, slab.data(), sum);
          for (int l = 0; l < G.layers(); ++l)
            std::memcpy(
                static_cast<std::uint8_t*>(assembled.layerData(l)) + k0 * plane * valueBytes,
                slab.data() + l * (k1 - k0) * plane * valueBytes,
                std::size_t((k1 - k0) * plane * valueBytes));
        }
        const std::string at = what + ", slabs of " + std::to_string(size) + ", " +
                               std::to_string(threads) + " thread(s)";
        for (int l = 0; l < G.layers(); ++l)
          EXPECT_EQ(std::memcmp(assembled.layerData(l), expected.layerData(l),
                                std::size_t(grid.numVoxels() * valueBytes)),
                    0)
              << at << ", layer " << l;
        EXPECT_EQ(sum.voxelWrites, whole.voxelWrites) << at;
        EXPECT_EQ(sum.shellVoxels, whole.shellVoxels) << at;
        EXPECT_GT(sum.voxelWrites, 0) << at;
      }
    }
    RasterReport unused;
    EXPECT_THROW(LabelSlabs(G, mesh, deformed, grid, options).rasterize(3, 2, nullptr, unused),
                 Error);  // an empty slab
  };

  // A bone whose end lies in soft tets, sheared beyond the joint (ABoneEndInSoftTetsMovesWith
  // TheBone): pieces, rims, ghosts and the soft tissue around them.
  {
    const BoneEnd b = boneEndInSoftTets();
    Volume G = b.G;  // two labels in the bone: its end beyond x = 6 another
    for (std::int64_t k = 2; k < 11; ++k)
      for (std::int64_t j = 2; j < 11; ++j)
        for (std::int64_t i = 2; i < 6; ++i) G.data<std::uint8_t>()[G.index(i, j, k)] = 7;
    const TransferMesh& mesh = b.mesh;
    const Eigen::MatrixX3d& deformed = b.deformed;
    const VolumeGeometry& grid = b.grid;
    const Volume& S = b.S;
    RasterOptions options;
    options.pieceLabels = &G;
    options.restParts = &S;
    check(G, mesh, deformed, grid, options, "a bone end in soft tets");
  }
  // The phantom's elbow flexed 60 degrees, on the grid `repose pose` makes for it; G and S as
  // the two layers of one map.
  {
    const PhantomScene& s = phantomScene();
    const Eigen::MatrixX3d deformed =
        s.deformation->deform(phantomElbowFlexion(s.phantom, s.cage, 60));
    const VolumeGeometry grid = deformedGrid(s.organs.geometry(), deformed);
    check(s.organs, s.mesh, deformed, grid, {}, "the phantom's elbow");
    Volume both(s.organs.geometry(), ScalarType::UInt8, 2);
    std::memcpy(both.layerData(0), s.organs.layerData(0), std::size_t(s.organs.numVoxels()));
    std::memcpy(both.layerData(1), s.parts.layerData(0), std::size_t(s.parts.numVoxels()));
    check(both, s.mesh, deformed, grid, {}, "two layers");
  }
}

// Two boxes of tets from different rest places (label 1 and label 2 of G) deformed onto the same
// place: the later box wins, unless the earlier one is a whole piece (a bone), which always does.
TEST(Rasterizer, AWholePieceKeepsItsVoxelsWhereSoftTissueFoldsOverIt) {
  const TransferMesh bone = tetBox({2, 2, 2}, {8, 8, 8}, {3, 3, 3});
  const TransferMesh soft = tetBox({12, 2, 2}, {18, 8, 8}, {3, 3, 3});
  TransferMesh mesh = concatenate(bone, soft);
  Eigen::MatrixX3d deformed = mesh.vertices;
  deformed.bottomRows(soft.vertices.rows()).col(0).array() -= 10;  // soft lands on the bone
  Volume G(unitGrid({22, 12, 12}), ScalarType::UInt8);
  for (std::int64_t k = 0; k < 12; ++k)
    for (std::int64_t j = 0; j < 12; ++j)
      for (std::int64_t i = 0; i < 22; ++i)
        G.data<std::uint8_t>()[G.index(i, j, k)] = i < 10 ? 1 : 2;
  auto labelAt = [&](const Volume& v) { return int(v.data<std::uint8_t>()[v.index(5, 5, 5)]); };
  EXPECT_EQ(labelAt(rasterizeLabels(G, mesh, deformed, G.geometry())), 2);  // later tet wins
  mesh.rigid.assign(std::size_t(mesh.tets.rows()), 0);
  std::fill_n(mesh.rigid.begin(), bone.tets.rows(), 11);
  const Volume withPieces = rasterizeLabels(G, mesh, deformed, G.geometry());
  int notBone = 0;
  for (std::int64_t k = 2; k < 8; ++k)
    for (std::int64_t j = 2; j < 8; ++j)
      for (std::int64_t i = 2; i < 8; ++i)
        notBone += withPieces.data<std::uint8_t>()[withPieces.index(i, j, k)] != 1;
  EXPECT_EQ(notBone, 0);
}

// A bone whose end lies in soft tets (a joint demoted them: demotePiecesAcrossJoints) still
// moves rigidly there. The bone fills a box meshed as tets; those beyond x = 14 are soft, and
// their far vertices follow a shear (the other side of a bent joint) instead of the bone's turn.
// Through its piece tets, rims and the ghosts of its soft tets (raster/PieceGhosts.h) every bone
// voxel lands where the bone's own motion puts it; without the pieces' label map the soft end
// bends with the joint.
// The Dice of bone label `bone` posed through the mesh against the bone moved by `motion` alone,
// with the pieces' map (rims, ghosts: G and S at rest) and without it.
static std::pair<double, double> boneDice(const Volume& G, const Volume& S,
                                          const TransferMesh& mesh,
                                          const Eigen::MatrixX3d& deformed,
                                          const VolumeGeometry& grid,
                                          const Eigen::Isometry3d& motion, int bone) {
  const Volume expected =
      mapDirectly(G, grid, [&](const Eigen::Vector3d& ras) { return motion.inverse() * ras; });
  auto dice = [&](const Volume& posed) {
    std::int64_t a = 0, b = 0, both = 0;
    for (std::int64_t v = 0; v < grid.numVoxels(); ++v) {
      const bool x = posed.data<std::uint8_t>()[v] == bone,
                 y = expected.data<std::uint8_t>()[v] == bone;
      a += x, b += y, both += x && y;
    }
    return double(2 * both) / double(a + b);
  };
  RasterOptions options;
  options.pieceLabels = &G;
  options.restParts = &S;
  return {dice(rasterizeLabels(G, mesh, deformed, grid, options)),
          dice(rasterizeLabels(G, mesh, deformed, grid))};
}

TEST(Rasterizer, ABoneEndInSoftTetsMovesWithTheBone) {
  const BoneEnd b = boneEndInSoftTets();
  ASSERT_GT(b.softTets, 0);
  const auto [withPieces, without] = boneDice(b.G, b.S, b.mesh, b.deformed, b.grid, b.motion, 5);
  EXPECT_LT(without, 0.95);  // the sheared end is a third of the bone
  EXPECT_GT(withPieces, 0.995) << "without the pieces' map: " << without;
}

// A bone whose end lies in another body part's soft tets (on thick slices Mesh_3 draws the parts'
// borders a slice or more off S's: on the ICRP adult male's grid half of the pelvis lay in the
// torso's tets) moves with its own piece there, not with that part's soft tissue: sitting had
// tilted the pelvis 25 degrees against the torso and moved 327 of its voxels off it.
TEST(Rasterizer, ABoneEndInAnotherPartsTetsMovesWithTheBone) {
  BoneEnd b = boneEndInSoftTets();
  // The bone's end beyond x = 14 is S's part 1 like the rest of it, but its tets are part 2's.
  for (Eigen::Index t = 0; t < b.mesh.tets.rows(); ++t)
    if (!b.mesh.rigid[std::size_t(t)]) b.mesh.labels[t] = 2;
  const auto [withPieces, without] = boneDice(b.G, b.S, b.mesh, b.deformed, b.grid, b.motion, 5);
  EXPECT_LT(without, 0.95);
  EXPECT_GT(withPieces, 0.995) << "without the pieces' map: " << without;
  // A bone of part 2 by S is not the part-1 piece's: nothing hosts it, and it stays with the soft
  // tissue that holds it.
  Volume S2 = b.S;
  for (std::int64_t v = 0; v < S2.numVoxels(); ++v)
    if (S2.data<std::uint8_t>()[v]) S2.data<std::uint8_t>()[v] = 2;
  EXPECT_LT(boneDice(b.G, S2, b.mesh, b.deformed, b.grid, b.motion, 5).first, 0.95);
}

// A bone Mesh_3 gave no tet of its own (the one-voxel ribs of the ICRP grid's phantom with
// one-voxel limb vessels and the sacrum up to its disc) lies wholly in soft tets. It moves with its
// body part's other pieces all the same, where the soft tissue around it is sheared: raising both
// arms had bent the ribs with the chest wall.
TEST(Rasterizer, ABoneWithNoTetsOfItsOwnMovesWithItsPartsPieces) {
  const BoneEnd b = boneEndInSoftTets();
  Volume G = b.G;  // the bone's end beyond x = 15, in the soft tets only, is another bone: 6
  for (std::int64_t k = 2; k < 11; ++k)
    for (std::int64_t j = 2; j < 11; ++j)
      for (std::int64_t i = 15; i < 20; ++i) G.data<std::uint8_t>()[G.index(i, j, k)] = 6;
  const std::map<int, int> bonePieces = {{5, 5}, {6, 6}};
  const Volume expected =
      mapDirectly(G, b.grid, [&](const Eigen::Vector3d& ras) { return b.motion.inverse() * ras; });
  auto dice = [&](const std::map<int, int>* pieces) {
    RasterOptions options;
    options.pieceLabels = &G;
    options.restParts = &b.S;
    options.bonePieces = pieces;
    const Volume posed = rasterizeLabels(G, b.mesh, b.deformed, b.grid, options);
    std::int64_t x = 0, y = 0, both = 0;
    for (std::int64_t v = 0; v < b.grid.numVoxels(); ++v) {
      const bool p = posed.data<std::uint8_t>()[v] == 6, e = expected.data<std::uint8_t>()[v] == 6;
      x += p, y += e, both += p && e;
    }
    return double(2 * both) / double(x + y);
  };
  const double without = dice(nullptr), with = dice(&bonePieces);
  EXPECT_LT(without, 0.9);  // sheared with the soft tissue
  EXPECT_GT(with, 0.99) << "not a piece: " << without;
}

// A bone with only a few tets of its own (a rib one voxel thick on 8 mm slices: Mesh_3 gave the
// ICRP grid's ribs 4 tets) lies mostly in soft tets, many rings away from them. It moves with its
// piece all the same, where the soft tissue around it is sheared: under both arms raised 160
// degrees on that grid the ribs' Dice was 0.65.
TEST(Rasterizer, ABoneFarFromItsOwnTetsMovesWithTheBone) {
  TransferMesh mesh = tetBox({2, 2, 2}, {62, 11, 11}, {20, 3, 3});
  mesh.rigid.assign(std::size_t(mesh.tets.rows()), 0);
  for (Eigen::Index t = 0; t < mesh.tets.rows(); ++t) {
    double x = 0;
    for (int c = 0; c < 4; ++c) x += mesh.vertices(mesh.tets(t, c), 0) / 4;
    if (x < 5) mesh.rigid[std::size_t(t)] = 5;  // one column of tets at the bone's end
  }
  const Eigen::Isometry3d motion = Eigen::Translation3d(10, 30, 6) *
                                   Eigen::AngleAxisd(0.2, Eigen::Vector3d::UnitZ()) *
                                   Eigen::Translation3d(-2, -6, -6);
  Eigen::MatrixX3d deformed = mesh.vertices;
  for (Eigen::Index v = 0; v < deformed.rows(); ++v) {
    const Eigen::Vector3d p = mesh.vertices.row(v).transpose();
    Eigen::Vector3d q = motion * p;
    if (p.x() > 5) q.y() -= 0.15 * (p.x() - 5);  // the soft tissue around it sheared
    deformed.row(v) = q.transpose();
  }
  const VolumeGeometry grid = unitGrid({80, 60, 14});
  Volume G(grid, ScalarType::UInt8), S(grid, ScalarType::UInt8);
  for (std::int64_t k = 2; k < 11; ++k)
    for (std::int64_t j = 2; j < 11; ++j)
      for (std::int64_t i = 2; i < 62; ++i) {
        S.data<std::uint8_t>()[S.index(i, j, k)] = 1;
        if (j >= 5 && j < 8 && k >= 5 && k < 8) G.data<std::uint8_t>()[G.index(i, j, k)] = 5;
      }
  const auto [withPieces, without] = boneDice(G, S, mesh, deformed, grid, motion, 5);
  EXPECT_LT(without, 0.5);  // sheared by up to 9 voxels, a 3-voxel bone
  EXPECT_GT(withPieces, 0.99) << "without the pieces' map: " << without;
}

// A bone of one body part that lies inside another part's piece tets (on 8 mm slices a scapula's
// tets lie on the ribs and take a slice of them) stays with its own part: the piece tets that
// hold it write the tissue around it instead, and its part's pieces place it (a ghost). Copied
// by the moving piece, it had moved with the shoulder girdle: the ribs +1.6 % under both arms
// raised on the ICRP grid with the girdles touching (issue 64).
TEST(Rasterizer, AnotherPartsBoneInsideAPiecesTetsStaysWithItsOwnPart) {
  TransferMesh mesh = tetBox({2, 2, 2}, {62, 11, 11}, {20, 3, 3});
  mesh.rigid.assign(std::size_t(mesh.tets.rows()), 0);
  for (Eigen::Index t = 0; t < mesh.tets.rows(); ++t) {
    double x = 0;
    for (int c = 0; c < 4; ++c) x += mesh.vertices(mesh.tets(t, c), 0) / 4;
    mesh.labels[t] = x < 32 ? 1 : 2;
    if (x < 29) mesh.rigid[std::size_t(t)] = 5;  // part 1's bone, moving
    if (x > 44) mesh.rigid[std::size_t(t)] = 7;  // part 2's bone, still
  }
  // Part 1 lifted 20 voxels; part 2 still; the soft tets between stretch.
  Eigen::MatrixX3d deformed = mesh.vertices;
  for (Eigen::Index v = 0; v < deformed.rows(); ++v) {
    const double x = mesh.vertices(v, 0);
    deformed(v, 1) += 20 * std::clamp((44 - x) / 12, 0.0, 1.0);
  }
  const VolumeGeometry grid = unitGrid({66, 40, 14});
  Volume G(grid, ScalarType::UInt8), S(grid, ScalarType::UInt8);
  std::int64_t rest6 = 0;
  for (std::int64_t k = 2; k < 11; ++k)
    for (std::int64_t j = 2; j < 11; ++j)
      for (std::int64_t i = 2; i < 62; ++i) {
        const bool six = i >= 20 && i < 22;  // a plate of part 2's bone 6, two voxels thick
        std::uint8_t g = i < 29 ? 5 : i > 45 ? 7 : 1;
        if (i >= 18 && i < 24) g = 1;  // soft tissue around the plate
        if (six) g = 6, ++rest6;
        G.data<std::uint8_t>()[G.index(i, j, k)] = g;
        S.data<std::uint8_t>()[S.index(i, j, k)] = six || i >= 32 ? 2 : 1;
      }
  const std::map<int, int> bonePieces = {{5, 5}, {6, 6}, {7, 7}};
  RasterOptions options;
  options.pieceLabels = &G;
  options.restParts = &S;
  options.bonePieces = &bonePieces;
  const Volume posed = rasterizeLabels(G, mesh, deformed, grid, options);
  std::int64_t inPlace = 0, moved = 0, five = 0, rest5 = 0;
  for (std::int64_t v = 0; v < grid.numVoxels(); ++v) {
    rest5 += G.data<std::uint8_t>()[v] == 5;
    five += posed.data<std::uint8_t>()[v] == 5;
    if (posed.data<std::uint8_t>()[v] != 6) continue;
    (G.data<std::uint8_t>()[v] == 6 ? inPlace : moved) += 1;
  }
  EXPECT_EQ(inPlace, rest6);  // where part 2 keeps it
  EXPECT_EQ(moved, 0);        // none lifted with part 1's bone
  EXPECT_EQ(five, rest5);     // the piece that held it keeps its own count
}

// Voxels no tet covers point one voxel centre past the input grid's nearest face (or nowhere when
// they lie a voxel beyond it already): nearest-neighbour resampling gives them background, and
// the field has no jump of metres beside the body (3D Slicer interpolates a grid transform with a
// cubic kernel: vtkITKTransformConverter.h).
TEST(Rasterizer, UncoveredVoxelsPointJustPastTheInputGrid) {
  const TransferMesh box = tetBox({6, 5, 4}, {14, 12, 9}, {2, 2, 2});
  const VolumeGeometry input = VolumeGeometry::make({20, 18, 12}, {1, 1.5, 2}, {0, 0, 0});
  const VolumeGeometry output = VolumeGeometry::make({30, 24, 20}, {1, 1.5, 2}, {-5, -6, -8});
  RasterOptions options;
  options.shellMm = 0;
  const std::vector<float> field = rasterizeDisplacement(box, box.vertices, input, output, options);
  const Volume coverage = rasterizeCoverage(box, box.vertices, output);
  const Eigen::Vector3d spacing(1, 1.5, 2),
      extent = spacing.cwiseProduct(Eigen::Vector3d(20, 18, 12));
  int uncovered = 0, stayed = 0;
  for (std::int64_t k = 0; k < 20; ++k)
    for (std::int64_t j = 0; j < 24; ++j)
      for (std::int64_t i = 0; i < 30; ++i) {
        const std::int64_t v = coverage.index(i, j, k);
        if (coverage.data<std::uint8_t>()[v]) continue;
        ++uncovered;
        const Eigen::Vector3d y = output.voxelToRas(double(i), double(j), double(k));
        const Eigen::Vector3d d(field[3 * v], field[3 * v + 1], field[3 * v + 2]);
        const Eigen::Vector3d u = input.rasToVoxel(y), t = input.rasToVoxel(y + d);
        const bool beyond =
            (u.array() <= -1).any() || (u.array() >= Eigen::Array3d(20, 18, 12)).any();
        if (beyond) {
          EXPECT_EQ(d.norm(), 0) << i << " " << j << " " << k;
          ++stayed;
          continue;
        }
        // One axis moved to the first voxel centre past the grid, the others kept.
        int moved = 0;
        for (int c = 0; c < 3; ++c) {
          if (std::fabs(t[c] - u[c]) < 1e-4) continue;
          ++moved;
          EXPECT_TRUE(std::fabs(t[c] + 1) < 1e-4 || std::fabs(t[c] - input.dims[c]) < 1e-4);
        }
        EXPECT_EQ(moved, 1) << i << " " << j << " " << k;
        EXPECT_LE(d.norm(), extent.minCoeff() / 2 + spacing.maxCoeff() + 1e-6);
      }
  EXPECT_GT(uncovered, 1000);
  EXPECT_GT(stayed, 100);
  EXPECT_LT(stayed, uncovered);
}
