// `repose info` and `repose convert` as a user runs them: JSON contents, conversion chains that
// keep voxels and geometry, and failures that print one line and leave nothing behind.
#include "CommandRunner.h"
#include "TestPaths.h"

#include "repose/io/VolumeIO.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cstring>
#include <filesystem>

using namespace repose;
using namespace repose::test;

namespace {

std::string fileDigest(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::string bytes((std::istreambuf_iterator<char>(in)), {});
  return std::to_string(bytes.size()) + ":" + std::to_string(std::hash<std::string>{}(bytes));
}

void expectCleanFailure(const CommandResult& r) {
  EXPECT_NE(r.exitCode, 0);
  EXPECT_EQ(lineCount(r.err), 1) << r.err;
  EXPECT_TRUE(r.out.empty()) << r.out;
}

}  // namespace

TEST(InfoCommand, JsonListsLiverWithItsVoxelCount) {
  const std::string seg = dataPath("totalsegmentator/example_seg.nii.gz");
  const CommandResult r = runCommand("repose", "info " + shellQuote(seg) + " --json");
  ASSERT_EQ(r.exitCode, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["labels_present"], 41);
  EXPECT_EQ(j["orientation"].get<std::string>().size(), 3u);
  EXPECT_EQ(j["scalar_type"], "uint8");
  bool liver = false;
  for (const auto& l : j["labels"])
    if (l["value"] == 5) {
      EXPECT_EQ(l["name"], "liver");
      EXPECT_GT(l["voxels"].get<long>(), 1000);
      // volume_ml = voxels x 27 mm^3 / 1000 on this 3 mm grid
      EXPECT_NEAR(l["volume_ml"].get<double>(), l["voxels"].get<long>() * 0.027, 1e-3);
      liver = true;
    }
  EXPECT_TRUE(liver);
}

TEST(InfoCommand, TextOutputForImagesAndSegmentations) {
  const CommandResult ct =
      runCommand("repose", "info " + shellQuote(dataPath("slicer_seg/CTChest4.nrrd")));
  ASSERT_EQ(ct.exitCode, 0) << ct.err;
  // Stored in LPS with negative x and y steps: the voxel axes point to R, A, S.
  EXPECT_NE(ct.out.find("orientation  RAS"), std::string::npos) << ct.out;
  EXPECT_NE(ct.out.find("(image)"), std::string::npos);
  const CommandResult seg = runCommand(
      "repose", "info " + shellQuote(dataPath("slicer_seg/SegmentationOverlapping.seg.nrrd")));
  ASSERT_EQ(seg.exitCode, 0) << seg.err;
  EXPECT_NE(seg.out.find("overlapping sphere"), std::string::npos) << seg.out;
  EXPECT_NE(seg.out.find("2 layers"), std::string::npos) << seg.out;
}

TEST(ConvertCommand, NiftiToSegNrrdToNiftiKeepsVoxelsGeometryAndNames) {
  ScratchDir dir;
  const std::string in = dataPath("totalsegmentator/example_seg.nii.gz");
  const std::string digest = fileDigest(in);
  const std::string seg = dir.file("seg.seg.nrrd"), back = dir.file("back.nii.gz");
  ASSERT_EQ(runCommand("repose", "convert " + shellQuote(in) + " " + shellQuote(seg)).exitCode, 0);
  const CommandResult r =
      runCommand("repose", "convert " + shellQuote(seg) + " " + shellQuote(back) + " --json");
  ASSERT_EQ(r.exitCode, 0) << r.err;
  EXPECT_EQ(nlohmann::json::parse(r.out)["labels_present"], 41);
  const Volume a = readVolume(in), b = readVolume(back), s = readVolume(seg);
  EXPECT_EQ(a.bytes(), b.bytes());
  EXPECT_EQ(a.bytes(), s.bytes());
  EXPECT_LT((a.geometry().ijkToRas - b.geometry().ijkToRas).cwiseAbs().maxCoeff(), 1e-4);
  EXPECT_LT((a.geometry().ijkToRas - s.geometry().ijkToRas).cwiseAbs().maxCoeff(), 1e-4);
  ASSERT_NE(b.labels().find(5), nullptr);
  EXPECT_EQ(b.labels().find(5)->name, "liver");
  EXPECT_EQ(fileDigest(in), digest);  // the input is never modified
}

TEST(ConvertCommand, DicomSeriesToNifti) {
  ScratchDir dir;
  const std::string out = dir.file("ct.nii.gz");
  const CommandResult r =
      runCommand("repose", "convert " + shellQuote(dataPath("dcmqi_ct3slice/ct-3slice")) + " " +
                               shellQuote(out));
  ASSERT_EQ(r.exitCode, 0) << r.err;
  const Volume ct = readVolume(out);
  EXPECT_EQ(ct.dims(), (std::array<std::int64_t, 3>{512, 512, 3}));
  EXPECT_FALSE(ct.isLabelMap());
}

