// Tests of vtkSlicerReposeLogic on real files: loaded image data matches the Core volume
// (geometry, voxels, labels), the logic follows its parameter node, and errors are one line.
#include "vtkMRMLReposeParametersNode.h"
#include "vtkSlicerReposeLogic.h"
#include "vtkSlicerReposeVolumeConversion.h"

#include "TestPaths.h"

#include <repose/io/VolumeIO.h>

#include <gtest/gtest.h>

#include <vtkImageData.h>
#include <vtkLookupTable.h>
#include <vtkMatrix3x3.h>
#include <vtkMatrix4x4.h>
#include <vtkNew.h>
#include <vtkPointData.h>

#include <array>
#include <cstring>
#include <set>
#include <fstream>

namespace {

// The loaded image must put every voxel where Core's IJK->RAS says, and hold the same bytes.
void expectMatchesCore(vtkSlicerReposeLogic* logic, const std::string& path) {
  const repose::Volume core = repose::readVolume(path);
  vtkImageData* image = logic->GetVolumeImageData();
  ASSERT_NE(image, nullptr);
  int dims[3];
  image->GetDimensions(dims);
  for (int a = 0; a < 3; ++a) EXPECT_EQ(dims[a], core.dims()[a]);
  const Eigen::Vector3d spacing = core.geometry().spacing(), origin = core.geometry().origin();
  const Eigen::Matrix3d direction = core.geometry().directions();
  for (int a = 0; a < 3; ++a) {
    EXPECT_NEAR(image->GetSpacing()[a], spacing[a], 1e-12);
    EXPECT_NEAR(image->GetOrigin()[a], origin[a], 1e-12);
    for (int c = 0; c < 3; ++c)
      EXPECT_NEAR(image->GetDirectionMatrix()->GetElement(a, c), direction(a, c), 1e-12);
  }
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c)
      EXPECT_EQ(logic->GetVolumeIJKToRASMatrix()->GetElement(r, c), core.geometry().ijkToRas(r, c));
  EXPECT_EQ(image->GetNumberOfScalarComponents(), core.layers());
  EXPECT_EQ(image->GetScalarType(),
            vtkSlicerReposeVolumeConversion::ToVTKScalarType(core.scalarType()));
  const repose::Volume back = vtkSlicerReposeVolumeConversion::FromImageData(image);
  EXPECT_TRUE(back.bytes() == core.bytes());
  EXPECT_EQ(logic->GetVolumeLabelNames().size(), core.labels().size());
}

}  // namespace

TEST(vtkSlicerReposeLogic, LoadsTotalSegmentatorNifti) {
  vtkNew<vtkSlicerReposeLogic> logic;
  const std::string path = repose::test::dataPath("totalsegmentator/example_seg.nii.gz");
  ASSERT_TRUE(logic->LoadVolume(path)) << logic->GetLastErrorMessage();
  EXPECT_TRUE(logic->GetLastErrorMessage().empty());
  expectMatchesCore(logic, path);
  int dims[3];
  logic->GetVolumeImageData()->GetDimensions(dims);
  EXPECT_EQ(dims[0], 122);
  EXPECT_EQ(dims[1], 101);
  EXPECT_EQ(dims[2], 30);
  EXPECT_NEAR(logic->GetVolumeImageData()->GetSpacing()[0], 3.0, 1e-4);
  EXPECT_GE(logic->GetVolumeLabelNames().size(), 41u);
  ASSERT_NE(logic->GetVolumeLookupTable(), nullptr);
  const std::string summary = logic->GetVolumeSummary();
  EXPECT_NE(summary.find("Dimensions: 122 x 101 x 30"), std::string::npos) << summary;
  EXPECT_NE(summary.find("Scalar type: uint8"), std::string::npos) << summary;
  EXPECT_NE(summary.find("Orientation: RAS"), std::string::npos) << summary;
  EXPECT_EQ(logic->GetVolumeLabelsPresent(), 41);  // as the data README says
  EXPECT_NE(summary.find("Labels: 41 present"), std::string::npos) << summary;
}

TEST(vtkSlicerReposeLogic, LoadsSlicerSegmentationsInLps) {
  vtkNew<vtkSlicerReposeLogic> logic;
  const std::string path = repose::test::dataPath("slicer_seg/Segmentation.seg.nrrd");
  ASSERT_TRUE(logic->LoadVolume(path)) << logic->GetLastErrorMessage();
  expectMatchesCore(logic, path);
  EXPECT_EQ(logic->GetVolumeLabelNames().size(), 7u);
  EXPECT_EQ(logic->GetVolumeLabelsPresent(), 7);
  // An intensity image has no labels to count.
  ASSERT_TRUE(logic->LoadVolume(repose::test::dataPath("slicer_seg/CTChest4.nrrd")));
  EXPECT_EQ(logic->GetVolumeLabelsPresent(), -1);
  EXPECT_NE(logic->GetVolumeSummary().find("not a label map"), std::string::npos);
  const std::string overlapping =
      repose::test::dataPath("slicer_seg/SegmentationOverlapping.seg.nrrd");
  ASSERT_TRUE(logic->LoadVolume(overlapping)) << logic->GetLastErrorMessage();
  expectMatchesCore(logic, overlapping);
  EXPECT_EQ(logic->GetVolumeImageData()->GetNumberOfScalarComponents(), 2);
  EXPECT_NE(logic->GetVolumeSummary().find("Layers: 2"), std::string::npos);
}

