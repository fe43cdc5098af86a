// A frame made slab by slab into its folder (poseFrameToFolder, issue 56) against the frame made
// whole and written (poseFrame, writePosedFrame): the same files byte for byte (the posed maps as
// NIfTI and as Slicer segmentations, their colour tables, the posed image, the transform) and the
// same report, for slabs of one slice (every label border, pocket and bone crosses a slab
// border; the rounding's candidates all on disk) and of several; through runPoseFrame when the
// memory budget is too small for the frame; DICOM SEG written in pieces as well, and refused in
// one line before the work when its frames would pass DICOM's 4 GiB.
#include "pose/PoseFrameSteps.h"
#include "TestDicomSeg.h"
#include "TestPaths.h"
#include "TestPoses.h"
#include "TestVolumes.h"

#include "repose/io/DicomSegIO.h"
#include "repose/io/VolumeIO.h"
#include "repose/phantom/Phantom.h"
#include "repose/pose/PoseJob.h"
#include "repose/pose/PoseRun.h"
#include "repose/util/Error.h"
#include "repose/util/Memory.h"
#include "repose/volume/TissueTable.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <memory>
#include <set>

#include <unistd.h>

using namespace repose;
using namespace repose::test;
namespace fs = std::filesystem;

namespace {

// The phantom at 8 mm with its synthetic CT, rigged for one pose of the suite.
struct Body {
  Volume organs, parts, image;
  TissueTable tissues;
  std::unique_ptr<PoseJob> job;
  std::unique_ptr<PoseRig> rig;

  explicit Body(const std::string& pose) {
    PhantomOptions o;
    o.voxelMm = 8;
    const Phantom phantom(o);
    std::tie(organs, parts) = phantom.makeVolumes();
    image = syntheticCT(organs);
    PoseJobRequest request;
    request.organsName = "G.nii.gz";
    request.tissues =
        readTissueTable(std::string(REPOSE_SOURCE_DIR) + "/Resources/Tissues/phantom.csv");
    request.tissuesName = "phantom.csv";
    request.skeleton = phantom.skeleton();
    request.settings.cageVertices = 200;
    request.settings.threads = 2;
    job = std::make_unique<PoseJob>(readPoseFile(suitePosePath(pose)), organs, parts,
                                    std::move(request));
    rig = job->makeRig(job->buildGeometry(), 2);
  }
};

std::string bytes(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  EXPECT_TRUE(in.good()) << path;
  return std::string(std::istreambuf_iterator<char>(in), {});
}

nlohmann::json report(const fs::path& folder) {
  nlohmann::json r = nlohmann::json::parse(bytes(folder / "report.json"));
  r.erase("streamed");
  return r;
}

struct Scratch {
  fs::path dir =
      fs::temp_directory_path() / ("repose-test-PoseFrameStream-" + std::to_string(::getpid()));
  Scratch() { fs::create_directories(dir); }
  ~Scratch() {
    std::error_code ec;
    fs::remove_all(dir, ec);
  }
};

// Every file of the whole frame's folder is in the streamed one, byte for byte; report.json
// holds the same figures.
void expectSameFolder(const fs::path& whole, const fs::path& streamed, const std::string& at) {
  std::size_t files = 0;
  for (const auto& entry : fs::directory_iterator(whole)) {
    const std::string name = entry.path().filename().string();
    ASSERT_TRUE(fs::exists(streamed / name)) << at << ": " << name;
    ++files;
    if (name == "report.json") continue;
    if (name.size() > 4 && name.substr(name.size() - 4) == ".dcm") {
      // New UIDs and dates each time: the frames and the voxels are the same.
      EXPECT_TRUE(segFramesOf(entry.path().string()) == segFramesOf((streamed / name).string()))
          << at << ": " << name;
      EXPECT_TRUE(
          sameVoxels(readVolume(entry.path().string()), readVolume((streamed / name).string())))
          << at << ": " << name;
      continue;
    }
    if (name.size() > 5 && name.substr(name.size() - 5) == ".ctbl") {
      // The first line names the file it was written as: the rest is the table.
      const std::string a = bytes(entry.path()), b = bytes(streamed / name);
      EXPECT_EQ(a.substr(a.find('\n')), b.substr(b.find('\n'))) << at << ": " << name;
      continue;
    }
    EXPECT_TRUE(bytes(entry.path()) == bytes(streamed / name)) << at << ": " << name;
  }
  EXPECT_EQ(std::size_t(std::distance(fs::directory_iterator(streamed), {})), files) << at;
  EXPECT_EQ(report(streamed).dump(2), report(whole).dump(2)) << at;
  const nlohmann::json r = nlohmann::json::parse(bytes(streamed / "report.json"));
  EXPECT_TRUE(r.contains("streamed")) << at;
}

}  // namespace

