// The FDTD voxel model: a grid along RAS in any voxel order keeps every voxel (only reordered),
// a resampled grid keeps each tissue's volume to within its surface's share of a cell, and
// materials are one per (tissue, density).
#include "TestVolumes.h"

#include "repose/dosimetry/FdtdModel.h"
#include "repose/util/Error.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <Eigen/LU>

using namespace repose;

namespace {

// A 12x10x8 label map on an LPS grid whose voxel axes run P, S, L (a permuted, flipped grid, as
// a sagittal DICOM series is stored), with two tissues and a ball of a third.
Volume permutedBody() {
  Eigen::Matrix3d d;
  d.col(0) = Eigen::Vector3d(0, -1, 0);  // i -> posterior
  d.col(1) = Eigen::Vector3d(0, 0, 1);   // j -> superior
  d.col(2) = Eigen::Vector3d(-1, 0, 0);  // k -> left... in RAS, -R
  Volume v(VolumeGeometry::make({12, 10, 8}, {1.5, 2.0, 3.0}, {40, 12, -7}, d), ScalarType::UInt16);
  v.setLabelMap(true);
  std::uint16_t* p = v.data<std::uint16_t>();
  for (std::int64_t k = 0; k < 8; ++k)
    for (std::int64_t j = 0; j < 10; ++j)
      for (std::int64_t i = 0; i < 12; ++i) {
        const double r = std::hypot(i - 6.0, j - 5.0, k - 4.0);
        p[v.index(i, j, k)] = r < 2.5 ? 7 : (i > 2 && i < 10 ? 3 : (j > 7 ? 0 : 1));
      }
  return v;
}

std::map<int, LabelTissue> tissues() {
  std::map<int, LabelTissue> t;
  t[1] = {"skin", 1109, "test", "Skin (Dry)", "test"};
  t[3] = {"muscle", 1090, "test", "Muscle", "test"};
  t[7] = {"liver", 1079, "test", "Liver", "test"};
  return t;
}

}  // namespace

TEST(FdtdModel, AnAxisAlignedGridIsOnlyReorderedCellForCell) {
  const Volume v = permutedBody();
  FdtdModelOptions o;
  o.frequencyHz = 900e6;
  const FdtdModel m = buildFdtdModel(v, tissues(), o, "body.nii.gz");
  EXPECT_FALSE(m.resampled);
  // R gets k's 8 voxels of 3 mm, A gets i's 12 of 1.5 mm, S gets j's 10 of 2 mm.
  EXPECT_EQ(m.dims, (std::array<std::int64_t, 3>{8, 12, 10}));
  EXPECT_TRUE(m.spacingMm.isApprox(Eigen::Vector3d(3, 1.5, 2)));
  ASSERT_EQ(m.materials.size(), 4u);  // background, skin, muscle, liver
  // Every cell holds the material of G's voxel at its centre.
  const Eigen::Matrix4d toIjk = v.geometry().ijkToRas.inverse();
  const std::uint16_t* p = v.data<std::uint16_t>();
  for (std::int64_t z = 0; z < m.dims[2]; ++z)
    for (std::int64_t y = 0; y < m.dims[1]; ++y)
      for (std::int64_t x = 0; x < m.dims[0]; ++x) {
        const Eigen::Vector3d c =
            m.cornerMm +
            (Eigen::Vector3d(x, y, z) + Eigen::Vector3d::Constant(0.5)).cwiseProduct(m.spacingMm);
        const Eigen::Vector4d ijk = toIjk * c.homogeneous();
        const std::int64_t i = std::lround(ijk[0]), j = std::lround(ijk[1]),
                           k = std::lround(ijk[2]);
        ASSERT_NEAR(ijk[0], double(i), 1e-9);
        const int label = p[v.index(i, j, k)];
        const int material = label == 0 ? 0 : m.labels.at(label).material;
        ASSERT_EQ(m.index[std::size_t((z * m.dims[1] + y) * m.dims[0] + x)], material);
      }
  for (const auto& [label, c] : m.labels) EXPECT_EQ(c.voxels, c.inputVoxels) << label;
  const FdtdMaterial& muscle = m.materials[std::size_t(m.labels.at(3).material)];
  EXPECT_EQ(muscle.tissue, "Muscle");
  EXPECT_NEAR(muscle.dielectric.relativePermittivity, 55.03, 0.01);
  EXPECT_NEAR(muscle.massKg(), 1090 * muscle.volumeMl * 1e-6, 1e-12);
}

