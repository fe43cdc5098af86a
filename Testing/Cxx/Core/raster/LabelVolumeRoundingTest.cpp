// Volume-preserving rounding of posed labels (RasterOptions::preserveLabelVolumes): the choice
// of voxels on its own, then the rasterizer's targets (the deformation's volume per label) and
// counts on a thin structure turned across thick slices, a uniform growth, and the identity.
#include "TestTetMeshes.h"

#include "raster/LabelVolumeRounding.h"
#include "repose/raster/Rasterizer.h"
#include "repose/util/Error.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <map>

using namespace repose;
using namespace repose::test;
using raster::RoundingCandidate;

namespace {

std::map<int, std::int64_t> counts(const Volume& v) {
  std::map<int, std::int64_t> c;
  const std::uint16_t* p = v.data<std::uint16_t>();
  for (std::int64_t i = 0; i < v.numVoxels(); ++i) ++c[p[i]];
  return c;
}

// 1 mm x 1 mm x 3 mm slices (a thick-slice scan): soft tissue 1 fills a box, a vessel 2 two
// voxels across runs along z in it, a sheet 3 two voxels thick lies across y, and a block 4;
// 0 around. 2, 3 and 4 are inside 1: 1 alone meets the background, whose outline the rounding
// leaves as sampled (on 3 mm slices a grown box's outline gains whole slices or none, which
// only label 1 absorbs). The mesh covers the box and a margin.
struct ThickSliceBlock {
  Volume labels;
  TransferMesh mesh;
  std::vector<std::uint8_t> outer;
  ThickSliceBlock()
      : labels(VolumeGeometry::make({40, 40, 16}, {1, 1, 3}, {0, 0, 0}), ScalarType::UInt16) {
    labels.setLabelMap(true);
    std::uint16_t* p = labels.data<std::uint16_t>();
    for (std::int64_t k = 2; k < 14; ++k)
      for (std::int64_t j = 6; j < 34; ++j)
        for (std::int64_t i = 6; i < 34; ++i) {
          std::uint16_t l = 1;
          const bool inner = i >= 8 && i < 32 && k >= 3 && k < 13;
          if (inner && i >= 19 && i < 21 && j >= 14 && j < 16) l = 2;
          if (inner && j >= 24 && j < 26) l = 3;
          if (i >= 9 && i < 13 && j >= 9 && j < 13 && k >= 4 && k < 8) l = 4;
          p[labels.index(i, j, k)] = l;
        }
    mesh = tetBox({3.5, 3.5, 1.5}, {36.5, 36.5, 43.5}, {6, 6, 6});
    outer = outerFaces(mesh);
  }
  RasterOptions options(bool preserve) const {
    RasterOptions o;
    o.shellMm = 0;
    o.outerFaces = &outer;
    o.preserveLabelVolumes = preserve;
    return o;
  }
  Eigen::MatrixX3d turned(double degrees) const {
    const Eigen::Vector3d c(20, 20, 22.5);
    const Eigen::Matrix3d R =
        Eigen::AngleAxisd(degrees * M_PI / 180, Eigen::Vector3d(1, 0.3, 0).normalized())
            .toRotationMatrix();
    return ((mesh.vertices.rowwise() - c.transpose()) * R.transpose()).rowwise() + c.transpose();
  }
};

}  // namespace

TEST(LabelVolumeRounding, TakesTheBestScoresFirstAndStopsAtTheTargets) {
  // Label 1 (1000 voxels wanted) has 10 too many, label 2 (100 wanted) 10 too few.
  const std::vector<double> target{0, 1000, 100, 0};
  std::vector<double> count{0, 1010, 90, 0};
  std::vector<RoundingCandidate> c;
  for (int v = 0; v < 30; ++v) c.push_back({v, 1, 2, float(v % 15) / 15 - 0.5f});
  c.push_back({100, 2, 1, 0.9f});   // the wrong way: label 2 has too few
  c.push_back({101, 1, 3, 0.95f});  // label 3 is not wanted at all
  const std::vector<std::size_t> taken = raster::chooseVolumeRounding(c, target, count);
  ASSERT_EQ(taken.size(), 10u);
  EXPECT_EQ(count[1], 1000);
  EXPECT_EQ(count[2], 100);
  // The ten best scores (14/15 down to 10/15, two voxels each), ties by voxel index.
  for (std::size_t n = 0; n < taken.size(); ++n) {
    const RoundingCandidate& r = c[taken[n]];
    EXPECT_EQ(r.from, 1);
    EXPECT_EQ(r.to, 2);
    EXPECT_GE(r.score, float(10) / 15 - 0.5f - 1e-6f);
    if (n > 0) {
      const RoundingCandidate& q = c[taken[n - 1]];
      EXPECT_TRUE(q.score > r.score || (q.score == r.score && q.voxel < r.voxel));
    }
  }
}