TEST(PoseFrameStream, SlabsWriteTheWholeFramesFilesAndReport) {
  Scratch scratch;
  std::int64_t filled = 0;
  for (const char* pose : {"elbow90", "sitting"}) {
    const Body b(pose);
    PoseFrameOptions options = b.job->frameOptions();
    options.image = &b.image;
    options.spacingMm = 3;  // more slices than the input: slabs cut the body finely
    FrameWriteOptions write;
    write.labelMapFiles = LabelMapFiles::Both;
    const std::size_t last = b.rig->frameCount() - 1;
    const PosedFrame frame = poseFrame(*b.rig, last, b.organs, b.parts, options);
    const fs::path whole = scratch.dir / (std::string(pose) + "_whole");
    writePosedFrame(frame, whole.string(), write);
    // The frame does something worth checking: soft labels rounded, bones, a report.
    const nlohmann::json r = report(whole);
    ASSERT_GT(r["label_volumes"]["relabelled_voxels"].get<std::int64_t>(), 0) << pose;
    ASSERT_FALSE(r["rigid_tissues"].empty()) << pose;
    filled += r["pockets"]["filled_voxels"].get<std::int64_t>();
    const std::int64_t nz = frame.grid.dims[2];
    for (const std::int64_t slices : {std::int64_t(1), std::int64_t(7)}) {
      const fs::path streamed =
          scratch.dir / (std::string(pose) + "_streamed_" + std::to_string(slices));
      const std::string written = poseFrameToFolder(*b.rig, last, b.organs, b.parts, options,
                                                    streamed.string(), write, 0, slices);
      const nlohmann::json s = nlohmann::json::parse(written);
      const std::int64_t slabs = s["streamed"]["slabs"].get<std::int64_t>();
      EXPECT_EQ(slabs, (nz + slices - 1) / slices) << pose;
      expectSameFolder(whole, streamed,
                       std::string(pose) + ", " + std::to_string(slabs) + " slabs");
    }
  }
  // Pockets were filled (across slab borders, with slabs of a slice).
  EXPECT_GT(filled, 0);
}

TEST(PoseFrameStream, RunPoseFrameStreamsAFrameBeyondItsBudgetAsDicomSegToo) {
  Scratch scratch;
  const Body b("elbow90");
  FrameRun run;
  run.spacingMm = 4;
  run.folder = (scratch.dir / "whole").string();
  const FrameOutcome whole = runPoseFrame(*b.job, *b.rig, 0, b.organs, b.parts, run);
  EXPECT_FALSE(whole.streamed);
  // A budget the posed volumes do not fit (half of what they need beside what is held now):
  // refused without outOfCore, streamed with it.
  run.memoryBudget = residentBytes() + 0.5 * double(whole.frame.grid.numVoxels()) *
                                           posedBytesPerVoxel(b.organs, b.parts, nullptr);
  run.folder = (scratch.dir / "refused").string();
  EXPECT_THROW(runPoseFrame(*b.job, *b.rig, 0, b.organs, b.parts, run), Error);
  EXPECT_FALSE(fs::exists(run.folder));
  run.outOfCore = true;
  run.folder = (scratch.dir / "streamed").string();
  VolumeGeometry seen;
  run.onGrid = [&](const VolumeGeometry& grid) { seen = grid; };
  const FrameOutcome streamed = runPoseFrame(*b.job, *b.rig, 0, b.organs, b.parts, run);
  EXPECT_TRUE(streamed.streamed);
  EXPECT_EQ(streamed.frame.organs.numVoxels(), 0);
  EXPECT_EQ(seen.dims, whole.frame.grid.dims);
  EXPECT_EQ(streamed.targetsMet, whole.targetsMet);
  expectSameFolder(scratch.dir / "whole", scratch.dir / "streamed", "runPoseFrame");
  // The job completed the report (its rig and inputs) on both paths.
  EXPECT_TRUE(report(scratch.dir / "streamed").contains("scene_reused"));
  EXPECT_TRUE(report(scratch.dir / "streamed").contains("rhythms"));
  // DICOM SEG: written in pieces too, the whole frame's frames and voxels.
  run.labelMapFiles = LabelMapFiles::DicomSeg;
  run.folder = (scratch.dir / "dicom").string();
  EXPECT_TRUE(runPoseFrame(*b.job, *b.rig, 0, b.organs, b.parts, run).streamed);
  run.outOfCore = false;
  run.memoryBudget = 0;
  run.folder = (scratch.dir / "dicom_whole").string();
  EXPECT_FALSE(runPoseFrame(*b.job, *b.rig, 0, b.organs, b.parts, run).streamed);
  expectSameFolder(scratch.dir / "dicom_whole", scratch.dir / "dicom", "DICOM SEG");
  EXPECT_EQ(dciodvfyErrors((scratch.dir / "dicom" / "posed_G.dcm").string()), "");
}