TEST(FdtdModel, AResampledGridKeepsEachTissuesVolumeNearlyAndCoversG) {
  const Volume v = permutedBody();
  FdtdModelOptions o;
  o.spacingMm = Eigen::Vector3d(1, 1, 1);
  const FdtdModel m = buildFdtdModel(v, tissues(), o, "body.nii.gz");
  EXPECT_TRUE(m.resampled);
  EXPECT_EQ(m.dims, (std::array<std::int64_t, 3>{24, 18, 20}));
  for (const auto& [label, c] : m.labels) {
    // Nearest neighbour at integer refinements of 1.5 mm (1.5 cells) is exact up to the cells
    // whose centre falls on a voxel boundary: within a layer of cells over the label's surface.
    EXPECT_NEAR(c.volumeMl, c.inputVolumeMl, 0.15 * c.inputVolumeMl) << label;
  }
  // Refinement by whole factors along R (3 mm -> 1 mm) and S (2 -> 1) and a half-voxel grid
  // along A: 1 mm cells in RAS are exact copies of G there.
  double body = 0, input = 0;
  for (std::size_t k = 1; k < m.materials.size(); ++k)
    body += m.materials[k].volumeMl, input += m.materials[k].inputVolumeMl;
  EXPECT_NEAR(body, input, 0.05 * input);
}

TEST(FdtdModel, ObliqueGridsNeedACellSizeAndMaterialsAreSharedByTissueAndDensity) {
  Volume oblique(test::obliqueGeometry(), ScalarType::UInt8);
  oblique.setLabelMap(true);
  std::fill(oblique.data<std::uint8_t>(), oblique.data<std::uint8_t>() + oblique.numVoxels(), 1);
  std::map<int, LabelTissue> t;
  t[1] = {"skin", 1109, "test", "Skin (Dry)", "test"};
  try {
    buildFdtdModel(oblique, t, {}, "oblique.nrrd");
    FAIL() << "an oblique grid was taken as it is";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("oblique.nrrd: its voxel axes are oblique"),
              std::string::npos)
        << e.what();
  }
  FdtdModelOptions o;
  o.spacingMm = Eigen::Vector3d(2, 2, 2);
  const FdtdModel m = buildFdtdModel(oblique, t, o, "oblique.nrrd");
  EXPECT_NEAR(m.labels.at(1).volumeMl, m.labels.at(1).inputVolumeMl,
              0.35 * m.labels.at(1).inputVolumeMl);

  // Two labels of one tissue and density share a material; another density makes its own.
  const Volume v = permutedBody();
  std::map<int, LabelTissue> shared = tissues();
  shared[7] = {"muscle_b", 1090, "test", "Muscle", "test"};
  EXPECT_EQ(buildFdtdModel(v, shared, {}, "b").materials.size(), 3u);
  shared[7].densityKgM3 = 1100;
  EXPECT_EQ(buildFdtdModel(v, shared, {}, "b").materials.size(), 4u);
}

TEST(FdtdModel, CellSizesAreParsedPerAxis) {
  EXPECT_TRUE(parseCellSizeMm("2").isApprox(Eigen::Vector3d(2, 2, 2)));
  EXPECT_TRUE(parseCellSizeMm("1,2,4.5").isApprox(Eigen::Vector3d(1, 2, 4.5)));
  for (const char* bad : {"", "0", "-1", "1,2", "a", "1,2,3,4", "2mm"})
    EXPECT_THROW(parseCellSizeMm(bad), Error) << bad;
}

TEST(FdtdModel, ALabelWithoutATissueIsRefusedNotMadeBackground) {
  const Volume v = permutedBody();
  std::map<int, LabelTissue> t = tissues();
  t.erase(7);
  try {
    buildFdtdModel(v, t, {}, "body.nii.gz");
    FAIL() << "label 7 became background";
  } catch (const Error& e) {
    EXPECT_STREQ(e.what(), "body.nii.gz: label 7 has no tissue");
  }
}
