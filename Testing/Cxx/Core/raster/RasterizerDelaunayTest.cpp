// The rasterizer's ownership rule (docs/ARCHITECTURE.md, the (e, e^2, e^3) tie of TetScan.h) on
// irregular conforming meshes (issue 29, item 3): Delaunay tetrahedralizations (CGAL) of random
// voxel centres in a box. Every vertex on a centre makes faces, edges and vertices pass through
// many centres at every angle, not only the axis-aligned and diagonal planes of the Kuhn boxes:
// each centre inside must be claimed by exactly one tet, the box's boundary as the half-open
// box [lo, hi) says, and none outside.
#include "TestDelaunay.h"

#include "repose/raster/Rasterizer.h"

#include <gtest/gtest.h>

#include <random>
#include <set>

using namespace repose;
using namespace repose::test;

TEST(RasterizerDelaunay, EveryCentreHasOneOwnerOnMeshesOfRandomCentres) {
  const Eigen::Vector3i lo(2, 2, 2), hi(16, 13, 11);
  const VolumeGeometry grid = VolumeGeometry::make({19, 16, 14}, {1, 1, 1}, {0, 0, 0});
  for (const unsigned seed : {1u, 2u, 3u, 4u}) {
    std::mt19937 rng(seed);
    std::uniform_int_distribution<int> x(lo.x(), hi.x()), y(lo.y(), hi.y()), z(lo.z(), hi.z());
    std::set<std::array<int, 3>> chosen;
    for (int c = 0; c < 8; ++c)  // the corners: the hull is the box
      chosen.insert({c & 1 ? hi.x() : lo.x(), c & 2 ? hi.y() : lo.y(), c & 4 ? hi.z() : lo.z()});
    while (chosen.size() < 8 + 120) chosen.insert({x(rng), y(rng), z(rng)});
    std::vector<Eigen::Vector3d> points;
    for (const auto& p : chosen) points.emplace_back(p[0], p[1], p[2]);
    const TransferMesh mesh = delaunayMesh(points);
    const Volume coverage = rasterizeCoverage(mesh, mesh.vertices, grid);
    const std::uint8_t* count = coverage.data<std::uint8_t>();
    std::int64_t wrong = 0, inside = 0;
    for (std::int64_t k = 0; k < grid.dims[2]; ++k)
      for (std::int64_t j = 0; j < grid.dims[1]; ++j)
        for (std::int64_t i = 0; i < grid.dims[0]; ++i) {
          const bool in =
              i >= lo.x() && i < hi.x() && j >= lo.y() && j < hi.y() && k >= lo.z() && k < hi.z();
          inside += in;
          wrong += count[coverage.index(i, j, k)] != (in ? 1 : 0);
        }
    EXPECT_EQ(wrong, 0) << "seed " << seed << ": " << mesh.tets.rows() << " tets, " << inside
                        << " centres inside";
    EXPECT_GT(mesh.tets.rows(), 300) << "seed " << seed;
  }
}