TEST(PoseFrameStream, ADicomSegBeyondFourGiBIsSaidBeforeTheWorkAndTheEstimateBoundsTheFrames) {
  Scratch scratch;
  for (const char* pose : {"elbow90", "sitting", "arms_up160", "walk"}) {
    const Body b(pose);
    PoseFrameOptions options = b.job->frameOptions();
    options.spacingMm = 3;
    FrameWriteOptions write;
    write.labelMapFiles = LabelMapFiles::DicomSeg;
    // The first frame and the last (one when the pose has no keyframes).
    for (const std::size_t index : std::set<std::size_t>{0, b.rig->frameCount() - 1}) {
      const fs::path folder = scratch.dir / (std::string(pose) + std::to_string(index));
      poseFrameToFolder(*b.rig, index, b.organs, b.parts, options, folder.string(), write);
      const frame::FrameStart start = frame::startFrame(*b.rig, index, b.organs, b.parts, options);
      for (const auto& [map, name] :
           {std::pair{&b.organs, "posed_G.dcm"}, {&b.parts, "posed_S.dcm"}}) {
        const std::string frames = segFramesOf((folder / name).string());
        const std::int64_t written = std::stoll(frames.substr(0, frames.find(' ')));
        const std::int64_t estimate =
            frame::dicomSegFramesEstimate(start, b.rig->mesh(), *map, b.parts);
        // An upper bound, within twice what is written: on this coarse body (8 mm voxels, tets
        // of several slices, a shell of 16 mm) 1.3 to 1.9 times.
        EXPECT_GE(estimate, written) << pose << " " << index << " " << name;
        EXPECT_LE(double(estimate), 2 * double(written)) << pose << " " << index << " " << name;
        std::printf("%s frame %zu %s: %lld frames written, %lld estimated\n", pose, index, name,
                    static_cast<long long>(written), static_cast<long long>(estimate));
        // The report says it, beside the limit.
        const nlohmann::json said =
            nlohmann::json::parse(bytes(folder / "report.json"))["dicom_seg"];
        EXPECT_EQ(said[name]["frames_bound"].get<std::int64_t>(), estimate) << name;
        EXPECT_EQ(said["pixel_data_limit_bytes"].get<std::int64_t>(), kDicomSegPixelDataBytes);
      }
    }
  }
  // On a grid of 0.25 mm, the frames pass 4 GiB: one line naming the file, before the work, and
  // nothing written, in core and slab by slab alike.
  const Body b("elbow90");
  FrameRun run;
  run.spacingMm = 0.25;
  run.labelMapFiles = LabelMapFiles::DicomSeg;
  run.memoryBudget = 1e15;
  for (const bool outOfCore : {false, true}) {
    run.alwaysOutOfCore = outOfCore;
    run.folder = (scratch.dir / ("huge" + std::to_string(outOfCore))).string();
    try {
      runPoseFrame(*b.job, *b.rig, 0, b.organs, b.parts, run);
      ADD_FAILURE() << "a DICOM SEG beyond 4 GiB was written";
    } catch (const Error& e) {
      const std::string message = e.what();
      EXPECT_NE(message.find(run.folder + "/posed_G.dcm: "), std::string::npos) << message;
      EXPECT_NE(message.find("4 GiB"), std::string::npos) << message;
      EXPECT_EQ(message.find('\n'), std::string::npos) << message;
    }
    EXPECT_FALSE(fs::exists(run.folder));
  }
}