TEST(vtkSlicerReposeLogic, LoadsADicomSegAndSaysWhichGridItTook) {
  vtkNew<vtkSlicerReposeLogic> logic;
  const std::string path = repose::test::dataPath("dcmqi_ct3slice/partial_overlaps.dcm");
  ASSERT_TRUE(logic->LoadVolume(path)) << logic->GetLastErrorMessage();
  expectMatchesCore(logic, path);
  EXPECT_EQ(logic->GetVolumeLabelNames().size(), 5u);
  const std::string summary = logic->GetVolumeSummary();
  EXPECT_NE(summary.find("Layers: 3"), std::string::npos) << summary;
  EXPECT_NE(summary.find("\nNote: placed on the grid of its referenced series in "),
            std::string::npos)
      << summary;
  // The next file's summary has no note of this one.
  ASSERT_TRUE(logic->LoadVolume(repose::test::dataPath("slicer_seg/Segmentation.seg.nrrd")));
  EXPECT_EQ(logic->GetVolumeSummary().find("Note:"), std::string::npos);
}

TEST(vtkSlicerReposeLogic, MissingOrBadFileGivesOneLineError) {
  vtkNew<vtkSlicerReposeLogic> logic;
  ASSERT_TRUE(logic->LoadVolume(repose::test::dataPath("totalsegmentator/example_seg.nii.gz")));
  const std::string missing = repose::test::dataPath("no/such/file.nii.gz");
  EXPECT_FALSE(logic->LoadVolume(missing));
  const std::string& error = logic->GetLastErrorMessage();
  EXPECT_NE(error.find(missing), std::string::npos) << error;
  EXPECT_EQ(error.find('\n'), std::string::npos) << error;
  EXPECT_EQ(logic->GetVolumeImageData(), nullptr);  // the previous volume is gone
  EXPECT_TRUE(logic->GetVolumeSummary().empty());

  repose::test::ScratchDir scratch;
  const std::string garbage = scratch.file("garbage.nii");
  std::ofstream(garbage) << "this is not a NIfTI file";
  EXPECT_FALSE(logic->LoadVolume(garbage));
  EXPECT_NE(logic->GetLastErrorMessage().find("garbage.nii"), std::string::npos);
  EXPECT_EQ(logic->GetLastErrorMessage().find('\n'), std::string::npos);
  EXPECT_FALSE(logic->LoadVolume(""));
  EXPECT_FALSE(logic->GetLastErrorMessage().empty());
}

TEST(vtkSlicerReposeLogic, AFileClaimingMoreThanTheMemoryBudgetIsRefusedUnread) {
  // 150 bytes whose header claims 4000^3 voxels (64 GB): the workbench reads within half the
  // physical memory, so this is refused from the header, before teem allocates anything.
  repose::test::ScratchDir scratch;
  const std::string claim = scratch.file("claims-64GB.nrrd");
  std::ofstream(claim, std::ios::binary)
      << "NRRD0004\ntype: uint8\ndimension: 3\nsizes: 4000 4000 4000\n"
         "space: left-posterior-superior\nspace directions: (1,0,0) (0,1,0) (0,0,1)\n"
         "encoding: raw\n\n"
      << std::string(64, '\0');
  vtkNew<vtkSlicerReposeLogic> logic;
  EXPECT_FALSE(logic->LoadVolume(claim));
  const std::string& error = logic->GetLastErrorMessage();
  EXPECT_EQ(error.rfind(claim, 0), 0u) << error;
  EXPECT_NE(error.find("reading it needs"), std::string::npos) << error;
  EXPECT_NE(error.find("64000000000 voxels"), std::string::npos) << error;
  EXPECT_NE(error.find("the workbench reads within half the physical memory"), std::string::npos)
      << error;
  EXPECT_EQ(error.find('\n'), std::string::npos) << error;
  EXPECT_EQ(logic->GetVolumeImageData(), nullptr);
  // Adding it as a segmentation to the scene is refused the same way.
  EXPECT_EQ(logic->AddSegmentation(claim, "", ""), nullptr);
  EXPECT_NE(logic->GetLastErrorMessage().find("reading it needs"), std::string::npos)
      << logic->GetLastErrorMessage();
}