TEST(ConvertCommand, DicomSegAndRtStructInAndDicomSegOut) {
  ScratchDir dir;
  // A SEG to NIfTI, then the NIfTI back to a SEG with the SEG's patient and study.
  const std::string seg = dataPath("dcmqi_ct3slice/liver.dcm");
  const CommandResult in = runCommand(
      "repose", "convert " + shellQuote(seg) + " " + shellQuote(dir.file("liver.nii.gz")));
  ASSERT_EQ(in.exitCode, 0) << in.err;
  EXPECT_NE(in.err.find("repose: note: " + seg + ": placed on the grid of its referenced series"),
            std::string::npos)
      << in.err;
  const CommandResult out =
      runCommand("repose", "convert " + shellQuote(seg) + " " + shellQuote(dir.file("again.dcm")));
  ASSERT_EQ(out.exitCode, 0) << out.err;
  const Volume a = readVolume(dir.file("liver.nii.gz")), b = readVolume(dir.file("again.dcm"));
  ASSERT_EQ(a.dims(), b.dims());
  EXPECT_EQ(std::memcmp(a.layerData(), b.layerData(), a.byteSize()), 0);
  EXPECT_EQ(b.labels().find(1)->name, "Liver");

  // An RT Structure Set needs a grid; with one, its ROIs come out as layered labels.
  const std::string rtss = dataPath("dicompyler_rt/rtss.dcm");
  const CommandResult noGrid = runCommand(
      "repose", "convert " + shellQuote(rtss) + " " + shellQuote(dir.file("rs.seg.nrrd")));
  EXPECT_EQ(noGrid.exitCode, 2);
  EXPECT_NE(noGrid.err.find("give its grid with --reference IMAGE or --spacing-mm MM"),
            std::string::npos)
      << noGrid.err;
  const CommandResult notContours =
      runCommand("repose", "convert " + shellQuote(seg) + " " + shellQuote(dir.file("x.nii.gz")) +
                               " --spacing-mm 2");
  EXPECT_EQ(notContours.exitCode, 2);
  const CommandResult rs =
      runCommand("repose", "convert " + shellQuote(rtss) + " " +
                               shellQuote(dir.file("rs.seg.nrrd")) + " --spacing-mm 4");
  ASSERT_EQ(rs.exitCode, 0) << rs.err;
  const Volume rois = readVolume(dir.file("rs.seg.nrrd"));
  EXPECT_EQ(rois.labels().size(), 10u);
  EXPECT_GT(rois.layers(), 1);
  ASSERT_TRUE(rois.labels().find(1, 0));
  EXPECT_EQ(rois.labels().find(1, 0)->name, "BODY");
  // Read as a volume, it says how to rasterize it.
  const CommandResult info = runCommand("repose", "info " + shellQuote(rtss));
  EXPECT_NE(info.err.find("rasterize it with `repose convert`"), std::string::npos) << info.err;
}

TEST(ConvertCommand, BadInputFailsWithOneLineAndNoOutput) {
  ScratchDir dir;
  const std::string out = dir.file("out.nii.gz");
  expectCleanFailure(runCommand(
      "repose", "convert " + shellQuote(dir.file("missing.nii")) + " " + shellQuote(out)));
  {
    std::ofstream bad(dir.file("bad.nrrd"));
    bad << "NRRD0004\ntype: short\ndimension: 3\nsizes: 100 100 100\nencoding: raw\n\n0123456789";
  }
  const CommandResult sizeMismatch =
      runCommand("repose", "convert " + shellQuote(dir.file("bad.nrrd")) + " " + shellQuote(out));
  expectCleanFailure(sizeMismatch);
  EXPECT_NE(sizeMismatch.err.find("bad.nrrd"), std::string::npos) << sizeMismatch.err;
  const std::string in = dataPath("slicer_seg/Segmentation.seg.nrrd");
  expectCleanFailure(
      runCommand("repose", "convert " + shellQuote(in) + " " + shellQuote(dir.file("x.png"))));
  expectCleanFailure(runCommand(
      "repose", "convert " + shellQuote(in) + " " + shellQuote(dir.file("no/dir/x.nii"))));
  expectCleanFailure(runCommand("repose", "convert " + shellQuote(in) + " /dev/null/x.nii"));
  EXPECT_FALSE(std::filesystem::exists(out));
  for (const auto& e : std::filesystem::directory_iterator(dir.path()))
    EXPECT_EQ(e.path().filename(), "bad.nrrd") << "left behind: " << e.path();
}

TEST(ConvertCommand, RefusesToOverwriteItsInput) {
  ScratchDir dir;
  const std::string copy = dir.file("seg.nii.gz");
  std::filesystem::copy_file(dataPath("totalsegmentator/example_seg.nii.gz"), copy);
  const std::string digest = fileDigest(copy);
  const CommandResult r =
      runCommand("repose", "convert " + shellQuote(copy) + " " + shellQuote(copy));
  expectCleanFailure(r);
  EXPECT_NE(r.err.find("overwrite"), std::string::npos) << r.err;
  EXPECT_EQ(fileDigest(copy), digest);
}

TEST(Cli, HelpAndUsageErrors) {
  for (const char* cmd : {"info", "convert", "phantom"}) {
    const CommandResult h = runCommand("repose", std::string(cmd) + " --help");
    EXPECT_EQ(h.exitCode, 0) << cmd;
    EXPECT_NE(h.out.find("usage: repose"), std::string::npos) << cmd;
  }
  expectCleanFailure(runCommand("repose", "info"));
  expectCleanFailure(runCommand("repose", "info --bogus x"));
  expectCleanFailure(runCommand("repose", "frobnicate"));
}
