// The posed image and the displacement field slab by slab (ImageSlabs, DisplacementSlabs): what a
// frame too large for memory is written from. Every slab size and thread count gives the whole
// grid's values bit for bit, with the shell the pose job uses (the rest parts given).
#include "RasterFixtures.h"

#include "repose/phantom/PhantomPoses.h"
#include "repose/raster/Rasterizer.h"
#include "repose/util/Error.h"

#include <gtest/gtest.h>

#include <cstring>

using namespace repose;
using namespace repose::test;

namespace {

// The phantom's image (a smooth ramp over its labels, as an intensity), the elbow flexed 70
// degrees on a grid of another spacing, so rest positions fall between voxel centres.
struct ElbowFrame {
  Volume image;
  Eigen::MatrixX3d deformed;
  VolumeGeometry grid;
  RasterOptions options;
};

ElbowFrame elbowFrame(ScalarType type) {
  const PhantomScene& s = phantomScene();
  ElbowFrame f;
  f.image = Volume(s.organs.geometry(), type);
  const auto d = s.organs.dims();
  for (std::int64_t k = 0; k < d[2]; ++k)
    for (std::int64_t j = 0; j < d[1]; ++j)
      for (std::int64_t i = 0; i < d[0]; ++i) {
        const std::int64_t v = s.organs.index(i, j, k);
        const double value = 10.0 * s.organs.data<std::uint8_t>()[v] + 0.37 * double(i + 2 * j + k);
        if (type == ScalarType::Int16)
          f.image.data<std::int16_t>()[v] = std::int16_t(value);
        else
          f.image.data<float>()[v] = float(value);
      }
  f.deformed = s.deformation->deform(phantomElbowFlexion(s.phantom, s.cage, 70));
  f.grid = deformedGrid(s.organs.geometry(), f.deformed, 3.3);
  f.options.restParts = &s.parts;
  return f;
}

}  // namespace

TEST(RasterFields, ImageSlabsEqualTheWholeGrid) {
  const PhantomScene& s = phantomScene();
  for (const ScalarType type : {ScalarType::Int16, ScalarType::Float32}) {
    ElbowFrame f = elbowFrame(type);
    for (const int threads : {1, 2}) {
      f.options.threads = threads;
      RasterReport whole;
      const Volume expected =
          rasterizeImage(f.image, s.mesh, f.deformed, f.grid, -5, f.options, &whole);
      const ImageSlabs slabs(f.image, s.mesh, f.deformed, f.grid, -5, f.options);
      const std::int64_t nz = f.grid.dims[2];
      ASSERT_EQ(slabs.sliceBytes(),
                f.grid.dims[0] * f.grid.dims[1] * std::int64_t(scalarSize(type)));
      for (const std::int64_t size : {std::int64_t(1), std::int64_t(4), nz}) {
        std::vector<std::uint8_t> assembled(std::size_t(nz * slabs.sliceBytes()));
        RasterReport sum;
        for (std::int64_t k0 = 0; k0 < nz; k0 += size)
          slabs.rasterize(k0, std::min(nz, k0 + size),
                          assembled.data() + std::size_t(k0 * slabs.sliceBytes()), sum);
        const std::string at =
            "slabs of " + std::to_string(size) + ", " + std::to_string(threads) + " thread(s)";
        EXPECT_EQ(std::memcmp(assembled.data(), expected.layerData(0), assembled.size()), 0) << at;
        EXPECT_EQ(sum.voxelWrites, whole.voxelWrites) << at;
        EXPECT_EQ(sum.shellVoxels, whole.shellVoxels) << at;
        EXPECT_GT(sum.voxelWrites, 0) << at;
      }
    }
  }
  // Not a trivial image: the posed one holds the background and the body's values.
  const ElbowFrame f = elbowFrame(ScalarType::Int16);
  const Volume posed = rasterizeImage(f.image, s.mesh, f.deformed, f.grid, -5, f.options);
  std::int64_t background = 0, body = 0;
  for (std::int64_t v = 0; v < posed.numVoxels(); ++v)
    (posed.data<std::int16_t>()[v] == -5 ? background : body) += 1;
  EXPECT_GT(background, 0);
  EXPECT_GT(body, posed.numVoxels() / 20);
  RasterReport unused;
  EXPECT_THROW(ImageSlabs(f.image, s.mesh, f.deformed, f.grid, -5).rasterize(2, 2, nullptr, unused),
               Error);
}

TEST(RasterFields, DisplacementSlabsEqualTheWholeGrid) {
  const PhantomScene& s = phantomScene();
  ElbowFrame f = elbowFrame(ScalarType::Int16);
  for (const int threads : {1, 2}) {
    f.options.threads = threads;
    const std::vector<float> expected =
        rasterizeDisplacement(s.mesh, f.deformed, s.organs.geometry(), f.grid, f.options);
    const DisplacementSlabs slabs(s.mesh, f.deformed, s.organs.geometry(), f.grid, f.options);
    const std::int64_t nz = f.grid.dims[2];
    ASSERT_EQ(slabs.sliceFloats(), 3 * f.grid.dims[0] * f.grid.dims[1]);
    ASSERT_EQ(std::int64_t(expected.size()), nz * slabs.sliceFloats());
    for (const std::int64_t size : {std::int64_t(1), std::int64_t(5), nz}) {
      std::vector<float> assembled(expected.size(), -1e30f);
      for (std::int64_t k0 = 0; k0 < nz; k0 += size)
        slabs.rasterize(k0, std::min(nz, k0 + size),
                        assembled.data() + std::size_t(k0 * slabs.sliceFloats()));
      EXPECT_EQ(std::memcmp(assembled.data(), expected.data(), expected.size() * sizeof(float)), 0)
          << "slabs of " << size << ", " << threads << " thread(s)";
    }
  }
  // The field moves the forearm: some vectors are centimetres long.
  const std::vector<float> field =
      rasterizeDisplacement(s.mesh, f.deformed, s.organs.geometry(), f.grid, f.options);
  float longest = 0;
  for (std::size_t v = 0; v < field.size(); v += 3)
    longest = std::max(longest, std::sqrt(field[v] * field[v] + field[v + 1] * field[v + 1] +
                                          field[v + 2] * field[v + 2]));
  EXPECT_GT(longest, 20.0f);
  EXPECT_THROW(DisplacementSlabs(s.mesh, f.deformed, s.organs.geometry(), f.grid)
                   .rasterize(0, f.grid.dims[2] + 1, nullptr),
               Error);
}
