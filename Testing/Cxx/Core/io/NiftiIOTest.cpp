// NIfTI reading and writing: round trips of every type and geometry, the real TotalSegmentator
// files (sform, label extension), NIfTI-2, and bad input.
#include "TestPaths.h"
#include "TestVolumes.h"

#include "repose/io/NiftiIO.h"
#include "repose/io/VolumeIO.h"
#include "repose/volume/LabelStatistics.h"

#include <gtest/gtest.h>

#include <fstream>
#include <zlib.h>

using namespace repose;
using namespace repose::test;

TEST(NiftiIO, RoundTripsEveryScalarTypeAndObliqueGeometry) {
  ScratchDir dir;
  int seed = 1;
  for (ScalarType t : {ScalarType::UInt8, ScalarType::UInt16, ScalarType::Int16, ScalarType::Int32,
                       ScalarType::Float32}) {
    for (const char* ext : {".nii", ".nii.gz"}) {
      Volume v = randomVolume(t, obliqueGeometry(), 40, seed++);
      v.setLabelMap(t != ScalarType::Float32);
      const std::string path = dir.file(std::string("v_") + scalarTypeName(t) + ext);
      writeVolume(v, path);
      const Volume r = readVolume(path);
      // The .nii written just before holds other voxels: reading X.nii.gz must not pick X.nii.
      EXPECT_TRUE(sameVoxels(v, r)) << path;
      // NIfTI-1 stores the sform in float32: 1e-4 mm is the promise, ~1e-7 the reality.
      EXPECT_LT(matrixDifference(v.geometry().ijkToRas, r.geometry().ijkToRas), 1e-4) << path;
      EXPECT_EQ(r.isLabelMap(), v.isLabelMap()) << path;
    }
  }
}

TEST(NiftiIO, LabelNamesAndColoursSurviveARoundTrip) {
  ScratchDir dir;
  Volume v = randomVolume(ScalarType::UInt16, obliqueGeometry(), 300, 7);
  v.setLabelMap(true);
  auto label = [](int value, const std::string& name, std::array<double, 3> color) {
    Label l;
    l.value = value, l.name = name, l.color = color;
    return l;
  };
  v.labels().set(label(5, "liver", {0.1, 0.2, 0.3}));
  v.labels().set(label(299, "left & right <kidney>", {1, 0, 0.5}));
  writeVolume(v, dir.file("labels.nii.gz"));
  const Volume r = readVolume(dir.file("labels.nii.gz"));
  ASSERT_NE(r.labels().find(5), nullptr);
  EXPECT_EQ(r.labels().find(5)->name, "liver");
  EXPECT_NEAR(r.labels().find(5)->color[2], 0.3, 1e-6);
  ASSERT_NE(r.labels().find(299), nullptr);
  EXPECT_EQ(r.labels().find(299)->name, "left & right <kidney>");
}

TEST(NiftiIO, Nifti2RoundTripsAndIsReallyVersion2) {
  ScratchDir dir;
  Volume v = randomVolume(ScalarType::Int16, obliqueGeometry(), 100, 3);
  WriteOptions o;
  o.niftiVersion = 2;
  writeVolume(v, dir.file("v2.nii"), o);
  std::ifstream in(dir.file("v2.nii"), std::ios::binary);
  std::int32_t sizeofHdr = 0;
  in.read(reinterpret_cast<char*>(&sizeofHdr), 4);
  EXPECT_EQ(sizeofHdr, 540);  // NIfTI-2 header size (NIfTI-1 is 348)
  const Volume r = readVolume(dir.file("v2.nii"));
  EXPECT_TRUE(sameVoxels(v, r));
  EXPECT_LT(matrixDifference(v.geometry().ijkToRas, r.geometry().ijkToRas), 1e-9);
}

TEST(NiftiIO, ReadsTotalSegmentatorSegmentationWithItsLabelExtension) {
  const Volume seg = readVolume(dataPath("totalsegmentator/example_seg.nii.gz"));
  EXPECT_EQ(seg.dims(), (std::array<std::int64_t, 3>{122, 101, 30}));
  EXPECT_EQ(seg.scalarType(), ScalarType::UInt8);
  EXPECT_TRUE(seg.isLabelMap());
  ASSERT_NE(seg.labels().find(5), nullptr);
  EXPECT_EQ(seg.labels().find(5)->name, "liver");
  EXPECT_EQ(countLabels(seg).size(), 41u);  // the README: 41 labels present
  EXPECT_LT((seg.geometry().spacing() - Eigen::Vector3d(3, 3, 3)).norm(), 1e-4);
  // Every name agrees with the label table shipped as TSV.
  std::ifstream tsv(dataPath("totalsegmentator/example_seg_labels.tsv"));
  std::string line;
  std::getline(tsv, line);
  int checked = 0;
  while (std::getline(tsv, line)) {
    std::istringstream fields(line);
    int value;
    std::string name;
    fields >> value >> name;
    ASSERT_NE(seg.labels().find(value), nullptr) << value;
    EXPECT_EQ(seg.labels().find(value)->name, name);
    ++checked;
  }
  EXPECT_GE(checked, 41);
}

