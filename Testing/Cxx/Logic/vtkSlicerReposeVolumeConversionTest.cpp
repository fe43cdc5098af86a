// Tests of Core <-> VTK volume conversion: every scalar type and layer count round-trips bit for
// bit, geometry (oblique, sheared, offset extents) keeps the IJK->RAS matrix, labels survive.
#include "vtkSlicerReposeVolumeConversion.h"

#include <repose/util/Error.h>

#include <gtest/gtest.h>

#include <vtkDoubleArray.h>
#include <vtkImageData.h>
#include <vtkLookupTable.h>
#include <vtkMatrix4x4.h>
#include <vtkPointData.h>

#include <Eigen/Geometry>
#include <cstring>

using Conversion = vtkSlicerReposeVolumeConversion;

namespace {

// An oblique, anisotropic grid with a slight shear, so no axis or spacing is trivial.
repose::VolumeGeometry obliqueGeometry() {
  const Eigen::Matrix3d rotation =
      Eigen::AngleAxisd(0.4, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  repose::VolumeGeometry g = repose::VolumeGeometry::make(
      {7, 5, 3}, Eigen::Vector3d(0.8, 1.25, 3.0), Eigen::Vector3d(-120.5, 33.0, 7.75), rotation);
  g.ijkToRas(0, 1) += 0.05;  // shear
  return g;
}

repose::Volume generated(repose::ScalarType type, int layers) {
  repose::Volume volume(obliqueGeometry(), type, layers);
  volume.setLabelMap(repose::isIntegerType(type));
  repose::dispatchScalar(type, [&](auto* tag) {
    using T = std::remove_pointer_t<decltype(tag)>;
    for (int l = 0; l < layers; ++l) {
      T* data = volume.data<T>(l);
      for (std::int64_t v = 0; v < volume.numVoxels(); ++v)
        data[v] = static_cast<T>((v * 37 + l * 11) % 251 - (std::is_signed_v<T> ? 100 : 0));
    }
  });
  repose::Label liver{1, "liver", {0.8, 0.2, 0.1}, 0, "Segment_1", "Category~SCT^123037004"};
  repose::Label spine{2, "spine", {0.9, 0.9, 0.7}, layers - 1, "", ""};
  volume.labels().set(liver);
  volume.labels().set(spine);
  return volume;
}

void expectSameLabels(const repose::LabelTable& a, const repose::LabelTable& b) {
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    const repose::Label &x = a.labels()[i], &y = b.labels()[i];
    EXPECT_EQ(x.value, y.value);
    EXPECT_EQ(x.layer, y.layer);
    EXPECT_EQ(x.name, y.name);
    EXPECT_EQ(x.color, y.color);
    EXPECT_EQ(x.id, y.id);
    EXPECT_EQ(x.tags, y.tags);
  }
}

}  // namespace

class VolumeConversionRoundTrip
    : public ::testing::TestWithParam<std::tuple<repose::ScalarType, int>> {};

TEST_P(VolumeConversionRoundTrip, IsLossless) {
  const auto [type, layers] = GetParam();
  const repose::Volume volume = generated(type, layers);
  vtkSmartPointer<vtkImageData> image = Conversion::ToImageData(volume);
  EXPECT_EQ(image->GetScalarType(), Conversion::ToVTKScalarType(type));
  EXPECT_EQ(image->GetNumberOfScalarComponents(), layers);
  // Each voxel sits where Core says it does, in RAS mm.
  for (const std::array<int, 3>& ijk : {std::array<int, 3>{0, 0, 0}, {6, 4, 2}, {3, 1, 2}}) {
    double xyz[3];
    image->TransformIndexToPhysicalPoint(ijk.data(), xyz);
    const Eigen::Vector3d ras = volume.geometry().voxelToRas(ijk[0], ijk[1], ijk[2]);
    for (int a = 0; a < 3; ++a) EXPECT_NEAR(xyz[a], ras[a], 1e-12);
  }
  // Component l of voxel (i,j,k) is layer l of Core's voxel.
  const std::int64_t index = volume.index(5, 3, 1);
  for (int l = 0; l < layers; ++l)
    EXPECT_EQ(image->GetScalarComponentAsDouble(5, 3, 1, l), volume.valueAsDouble(index, l));

  const repose::Volume back = Conversion::FromImageData(image);
  EXPECT_EQ(back.scalarType(), type);
  EXPECT_EQ(back.layers(), layers);
  EXPECT_EQ(back.dims(), volume.dims());
  EXPECT_EQ(back.isLabelMap(), volume.isLabelMap());
  EXPECT_TRUE(back.bytes() == volume.bytes());
  EXPECT_TRUE(back.geometry().ijkToRas.isApprox(volume.geometry().ijkToRas, 1e-14));
  expectSameLabels(back.labels(), volume.labels());
}