TEST(LabelVolumeRounding, RelativeMisfitLetsALargeLabelAbsorbASmallOnesSurplus) {
  // The vessel (200 wanted) has 8 too many; the muscle around it is itself 50 over, but 50 of
  // 100,000 is a smaller share than one vessel voxel of 200, so the vessel gives to it.
  const std::vector<double> target{0, 100000, 200};
  std::vector<double> count{0, 100050, 208};
  std::vector<RoundingCandidate> c;
  for (int v = 0; v < 20; ++v) c.push_back({v, 2, 1, 0.1f});
  const std::vector<std::size_t> taken = raster::chooseVolumeRounding(c, target, count);
  EXPECT_EQ(taken.size(), 8u);
  EXPECT_EQ(count[2], 200);
}

TEST(LabelVolumeRounding, TurnedAcrossThickSlicesEverySoftLabelKeepsItsVolume) {
  const ThickSliceBlock b;
  const std::map<int, std::int64_t> rest = counts(b.labels);
  for (const double degrees : {23.0, 41.0, 67.0, 90.0}) {
    SCOPED_TRACE(degrees);
    const Eigen::MatrixX3d deformed = b.turned(degrees);
    const VolumeGeometry grid = deformedGrid(b.labels.geometry(), deformed);
    RasterReport nearestReport, preservedReport;
    const Volume nearest =
        rasterizeLabels(b.labels, b.mesh, deformed, grid, b.options(false), &nearestReport);
    const Volume preserved =
        rasterizeLabels(b.labels, b.mesh, deformed, grid, b.options(true), &preservedReport);
    const std::map<int, std::int64_t> n = counts(nearest), p = counts(preserved);
    // A rigid motion: the deformation gives each soft label its rest volume, and the labels
    // inside get it to a voxel or 0.2 %.
    for (const int l : {1, 2, 3, 4})
      EXPECT_NEAR(preservedReport.labelTargets.at(l), double(rest.at(l)), 1e-6 * rest.at(l));
    for (const int l : {2, 3, 4})
      EXPECT_LE(std::abs(p.at(l) - rest.at(l)), std::max<std::int64_t>(1, rest.at(l) / 500))
          << "label " << l << ": nearest gives " << n.at(l) << " of " << rest.at(l);
    // Background is neither given nor taken: the body's outline stays as sampled.
    EXPECT_EQ(p.at(0), n.at(0));
    EXPECT_FALSE(preservedReport.labelTargets.count(0));
    EXPECT_GT(preservedReport.roundedVoxels, 0);
  }
}

TEST(LabelVolumeRounding, AUniformGrowthGivesEachLabelTheGrownVolume) {
  const ThickSliceBlock b;
  const std::map<int, std::int64_t> rest = counts(b.labels);
  const double s = 1.07;
  const Eigen::Vector3d c(20, 20, 22.5);
  const Eigen::MatrixX3d deformed =
      ((b.mesh.vertices.rowwise() - c.transpose()) * s).rowwise() + c.transpose();
  const VolumeGeometry grid = deformedGrid(b.labels.geometry(), deformed);
  RasterReport report;
  const Volume out = rasterizeLabels(b.labels, b.mesh, deformed, grid, b.options(true), &report);
  const std::map<int, std::int64_t> p = counts(out);
  for (const int l : {1, 2, 3, 4}) {
    SCOPED_TRACE(l);
    const double grown = s * s * s * double(rest.at(l));
    EXPECT_NEAR(report.labelTargets.at(l), grown, 1e-6 * grown);
    // Within 0.5 %: label 1, short of voxels at the outline, gives the others little.
    if (l != 1) {
      EXPECT_LE(std::abs(double(p.at(l)) - grown), std::max(2.5, grown / 200));
    }
  }
}

TEST(LabelVolumeRounding, TheIdentityIsLeftAsSampled) {
  const ThickSliceBlock b;
  RasterReport report;
  const Volume out = rasterizeLabels(b.labels, b.mesh, b.mesh.vertices, b.labels.geometry(),
                                     b.options(true), &report);
  EXPECT_EQ(report.roundedVoxels, 0);
  const std::uint16_t *a = out.data<std::uint16_t>(), *r = b.labels.data<std::uint16_t>();
  std::int64_t different = 0;
  for (std::int64_t v = 0; v < out.numVoxels(); ++v) different += a[v] != r[v];
  EXPECT_EQ(different, 0);
}

TEST(LabelVolumeRounding, AMapOfLayersIsSampledAndTheReportSaysWhy) {
  // Overlapping segments (a .seg.nrrd's layers) cannot be relabelled one voxel at a time: the
  // map is left as sampled, and the report says it was not rounded.
  const ThickSliceBlock b;
  Volume layered(b.labels.geometry(), ScalarType::UInt16, 2);
  layered.setLabelMap(true);
  std::copy_n(b.labels.data<std::uint16_t>(), b.labels.numVoxels(), layered.data<std::uint16_t>(0));
  const Eigen::MatrixX3d deformed = b.turned(41);
  const VolumeGeometry grid = deformedGrid(b.labels.geometry(), deformed);
  RasterReport preserved, nearest;
  const Volume p = rasterizeLabels(layered, b.mesh, deformed, grid, b.options(true), &preserved);
  const Volume n = rasterizeLabels(layered, b.mesh, deformed, grid, b.options(false), &nearest);
  EXPECT_EQ(preserved.roundingSkipped, "a map of 2 layers");
  EXPECT_TRUE(nearest.roundingSkipped.empty());
  EXPECT_EQ(preserved.roundedVoxels, 0);
  EXPECT_TRUE(std::equal(p.data<std::uint16_t>(0), p.data<std::uint16_t>(0) + p.numVoxels(),
                         n.data<std::uint16_t>(0)));
}