TEST(vtkSlicerReposeLogic, FollowsParameterNode) {
  vtkNew<vtkSlicerReposeLogic> logic;
  vtkNew<vtkMRMLReposeParametersNode> node;
  const std::string path = repose::test::dataPath("slicer_seg/Segmentation.seg.nrrd");
  node->SetInputSegmentationPath(path);
  logic->SetParameterNode(node);  // adopts the node's input at once
  ASSERT_NE(logic->GetVolumeImageData(), nullptr) << logic->GetLastErrorMessage();
  EXPECT_EQ(logic->GetVolumePath(), path);

  vtkImageData* before = logic->GetVolumeImageData();
  node->SetCageVertexCount(500);  // unrelated change: no reload
  EXPECT_EQ(logic->GetVolumeImageData(), before);

  node->SetInputSegmentationPath("");
  EXPECT_EQ(logic->GetVolumeImageData(), nullptr);
  EXPECT_TRUE(logic->GetLastErrorMessage().empty());

  // Loading through the logic writes the path back to the node.
  const std::string nifti = repose::test::dataPath("totalsegmentator/example_seg.nii.gz");
  ASSERT_TRUE(logic->LoadVolume(nifti));
  EXPECT_EQ(node->GetInputSegmentationPath(), nifti);

  // Without a node given, the logic takes a new one of its own (its state lives in a node) and
  // follows it: the old node is no longer observed.
  logic->SetParameterNode(nullptr);
  ASSERT_NE(logic->GetParameterNode(), nullptr);
  EXPECT_NE(logic->GetParameterNode(), node.GetPointer());
  EXPECT_EQ(logic->GetVolumePath(), "");  // the new node names no input
  node->SetInputSegmentationPath(path);   // no longer observed
  EXPECT_EQ(logic->GetVolumePath(), "");
}

// A label map with no colour table (a NIfTI from another tool): every label present gets its own
// colour and its number as the name in the display's lookup table, not the table's one colour
// for unknown values (every label drawn the same dark red); a label the table names keeps its
// colour and name.
TEST(vtkSlicerReposeLogic, EveryLabelPresentHasItsOwnColourWithOrWithoutAColourTable) {
  repose::test::ScratchDir dir;
  repose::VolumeGeometry g;
  g.dims = {8, 8, 4};
  repose::Volume v(g, repose::ScalarType::UInt8);
  v.setLabelMap(true);
  const std::vector<int> values = {1, 2, 3, 7, 200};
  for (std::int64_t i = 0; i < v.numVoxels(); ++i)
    v.data<std::uint8_t>()[i] =
        std::uint8_t(i % 3 == 0 ? 0 : values[std::size_t(i) % values.size()]);
  repose::Label named;
  named.value = 7;
  named.name = "liver";
  named.color = {0.1, 0.2, 0.3};
  v.labels().set(named);
  const std::string path = dir.file("no_table.nii.gz");
  repose::writeVolume(v, path);

  vtkNew<vtkSlicerReposeLogic> logic;
  ASSERT_TRUE(logic->LoadVolume(path)) << logic->GetLastErrorMessage();
  vtkLookupTable* lut = logic->GetVolumeLookupTable();
  ASSERT_TRUE(lut);
  std::set<std::array<double, 3>> colours;
  for (const int value : values) {
    const vtkIdType index = lut->GetAnnotatedValueIndex(vtkVariant(value));
    ASSERT_GE(index, 0) << value;
    double rgba[4];
    lut->GetTableValue(index, rgba);
    colours.insert({rgba[0], rgba[1], rgba[2]});
    EXPECT_EQ(lut->GetAnnotation(index), value == 7 ? "liver" : std::to_string(value));
  }
  EXPECT_EQ(colours.size(), values.size());  // distinct
  double liver[4];  // the named label keeps its own colour (as the file stores it, 8 bits)
  lut->GetTableValue(lut->GetAnnotatedValueIndex(vtkVariant(7)), liver);
  EXPECT_NEAR(liver[0], 0.1, 1.0 / 255);
  EXPECT_NEAR(liver[1], 0.2, 1.0 / 255);
  EXPECT_NEAR(liver[2], 0.3, 1.0 / 255);
  EXPECT_LT(lut->GetAnnotatedValueIndex(vtkVariant(0)), 0);  // background is not a label
  // The same for the lookup the views build from a node's label map.
  vtkSmartPointer<vtkLookupTable> fromImage =
      vtkSlicerReposeLogic::GetLabelLookupTable(logic->GetVolumeImageData());
  ASSERT_TRUE(fromImage);
  EXPECT_EQ(fromImage->GetNumberOfAnnotatedValues(), vtkIdType(values.size()));
}