INSTANTIATE_TEST_SUITE_P(
    AllTypes, VolumeConversionRoundTrip,
    ::testing::Combine(::testing::Values(repose::ScalarType::UInt8, repose::ScalarType::UInt16,
                                         repose::ScalarType::Int16, repose::ScalarType::Int32,
                                         repose::ScalarType::Float32),
                       ::testing::Values(1, 2)),
    [](const ::testing::TestParamInfo<std::tuple<repose::ScalarType, int>>& info) {
      return std::string(repose::scalarTypeName(std::get<0>(info.param))) + "_" +
             std::to_string(std::get<1>(info.param)) + "layers";
    });

TEST(VolumeConversion, ExtentStartFoldsIntoOrigin) {
  const repose::Volume volume = generated(repose::ScalarType::Int16, 1);
  vtkSmartPointer<vtkImageData> image = Conversion::ToImageData(volume);
  // A VOI-style extent starting at (2,1,1): voxel (0,0,0) of the result is image index (2,1,1).
  auto cropped = vtkSmartPointer<vtkImageData>::New();
  cropped->SetExtent(2, 4, 1, 3, 1, 2);
  cropped->SetOrigin(image->GetOrigin());
  cropped->SetSpacing(image->GetSpacing());
  cropped->SetDirectionMatrix(image->GetDirectionMatrix());
  cropped->AllocateScalars(VTK_SHORT, 1);
  const repose::Volume back = Conversion::FromImageData(cropped);
  EXPECT_EQ(back.dims(), (std::array<std::int64_t, 3>{3, 3, 2}));
  double xyz[3];
  cropped->TransformIndexToPhysicalPoint(2, 1, 1, xyz);
  const Eigen::Vector3d origin = back.geometry().origin();
  for (int a = 0; a < 3; ++a) EXPECT_NEAR(origin[a], xyz[a], 1e-12);
}

TEST(VolumeConversion, RejectsWhatCoreCannotHold) {
  auto image = vtkSmartPointer<vtkImageData>::New();
  image->SetDimensions(2, 2, 2);
  EXPECT_THROW(Conversion::FromImageData(image), repose::Error);  // no scalars
  image->AllocateScalars(VTK_DOUBLE, 1);
  try {
    Conversion::FromImageData(image);
    FAIL() << "double accepted";
  } catch (const repose::Error& e) {
    EXPECT_NE(std::string(e.what()).find("double"), std::string::npos) << e.what();
  }
  EXPECT_THROW(Conversion::FromImageData(nullptr), repose::Error);
}

TEST(VolumeConversion, LookupTableAnnotatesLabelsOfOneLayer) {
  const repose::Volume volume = generated(repose::ScalarType::UInt8, 2);
  vtkSmartPointer<vtkLookupTable> lut = Conversion::ToLookupTable(volume.labels(), 0);
  EXPECT_TRUE(lut->GetIndexedLookup());
  ASSERT_EQ(lut->GetNumberOfAnnotatedValues(), 1);
  EXPECT_EQ(lut->GetAnnotation(lut->GetAnnotatedValueIndex(vtkVariant(1))), "liver");
  double rgba[4];
  lut->GetAnnotationColor(vtkVariant(1), rgba);
  EXPECT_DOUBLE_EQ(rgba[0], 0.8);
  vtkSmartPointer<vtkLookupTable> second = Conversion::ToLookupTable(volume.labels(), 1);
  EXPECT_EQ(second->GetAnnotation(second->GetAnnotatedValueIndex(vtkVariant(2))), "spine");
}

TEST(VolumeConversion, MatrixCopiesAllSixteenElements) {
  Eigen::Matrix4d m;
  for (int i = 0; i < 16; ++i) m(i / 4, i % 4) = i * 1.5 - 3;
  vtkSmartPointer<vtkMatrix4x4> matrix = Conversion::ToMatrix(m);
  for (int i = 0; i < 16; ++i) EXPECT_EQ(matrix->GetElement(i / 4, i % 4), m(i / 4, i % 4));
}
