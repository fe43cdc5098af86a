// DICOM series through GDCM: JPEG 2000 and uncompressed give identical voxels, the geometry
// matches the NIfTI segmentation made from the same series, and the anatomy lines up.
#include "TestPaths.h"
#include "TestVolumes.h"

#include "repose/io/DicomSeriesIO.h"
#include "repose/io/VolumeIO.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>

using namespace repose;
using namespace repose::test;

namespace {

const Volume& ctSeries() {
  static const Volume v = readVolume(dataPath("totalsegmentator/example_ct_dicom_uncompressed"));
  return v;
}

}  // namespace

TEST(DicomSeries, Jpeg2000AndUncompressedGiveIdenticalVoxels) {
  const Volume j2k = readVolume(dataPath("totalsegmentator/example_ct_dicom_j2k"));
  EXPECT_EQ(j2k.dims(), (std::array<std::int64_t, 3>{512, 512, 20}));
  EXPECT_TRUE(sameVoxels(j2k, ctSeries()));
  EXPECT_LT(matrixDifference(j2k.geometry().ijkToRas, ctSeries().geometry().ijkToRas), 1e-9);
  EXPECT_EQ(j2k.scalarType(), ScalarType::Int16);
}

TEST(DicomSeries, GeometryMatchesTheNiftiSegmentationOfTheSeries) {
  const Volume seg = readVolume(dataPath("totalsegmentator/example_seg_dicom.nii.gz"));
  const VolumeGeometry& g = ctSeries().geometry();
  EXPECT_LT((g.spacing() - Eigen::Vector3d(0.9765625, 0.9765625, 2.0)).norm(), 1e-5);
  // README: NIfTI i = DICOM column, NIfTI j = 511 - DICOM row, NIfTI k = 0 at z = -804.5 mm.
  int kAtBottom = -1;
  for (int k = 0; k < 20; ++k)
    if (std::fabs(g.voxelToRas(0, 0, k).z() + 804.5) < 1e-3) kAtBottom = k;
  ASSERT_GE(kAtBottom, 0);
  for (const Eigen::Vector3d& ijk : {Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(511, 0, 19),
                                     Eigen::Vector3d(17, 300, 7), Eigen::Vector3d(511, 511, 10)}) {
    const Eigen::Vector3d niftiIjk =
        seg.geometry().rasToVoxel(g.voxelToRas(ijk.x(), ijk.y(), ijk.z()));
    EXPECT_NEAR(niftiIjk.x(), ijk.x(), 1e-3);
    EXPECT_NEAR(niftiIjk.y(), 511 - ijk.y(), 1e-3);
    EXPECT_NEAR(std::fabs(niftiIjk.z() - (ijk.z() - kAtBottom)), 0, 1e-3);
  }
}

TEST(DicomSeries, SegmentationLabelsLandOnTheRightTissue) {
  // Resample the label map into the CT by physical position: bones must be dense, the liver soft
  // tissue. A flip of any axis would put labels on the wrong tissue.
  const Volume seg = readVolume(dataPath("totalsegmentator/example_seg_dicom.nii.gz"));
  const Volume& ct = ctSeries();
  double boneSum = 0, liverSum = 0;
  std::int64_t bone = 0, liver = 0;
  const auto& d = seg.dims();
  for (std::int64_t k = 0; k < d[2]; ++k)
    for (std::int64_t j = 0; j < d[1]; ++j)
      for (std::int64_t i = 0; i < d[0]; ++i) {
        const int label = seg.data<std::uint8_t>()[seg.index(i, j, k)];
        if (!label) continue;
        const Eigen::Vector3d c = ct.geometry().rasToVoxel(seg.geometry().voxelToRas(i, j, k));
        const auto ci = std::lround(c.x()), cj = std::lround(c.y()), ck = std::lround(c.z());
        if (ci < 0 || cj < 0 || ck < 0 || ci >= 512 || cj >= 512 || ck >= 20) continue;
        const double hu = ct.data<std::int16_t>()[ct.index(ci, cj, ck)];
        const std::string& name = seg.labels().find(label)->name;
        if (name.rfind("vertebrae", 0) == 0 || name.rfind("rib", 0) == 0) boneSum += hu, ++bone;
        if (name == "liver") liverSum += hu, ++liver;
      }
  ASSERT_GT(bone, 1000);
  ASSERT_GT(liver, 1000);
  EXPECT_GT(boneSum / bone, 200);
  EXPECT_GT(liverSum / liver, 0);
  EXPECT_LT(liverSum / liver, 150);
}

TEST(DicomSeries, GeSeriesMatchesItsNrrdLabelMaps) {
  const Volume ct = readVolume(dataPath("dcmqi_ct3slice/ct-3slice"));
  const Volume liver = readVolume(dataPath("dcmqi_ct3slice/liver_seg.nrrd"));
  EXPECT_EQ(ct.dims(), liver.dims());
  // The NRRD's slice 0 is 03.dcm; slices sorted by position must agree with it.
  EXPECT_LT(matrixDifference(ct.geometry().ijkToRas, liver.geometry().ijkToRas), 1e-3);
  EXPECT_LT(ct.valueAsDouble(0), -900);  // rescale intercept -1024 applied: air in the corner
}

TEST(DicomSeries, BadFoldersGiveOneLineErrors) {
  ScratchDir dir;
  EXPECT_THROW(readVolume(dir.path().string()), Error);  // empty folder
  std::ofstream(dir.file("notdicom.txt")) << "hello";
  try {
    readVolume(dir.path().string());
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("no DICOM image"), std::string::npos) << e.what();
  }
  // Missing slice in the middle: uneven spacing is refused, not silently stretched.
  const std::string src = dataPath("totalsegmentator/example_ct_dicom_uncompressed");
  int n = 0;
  for (const auto& e : std::filesystem::directory_iterator(src))
    if (e.path().filename().string().find("16580") == std::string::npos)
      std::filesystem::copy_file(e.path(), dir.path() / e.path().filename()), ++n;
  ASSERT_EQ(n, 19);
  try {
    readVolume(dir.path().string());
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("evenly spaced"), std::string::npos) << e.what();
  }
}

