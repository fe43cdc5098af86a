// The tissues each soft tet carries at rest (raster/RestTissues.h): every labelled voxel the rest
// scan reaches is counted once, in the tet that carries it, including a one-voxel layer just
// outside the mesh that only the shell reaches (a skin on thick slices), which counting at the
// tets' own voxel centres (mesh tetTissues) misses; whole pieces' tets carry none.
#include "repose/raster/RestTissues.h"

#include "TestTetMeshes.h"

#include <gtest/gtest.h>

#include <map>

using namespace repose;

namespace {

// A 16-voxel cube of label 1 meshed with its faces half a voxel outside its voxel centres, and
// around it a one-voxel layer of label 2 (the skin) whose centres lie 0.5 mm beyond the faces;
// S marks both as body part 1.
struct SkinnedCube {
  VolumeGeometry grid = VolumeGeometry::make({24, 24, 24}, {1, 1, 1}, {0, 0, 0});
  Volume organs{grid, ScalarType::UInt8}, parts{grid, ScalarType::UInt8};
  TransferMesh mesh;
  std::int64_t inside = 0, layer = 0;
  SkinnedCube() {
    const Eigen::Vector3d a = grid.voxelToRas(3.5, 3.5, 3.5), b = grid.voxelToRas(19.5, 19.5, 19.5);
    mesh = test::tetBox(a.cwiseMin(b), a.cwiseMax(b), {4, 4, 4}, 1);
    for (std::int64_t k = 0; k < 24; ++k)
      for (std::int64_t j = 0; j < 24; ++j)
        for (std::int64_t i = 0; i < 24; ++i) {
          auto within = [&](std::int64_t lo, std::int64_t hi) {
            return i >= lo && i <= hi && j >= lo && j <= hi && k >= lo && k <= hi;
          };
          const int label = within(4, 19) ? 1 : within(3, 20) ? 2 : 0;
          organs.data<std::uint8_t>()[organs.index(i, j, k)] = std::uint8_t(label);
          parts.data<std::uint8_t>()[parts.index(i, j, k)] = std::uint8_t(label > 0);
          inside += label == 1, layer += label == 2;
        }
  }
  RasterOptions options() const {
    RasterOptions o;
    o.restParts = &parts;
    return o;
  }
};

std::map<int, std::int64_t> totals(const TetTissues& t) {
  std::map<int, std::int64_t> sum;
  for (const auto& [label, voxels] : t.entries) sum[label] += voxels;
  return sum;
}

}  // namespace

TEST(RestTissues, EveryVoxelTheRestScanReachesIsCountedOnceShellIncluded) {
  const SkinnedCube c;
  ASSERT_EQ(c.inside, 16 * 16 * 16);
  ASSERT_EQ(c.layer, 18 * 18 * 18 - 16 * 16 * 16);
  const TetTissues scanned = restTetTissues(c.mesh, c.organs, c.options());
  ASSERT_EQ(scanned.offsets.size(), std::size_t(c.mesh.tets.rows()) + 1);
  const auto sum = totals(scanned);
  EXPECT_EQ(sum.at(1), c.inside);
  EXPECT_EQ(sum.at(2), c.layer);
  // At the tets' own centres the layer is not seen at all (and a centre on a face two tets
  // share is counted in both: 7,680 for 4,096 voxels here).
  const auto centres = totals(tetTissues(c.mesh, c.organs));
  EXPECT_GE(centres.at(1), c.inside);
  EXPECT_EQ(centres.count(2), 0u);
}

TEST(RestTissues, WholePiecesCarryNone) {
  SkinnedCube c;
  const Eigen::Index nt = c.mesh.tets.rows();
  c.mesh.rigid.assign(std::size_t(nt), 0);
  for (Eigen::Index t = 0; t < nt; t += 2) c.mesh.rigid[std::size_t(t)] = 1;
  const TetTissues scanned = restTetTissues(c.mesh, c.organs, c.options());
  std::int64_t carried = 0;
  for (Eigen::Index t = 0; t < nt; ++t) {
    const int n = scanned.offsets[std::size_t(t) + 1] - scanned.offsets[std::size_t(t)];
    if (c.mesh.rigid[std::size_t(t)]) {
      EXPECT_EQ(n, 0) << t;
    } else {
      carried += n;
    }
  }
  EXPECT_GT(carried, 0);
}