TEST(NiftiIO, CtAndSegmentationShareTheirGrid) {
  const Volume ct = readVolume(dataPath("totalsegmentator/example_ct_sm.nii.gz"));
  const Volume seg = readVolume(dataPath("totalsegmentator/example_seg.nii.gz"));
  EXPECT_EQ(ct.scalarType(), ScalarType::Int16);
  EXPECT_FALSE(ct.isLabelMap());
  EXPECT_EQ(ct.dims(), seg.dims());
  EXPECT_LT(matrixDifference(ct.geometry().ijkToRas, seg.geometry().ijkToRas), 1e-4);
  // Anatomy check of orientation: the liver (5) sits on the patient's right, so at larger RAS x
  // than the spleen (1).
  auto centroidX = [&](int label) {
    double sum = 0;
    std::int64_t n = 0;
    const auto* d = seg.data<std::uint8_t>();
    for (std::int64_t k = 0; k < seg.dims()[2]; ++k)
      for (std::int64_t j = 0; j < seg.dims()[1]; ++j)
        for (std::int64_t i = 0; i < seg.dims()[0]; ++i)
          if (d[seg.index(i, j, k)] == label) sum += seg.geometry().voxelToRas(i, j, k).x(), ++n;
    return sum / n;
  };
  EXPECT_GT(centroidX(5), centroidX(1));
}

TEST(NiftiIO, MrWithNegativeSformAxes) {
  const Volume mr = readVolume(dataPath("totalsegmentator/example_mr_sm.nii.gz"));
  const Volume seg = readVolume(dataPath("totalsegmentator/example_seg_mr.nii.gz"));
  EXPECT_EQ(mr.dims(), (std::array<std::int64_t, 3>{117, 91, 20}));
  EXPECT_EQ(mr.dims(), seg.dims());
  EXPECT_LT(matrixDifference(mr.geometry().ijkToRas, seg.geometry().ijkToRas), 1e-4);
  EXPECT_LT(mr.geometry().ijkToRas(0, 0), 0);  // "sform with negative x/y"
  EXPECT_TRUE(seg.isLabelMap());
}

namespace {

void writeAll(const std::string& path, const std::vector<char>& bytes) {
  std::ofstream(path, std::ios::binary).write(bytes.data(), bytes.size());
}
std::vector<char> gunzip(const std::string& path) {
  gzFile f = gzopen(path.c_str(), "rb");
  std::vector<char> out, buf(1 << 16);
  int n;
  while ((n = gzread(f, buf.data(), buf.size())) > 0)
    out.insert(out.end(), buf.begin(), buf.begin() + n);
  gzclose(f);
  return out;
}

void expectOneLineError(const std::string& path, const std::string& fragment) {
  try {
    readVolume(path);
    FAIL() << "no error for " << path;
  } catch (const Error& e) {
    const std::string msg = e.what();
    EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
    EXPECT_NE(msg.find(path), std::string::npos) << msg;
    EXPECT_NE(msg.find(fragment), std::string::npos) << msg;
  }
}

}  // namespace