// Regression (Testing/Fuzz/FuzzDicom): GDCM allocates and zero-fills each element at the length
// the file claims, so one corrupt length made a 0.5 MB file take 4 GB. Such a file is refused
// before GDCM sees it, with the element named; the untouched series still reads.
TEST(DicomSeries, ElementLongerThanTheFileIsRefusedBeforeGdcmAllocatesIt) {
  ScratchDir dir;
  const std::string src = dataPath("dcmqi_ct3slice/ct-3slice");
  for (const auto& e : std::filesystem::directory_iterator(src))
    std::filesystem::copy_file(e.path(), dir.path() / e.path().filename());
  EXPECT_EQ(readVolume(dir.path().string()).dims()[2], 3);
  // The middle slice's (7FE0,0010) Pixel Data made to claim 0xFF000000 bytes (its 32-bit length
  // follows the tag in implicit VR, as here, or "OW" and two reserved bytes in explicit VR).
  const std::string slice = (dir.path() / "02.dcm").string();
  std::fstream f(slice, std::ios::in | std::ios::out | std::ios::binary);
  std::vector<char> bytes((std::istreambuf_iterator<char>(f)), {});
  const char pixelData[4] = {'\xE0', '\x7F', '\x10', '\x00'};
  const auto at = std::search(bytes.begin(), bytes.end(), pixelData, pixelData + 4);
  ASSERT_NE(at, bytes.end());
  const bool explicitVr = at[4] == 'O' && (at[5] == 'W' || at[5] == 'B');
  const std::size_t lengthAt = std::size_t(at - bytes.begin()) + (explicitVr ? 8 : 4);
  const unsigned char huge[4] = {0x00, 0x00, 0x00, 0xFF};
  f.clear();
  f.seekp(std::streamoff(lengthAt));
  f.write(reinterpret_cast<const char*>(huge), 4);
  f.close();
  try {
    readVolume(dir.path().string());
    FAIL() << "a file claiming 4 GB of pixel data was read";
  } catch (const Error& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("02.dcm"), std::string::npos) << msg;
    EXPECT_NE(msg.find("(7FE0,0010) claims 4278190080 bytes"), std::string::npos) << msg;
    EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
  }
}

// Regression (Testing/Fuzz/FuzzDicom): a file meta header followed by zeros makes Debian's GDCM
// fail an assert() and abort the process. GDCM now reads each file first in a child process, so
// this process lives and the file is refused by name.
TEST(DicomSeries, AFileThatAbortsGdcmIsRefusedAndTheProcessLives) {
  ScratchDir dir;
  std::ifstream in(dataPath("dcmqi_ct3slice/liver.dcm"), std::ios::binary);
  std::vector<char> bytes((std::istreambuf_iterator<char>(in)), {});
  ASSERT_GT(bytes.size(), 402u);
  bytes.resize(402);
  bytes.insert(bytes.end(), 11, '\0');
  std::ofstream(dir.file("broken.dcm"), std::ios::binary)
      .write(bytes.data(), std::streamsize(bytes.size()));
  try {
    readVolume(dir.path().string());
    FAIL() << "the broken file was read";
  } catch (const Error& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("broken.dcm: corrupt DICOM"), std::string::npos) << msg;
    EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
  }
}

// Regression (a FuzzDicom campaign): liver.dcm relabelled explicit big endian, two bytes inserted
// before (0008,0030) and cut to 4,706 bytes. The screen walks it big endian and finds nothing
// wrong; GDCM falls back to other readings of the data set, takes "30 00 54 4D" as a 32-bit
// length and allocates and zero-fills 1.3 GB (4 s). The child's memory cap refuses it.
TEST(DicomSeries, AFileThatMakesGdcmAllocateGigabytesIsRefused) {
  ScratchDir dir;
  std::ifstream in(dataPath("dcmqi_ct3slice/liver.dcm"), std::ios::binary);
  std::string bytes((std::istreambuf_iterator<char>(in)), {});
  const std::string syntax("1.2.840.10008.1.2.1\0", 20);
  const auto ts = bytes.find(syntax);
  ASSERT_NE(ts, std::string::npos);
  bytes[ts + 18] = '2';  // explicit VR big endian
  const auto studyTime = bytes.find(std::string("\x08\x00\x30\x00TM", 6));
  ASSERT_NE(studyTime, std::string::npos);
  bytes.insert(studyTime, std::string("\x01\x00", 2));
  bytes.resize(4706);
  std::ofstream(dir.file("big.dcm"), std::ios::binary) << bytes;
  // The file is (was) a SEG, which readVolume gives DCMTK: refused there in one line too.
  try {
    readVolume(dir.path().string());
    FAIL() << "the file was read";
  } catch (const Error& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("big.dcm: "), std::string::npos) << msg;
    EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
  }
  // GDCM's guard, as a series folder meets it.
  try {
    readDicomSeries(dir.path().string());
    FAIL() << "the file was read";
  } catch (const Error& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("big.dcm: corrupt DICOM: the DICOM library (GDCM) "), std::string::npos)
        << msg;
    if (!kAddressSanitizer) {  // whose allocator aborts the child instead ("crashed")
      EXPECT_NE(msg.find("needed more than 512 MB to read it"), std::string::npos) << msg;
    }
    EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
  }
}
