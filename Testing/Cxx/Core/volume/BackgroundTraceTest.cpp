// Enclosed background traced slab by slab (BackgroundTrace) against the whole grid's flood fill
// (outsideBackground): the same voxels for every slab size, holes reaching across slab borders,
// and a cavity that looks closed until a tunnel in a later slab opens it.
#include "repose/util/Error.h"
#include "repose/volume/BackgroundTrace.h"
#include "repose/volume/LabelStatistics.h"

#include <gtest/gtest.h>

#include <random>

using namespace repose;

namespace {

// Enclosed voxels of the whole grid by flood fill from its border.
std::vector<std::int64_t> floodEnclosed(const Volume& v) {
  const std::vector<char> outside = outsideBackground(v);
  std::vector<std::int64_t> out;
  for (std::int64_t i = 0; i < v.numVoxels(); ++i)
    if (v.data<std::uint16_t>()[i] == 0 && !outside[std::size_t(i)]) out.push_back(i);
  return out;
}

// Traced in slabs of `size` slices; the open lists the calls return, joined.
std::vector<std::int64_t> traced(const Volume& v, std::int64_t size,
                                 std::vector<std::int64_t>* open = nullptr) {
  BackgroundTrace trace(v.dims());
  const std::int64_t plane = v.dims()[0] * v.dims()[1], nz = v.dims()[2];
  for (std::int64_t k0 = 0; k0 < nz; k0 += size)
    trace.add(v.data<std::uint16_t>() + k0 * plane, ScalarType::UInt16, k0, std::min(nz, k0 + size),
              open);
  std::vector<std::int64_t> out = trace.enclosedList();
  EXPECT_EQ(trace.enclosedVoxels(), std::int64_t(out.size()));
  for (const std::int64_t voxel : out) EXPECT_TRUE(trace.enclosed(voxel));
  return out;
}

}  // namespace

TEST(BackgroundTrace, RandomTissueGivesTheFloodFillsHolesForEverySlabSize) {
  std::mt19937 random(7);
  for (const double density : {0.55, 0.7, 0.8}) {
    Volume v(VolumeGeometry::make({13, 11, 17}, {1, 1, 1}, {0, 0, 0}), ScalarType::UInt16);
    std::bernoulli_distribution tissue(density);
    std::uniform_int_distribution<int> label(1, 40);
    for (std::int64_t i = 0; i < v.numVoxels(); ++i)
      v.data<std::uint16_t>()[i] = tissue(random) ? std::uint16_t(label(random)) : 0;
    const std::vector<std::int64_t> expected = floodEnclosed(v);
    EXPECT_FALSE(expected.empty()) << density;
    EXPECT_EQ(countEnclosedBackground(v), std::int64_t(expected.size()));
    for (const std::int64_t size : {1, 2, 5, 17}) {
      std::vector<std::int64_t> open;
      EXPECT_EQ(traced(v, size, &open), expected) << density << ", slabs of " << size;
      // Every enclosed voxel was listed open in its slab, and the lists ascend.
      EXPECT_TRUE(std::includes(open.begin(), open.end(), expected.begin(), expected.end()));
      EXPECT_TRUE(std::is_sorted(open.begin(), open.end()));
    }
  }
}

TEST(BackgroundTrace, ACavityOpenedByATunnelSlabsLaterIsNotEnclosed) {
  // A closed box of tissue (shell 1 voxel thick) around a cavity of 4 x 4 x 10, and a second,
  // closed cavity beside it; a tunnel from the first cavity's top up through the shell to the
  // grid's last slice opens it only in the last slabs.
  Volume v(VolumeGeometry::make({16, 8, 16}, {1, 1, 1}, {0, 0, 0}), ScalarType::UInt16);
  auto set = [&](std::int64_t i, std::int64_t j, std::int64_t k, std::uint16_t value) {
    v.data<std::uint16_t>()[v.index(i, j, k)] = value;
  };
  for (std::int64_t k = 1; k < 13; ++k)
    for (std::int64_t j = 1; j < 7; ++j)
      for (std::int64_t i = 1; i < 15; ++i) set(i, j, k, 3);
  for (std::int64_t k = 2; k < 12; ++k)
    for (std::int64_t j = 2; j < 6; ++j) {
      for (std::int64_t i = 2; i < 6; ++i) set(i, j, k, 0);   // opened by the tunnel
      for (std::int64_t i = 9; i < 13; ++i) set(i, j, k, 0);  // closed: 160 voxels
    }
  for (std::int64_t k = 12; k < 16; ++k) set(3, 3, k, 0);  // the tunnel, through the lid
  for (std::int64_t k = 13; k < 16; ++k)
    for (std::int64_t j = 0; j < 8; ++j)
      for (std::int64_t i = 0; i < 16; ++i)
        if (!(i == 3 && j == 3) && !(k == 15)) set(i, j, k, 5);  // a lid above, open at k = 15
  const std::vector<std::int64_t> expected = floodEnclosed(v);
  ASSERT_EQ(expected.size(), 160u);
  for (const std::int64_t size : {1, 3, 4, 16}) {
    std::vector<std::int64_t> open;
    EXPECT_EQ(traced(v, size, &open), expected) << "slabs of " << size;
    // The first cavity's voxels were open when their slabs were traced (the tunnel comes later).
    if (size < 12) EXPECT_GT(open.size(), expected.size()) << "slabs of " << size;
  }
}

TEST(BackgroundTrace, SlabsOutOfOrderAndEarlyQuestionsAreRefused) {
  Volume v(VolumeGeometry::make({4, 4, 4}, {1, 1, 1}, {0, 0, 0}), ScalarType::UInt8);
  BackgroundTrace trace(v.dims());
  EXPECT_THROW(trace.add(v.layerData(0), ScalarType::UInt8, 1, 2), Error);
  trace.add(v.layerData(0), ScalarType::UInt8, 0, 2);
  EXPECT_THROW(trace.enclosedVoxels(), Error);
  EXPECT_THROW(trace.add(v.layerData(0), ScalarType::Float32, 2, 4), Error);
  trace.add(v.data<std::uint8_t>() + 32, ScalarType::UInt8, 2, 4);
  EXPECT_EQ(trace.enclosedVoxels(), 0);
  EXPECT_THROW(trace.add(v.layerData(0), ScalarType::UInt8, 4, 5), Error);
}