TEST(NiftiIO, BadInputGivesOneLineErrors) {
  ScratchDir dir;
  const std::vector<char> good = gunzip(dataPath("totalsegmentator/example_seg.nii.gz"));
  ASSERT_GT(good.size(), 13168u);
  writeAll(dir.file("truncated_header.nii"), std::vector<char>(good.begin(), good.begin() + 200));
  expectOneLineError(dir.file("truncated_header.nii"), "NIfTI");
  writeAll(dir.file("truncated_data.nii"), std::vector<char>(good.begin(), good.end() - 5000));
  expectOneLineError(dir.file("truncated_data.nii"), "truncated");
  std::vector<char> corrupt = good;
  std::fill(corrupt.begin(), corrupt.begin() + 348, '\x5a');
  writeAll(dir.file("corrupt.nii"), corrupt);
  expectOneLineError(dir.file("corrupt.nii"), "NIfTI");
  std::vector<char> complexType = good;
  const std::int16_t dtComplex = 32;  // DT_COMPLEX64
  std::memcpy(&complexType[70], &dtComplex, 2);
  const std::int16_t bitpix = 64;
  std::memcpy(&complexType[72], &bitpix, 2);
  writeAll(dir.file("complex.nii"), complexType);
  expectOneLineError(dir.file("complex.nii"), "unsupported");
  std::vector<char> fourD = good;
  const std::int16_t dims[5] = {4, 122, 101, 30, 2};
  std::memcpy(&fourD[40], dims, sizeof(dims));
  writeAll(dir.file("fourd.nii"), fourD);
  expectOneLineError(dir.file("fourd.nii"), "4D");
  // Regression (Testing/Fuzz/FuzzNifti): a big-endian header without magic whose vox_offset is
  // -1.7e38 passed the truncation check, and the 350-byte file allocated 1024^3 voxels. Now
  // refused from the header, before the memory budget is even asked.
  std::vector<char> negativeOffset(350, 0);
  negativeOffset[0] = '\x5c', negativeOffset[1] = '\x01';  // sizeof_hdr as the fuzzer left it
  auto putBigEndian = [&](std::size_t at, const void* value, std::size_t bytes) {
    for (std::size_t i = 0; i < bytes; ++i)
      negativeOffset[at + i] = static_cast<const char*>(value)[bytes - 1 - i];
  };
  const std::int16_t bigDims[4] = {3, 1024, 1024, 1024}, type[2] = {256, 8};  // DT_INT8
  for (int i = 0; i < 4; ++i) putBigEndian(40 + 2 * std::size_t(i), &bigDims[i], 2);
  putBigEndian(70, &type[0], 2);
  putBigEndian(72, &type[1], 2);
  const float offset = -1.7e38f;
  putBigEndian(108, &offset, 4);
  writeAll(dir.file("negative_offset.nii"), negativeOffset);
  expectOneLineError(dir.file("negative_offset.nii"), "vox_offset");
  ReadOptions small;
  small.memoryLimitBytes = 1e6;
  try {
    (void)readVolume(dir.file("negative_offset.nii"), small);
    ADD_FAILURE() << "read";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("vox_offset"), std::string::npos) << e.what();
  }
  expectOneLineError(dir.file("missing.nii.gz"), "not found");
  writeAll(dir.file("empty.nii"), {});
  expectOneLineError(dir.file("empty.nii"), "empty");
}

// Regression (Testing/Fuzz/FuzzNifti): a .nii.gz whose compressed voxel data ends early made
// niftilib free() the volume's own buffer (allocated with new) and the volume free it again.
TEST(NiftiIO, TruncatedGzipVoxelDataIsAnErrorNotACrash) {
  ScratchDir dir;
  std::ifstream in(dataPath("totalsegmentator/example_seg.nii.gz"), std::ios::binary);
  const std::vector<char> gz((std::istreambuf_iterator<char>(in)), {});
  ASSERT_GT(gz.size(), 20000u);
  for (const std::size_t keep : {gz.size() / 2, gz.size() - 100}) {
    const std::string path = dir.file("cut" + std::to_string(keep) + ".nii.gz");
    writeAll(path, std::vector<char>(gz.begin(), gz.begin() + std::ptrdiff_t(keep)));
    expectOneLineError(path, "voxel data");
  }
}

TEST(NiftiIO, FailedWriteLeavesNoFile) {
  ScratchDir dir;
  Volume v = randomVolume(ScalarType::UInt8, obliqueGeometry(), 5, 1);
  EXPECT_THROW(writeVolume(v, dir.file("no/such/folder/out.nii.gz")), Error);
  Volume layered = randomVolume(ScalarType::UInt8, obliqueGeometry(), 5, 1, 2);
  EXPECT_THROW(writeVolume(layered, dir.file("layered.nii.gz")), Error);
  EXPECT_TRUE(std::filesystem::is_empty(dir.path()));  // no temporary or partial file left
}

TEST(NiftiIO, SlabWriterRefusesAnIncompleteVolume) {
  ScratchDir dir;
  const VolumeGeometry g = obliqueGeometry();
  {
    NiftiSlabWriter w(dir.file("slabs.nii.gz"), g, ScalarType::UInt8, {}, true);
    std::vector<std::uint8_t> slice(g.dims[0] * g.dims[1], 3);
    w.writeSlices(slice.data(), 1);
    EXPECT_THROW(w.finish(), Error);
  }
  EXPECT_TRUE(std::filesystem::is_empty(dir.path()));
}