// A frame made slab by slab (LabelSlabs, LabelSlabRounding): the slabs' counts and candidates,
// merged, choose exactly the whole grid's voxels, whatever the slab size, thread count, and
// whether the candidates stay in memory or go to a temporary file; label borders run across
// every slab border (slabs of 1 slice: every border between slices is a slab's).
TEST(LabelVolumeRounding, SlabsChooseTheWholeGridsVoxels) {
  const ThickSliceBlock b;
  for (const double degrees : {41.0, 90.0}) {
    const Eigen::MatrixX3d deformed = b.turned(degrees);
    const VolumeGeometry grid = deformedGrid(b.labels.geometry(), deformed);
    for (const int threads : {1, 2}) {
      RasterOptions options = b.options(true);
      options.threads = threads;
      RasterReport whole;
      const Volume expected = rasterizeLabels(b.labels, b.mesh, deformed, grid, options, &whole);
      ASSERT_GT(whole.roundedVoxels, 0);
      const LabelSlabs slabs(b.labels, b.mesh, deformed, grid, options);
      const std::int64_t plane = grid.dims[0] * grid.dims[1], nz = grid.dims[2];
      for (const std::int64_t size : {1, 3, 7})
        for (const std::size_t memory : {std::size_t(-1), std::size_t(0)}) {
          const std::string at = std::to_string(degrees) + " degrees, slabs of " +
                                 std::to_string(size) + ", " + std::to_string(threads) +
                                 " thread(s), " + (memory ? "in memory" : "on disk");
          LabelSlabRounding rounding(slabs, memory);
          EXPECT_EQ(rounding.skipped(), "") << at;
          RasterReport unused;
          // Pass 1: each slab with the slices beside it.
          for (std::int64_t k0 = 0; k0 < nz; k0 += size) {
            const std::int64_t k1 = std::min(nz, k0 + size);
            const std::int64_t lo = std::max<std::int64_t>(0, k0 - 1), hi = std::min(nz, k1 + 1);
            std::vector<std::uint16_t> halo(std::size_t((hi - lo) * plane));
            slabs.rasterize(lo, hi, halo.data(), unused);
            const std::uint16_t* slab = halo.data() + (k0 - lo) * plane;
            rounding.addSlab(k0, k1, k0 > 0 ? slab - plane : nullptr, slab,
                             k1 < nz ? slab + (k1 - k0) * plane : nullptr);
          }
          EXPECT_EQ(memory ? rounding.candidatesOnDisk() : rounding.candidatesInMemory(), 0u) << at;
          RasterReport report;
          rounding.choose(report);
          EXPECT_EQ(report.roundedVoxels, whole.roundedVoxels) << at;
          EXPECT_EQ(report.labelTargets, whole.labelTargets) << at;
          // Pass 2: each slab made again, the choice applied.
          std::vector<std::uint16_t> assembled(std::size_t(nz * plane));
          for (std::int64_t k0 = 0; k0 < nz; k0 += size) {
            const std::int64_t k1 = std::min(nz, k0 + size);
            std::uint16_t* slab = assembled.data() + k0 * plane;
            slabs.rasterize(k0, k1, slab, unused);
            rounding.apply(k0, k1, slab);
          }
          EXPECT_TRUE(
              std::equal(assembled.begin(), assembled.end(), expected.data<std::uint16_t>()))
              << at;
        }
    }
  }
  // Out of order, or chosen early: refused.
  const Eigen::MatrixX3d deformed = b.turned(41);
  const VolumeGeometry grid = deformedGrid(b.labels.geometry(), deformed);
  const LabelSlabs slabs(b.labels, b.mesh, deformed, grid, b.options(true));
  LabelSlabRounding rounding(slabs);
  std::vector<std::uint16_t> slab(std::size_t(grid.dims[0] * grid.dims[1]));
  EXPECT_THROW(rounding.addSlab(1, 2, nullptr, slab.data(), nullptr), Error);
  RasterReport report;
  EXPECT_THROW(rounding.choose(report), Error);
  EXPECT_THROW(rounding.apply(0, 1, slab.data()), Error);
}

TEST(LabelVolumeRounding, SlabsOfALayeredMapSayWhyTheyAreNotRounded) {
  const ThickSliceBlock b;
  Volume layered(b.labels.geometry(), ScalarType::UInt16, 2);
  const Eigen::MatrixX3d deformed = b.turned(41);
  const VolumeGeometry grid = deformedGrid(b.labels.geometry(), deformed);
  const LabelSlabs slabs(layered, b.mesh, deformed, grid, b.options(true));
  LabelSlabRounding rounding(slabs);
  EXPECT_EQ(rounding.skipped(), "a map of 2 layers");
}
