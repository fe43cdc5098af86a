// The steps every front end runs through Core (pose/PoseRun.h): the one poseable rule, the
// unnamed-label line, and one frame from the rig to its files — the same voxels as the frame on
// its own, the report completed by the job and written with its outputs, the targets read back,
// the memory rule refusing before anything is allocated or written, and a cancel leaving nothing.
#include "TestPaths.h"
#include "TestPoses.h"

#include "repose/io/VolumeIO.h"
#include "repose/phantom/Phantom.h"
#include "repose/pose/PoseJob.h"
#include "repose/pose/PoseReport.h"
#include "repose/pose/PoseRun.h"
#include "repose/util/Error.h"
#include "repose/volume/TissueTable.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <memory>
#include <set>
#include <sstream>

#include <unistd.h>

using namespace repose;
using namespace repose::test;
namespace fs = std::filesystem;

namespace {

// The phantom at 8 mm, elbow90 rigged once for every test of this file. S is written to a file:
// a scene's key names S's file (its path, size and time).
struct Body {
  Volume organs, parts;
  std::string partsPath;
  std::unique_ptr<PoseJob> job;
  std::unique_ptr<PoseRig> rig;

  Body() {
    PhantomOptions o;
    o.voxelMm = 8;
    const Phantom phantom(o);
    std::tie(organs, parts) = phantom.makeVolumes();
    partsPath = (fs::temp_directory_path() /
                 ("repose-test-PoseRun-S-" + std::to_string(::getpid()) + ".nii.gz"))
                    .string();
    writeVolume(parts, partsPath);
    PoseJobRequest request;
    request.organsName = "G.nii.gz";
    request.partsPath = partsPath;
    request.tissues =
        readTissueTable(std::string(REPOSE_SOURCE_DIR) + "/Resources/Tissues/phantom.csv");
    request.tissuesName = "phantom.csv";
    request.skeleton = phantom.skeleton();
    request.settings.cageVertices = 200;
    request.settings.threads = 2;
    job = std::make_unique<PoseJob>(readPoseFile(suitePosePath("elbow90")), organs, parts,
                                    std::move(request));
    rig = job->makeRig(job->buildGeometry(), 2);
  }
  ~Body() {
    std::error_code ec;
    fs::remove(partsPath, ec);
  }
};

const Body& body() {
  static const Body b;
  return b;
}

bool sameVoxels(const Volume& a, const Volume& b) {
  if (a.dims() != b.dims() || a.scalarType() != b.scalarType()) return false;
  for (std::int64_t v = 0; v < a.numVoxels(); ++v)
    if (a.valueAsDouble(v) != b.valueAsDouble(v)) return false;
  return true;
}

nlohmann::json readJson(const fs::path& path) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  return nlohmann::json::parse(text.str());
}

}  // namespace

TEST(PoseRun, AFrameIsTheFrameOfPoseFrameCompletedByTheJobAndWritten) {
  const Body& b = body();
  ScratchDir dir;
  FrameRun run;
  run.folder = dir.file("frame");
  run.sceneReused = true;  // said in the report as given
  int grids = 0;
  VolumeGeometry seen;
  run.onGrid = [&](const VolumeGeometry& g) { ++grids, seen = g; };
  std::vector<std::string> warnings;
  run.warn = [&](const std::string& line) { warnings.push_back(line); };
  const FrameOutcome out = runPoseFrame(*b.job, *b.rig, 0, b.organs, b.parts, run);

  // The same voxels as the frame step on its own with the job's options.
  const PosedFrame alone = poseFrame(*b.rig, 0, b.organs, b.parts, b.job->frameOptions());
  EXPECT_TRUE(sameVoxels(out.frame.organs, alone.organs));
  EXPECT_TRUE(sameVoxels(out.frame.parts, alone.parts));
  EXPECT_EQ(out.frame.grid.dims, alone.grid.dims);
  // The grid was shown once, after the memory rule let it through, and it is the frame's.
  EXPECT_EQ(grids, 1);
  EXPECT_EQ(seen.dims, out.frame.grid.dims);

  // report.json on disk is the one returned, completed by the job, naming what was written.
  const nlohmann::json written = readJson(fs::path(run.folder) / "report.json");
  EXPECT_EQ(written, nlohmann::json::parse(out.reportJson));
  EXPECT_EQ(written["input"], "G.nii.gz");
  EXPECT_EQ(written["scene_reused"], true);
  EXPECT_TRUE(written.contains("separations"));
  EXPECT_TRUE(written.contains("rhythms"));
  // Every file "outputs" names (a name, or a list of names) is there.
  int named = 0;
  for (const auto& [what, files] : written["outputs"].items())
    for (const auto& file : files.is_array() ? files : nlohmann::json::array({files})) {
      EXPECT_TRUE(fs::exists(fs::path(run.folder) / file.get<std::string>())) << what;
      ++named;
    }
  EXPECT_GE(named, 5);  // G, S, their colour tables, the transform
  EXPECT_TRUE(fs::exists(fs::path(run.folder) / "posed_G.nii.gz"));
  // The targets as the report has them, and the line a front end prints.
  EXPECT_EQ(out.targetsMet, written["targets"]["met"].get<bool>());
  ASSERT_EQ(out.missed.size(), written["targets"]["missed"].size());
  std::string line;
  for (const auto& m : written["targets"]["missed"])
    line += (line.empty() ? "" : "; ") + m.get<std::string>();
  EXPECT_EQ(out.missedLine(), line);
  EXPECT_EQ(out.targetsMet, out.missed.empty());
  // Warnings reached the front end as they are in the report.
  EXPECT_EQ(warnings.size(), written["warnings"].size());

  // The cage the rig has: asked and used (200 vertices passes its checks: nothing else tried).
  EXPECT_EQ(written["cage"]["asked"]["vertices"], 200);
  EXPECT_EQ(written["cage"]["used"], written["cage"]["asked"]);
  EXPECT_EQ(written["cage"]["fallback"], false);
  ASSERT_EQ(written["cage"]["tried"].size(), 1u);
  EXPECT_TRUE(written["cage"]["tried"][0]["failed"].is_null());
  // The tets inside out, by the skeleton's joints: every one counted once, at a joint named by
  // the skeleton, and at the bent elbow if anywhere.
  std::int64_t byJoint = 0;
  for (const auto& [joint, tets] : written["mesh"]["inverted_tets_by_joint"].items()) {
    EXPECT_TRUE(std::any_of(b.job->skeleton()->joints.begin(), b.job->skeleton()->joints.end(),
                            [&](const SkeletonJoint& j) { return j.name == joint; }))
        << joint;
    EXPECT_GT(tets.get<int>(), 0) << joint;
    byJoint += tets.get<std::int64_t>();
  }
  EXPECT_EQ(byJoint, written["mesh"]["inverted_tets"].get<std::int64_t>());
  // Rigid pieces apart is a target, and agrees with the collisions it counts: each pair beyond
  // its allowance (at least a voxel) misses it.
  std::int64_t beyond = 0;
  for (const auto& pair : written["bone_collisions"]["pairs"]) {
    EXPECT_GE(pair["allowed_voxels"].get<std::int64_t>(), 1);
    EXPECT_EQ(pair["beyond_allowance"].get<bool>(),
              pair["voxels"].get<std::int64_t>() > pair["allowed_voxels"].get<std::int64_t>());
    if (pair["beyond_allowance"].get<bool>()) beyond += pair["voxels"].get<std::int64_t>();
  }
  EXPECT_EQ(beyond, written["bone_collisions"]["beyond_allowance_voxels"].get<std::int64_t>());
  EXPECT_EQ(written["quality"]["pieces_apart"]["met"], beyond == 0);
  // The rounding says whether it held, label by label, and names those of >= 1000 voxels that
  // missed.
  std::set<int> missed;
  for (const auto& l : written["label_volumes"]["rounding_missed"])
    missed.insert(l["value"].get<int>());
  int rounded = 0;
  for (const auto& row : written["labels"]) {
    if (!row.contains("rounding")) continue;
    ++rounded;
    const auto& r = row["rounding"];
    const double by = r["missed_by_percent"].get<double>();
    EXPECT_NEAR(
        by, 100 * (row["voxels_after"].get<double>() / r["target_voxels"].get<double>() - 1), 1e-9);
    EXPECT_EQ(r["held"].get<bool>(), std::fabs(by) <= r["tolerance_percent"].get<double>());
    EXPECT_EQ(row["rounded"], r["held"]);
    EXPECT_EQ(missed.count(row["value"].get<int>()) == 1,
              !r["held"].get<bool>() && row["voxels_before"].get<std::int64_t>() >= 1000)
        << row["name"];
  }
  EXPECT_GT(rounded, 3);
}

TEST(PoseRun, WithoutAFolderNothingIsWrittenAndTheReportHasNoOutputs) {
  const Body& b = body();
  FrameRun run;
  run.sceneReused = false;
  const FrameOutcome out = runPoseFrame(*b.job, *b.rig, 0, b.organs, b.parts, run);
  const nlohmann::json report = nlohmann::json::parse(out.reportJson);
  EXPECT_EQ(report["scene_reused"], false);
  EXPECT_EQ(out.reportJson, out.frame.reportJson);
  EXPECT_GT(out.frame.organs.numVoxels(), 0);
}

TEST(PoseRun, TheMemoryRuleRefusesBeforeTheGridIsUsedOrAnythingWritten) {
  const Body& b = body();
  ScratchDir dir;
  FrameRun run;
  run.folder = dir.file("refused");
  run.memoryBudget = 1024;  // a kibibyte: less than the process already holds
  run.budgetWhat = "out: frame elbow90";
  run.budgetHint = "--memory; out of core: `repose warp`";
  bool gridSeen = false;
  run.onGrid = [&](const VolumeGeometry&) { gridSeen = true; };
  try {
    runPoseFrame(*b.job, *b.rig, 0, b.organs, b.parts, run);
    FAIL() << "a frame beyond the budget was posed";
  } catch (const Cancelled&) {
    FAIL() << "refused as a cancel";
  } catch (const Error& e) {
    const std::string m = e.what();
    EXPECT_EQ(m.rfind("out: frame elbow90 needs ", 0), 0u) << m;
    EXPECT_NE(m.find("more than the memory budget of"), std::string::npos) << m;
    EXPECT_NE(m.find("(--memory; out of core: `repose warp`)"), std::string::npos) << m;
    EXPECT_EQ(m.find('\n'), std::string::npos) << m;
  }
  EXPECT_FALSE(gridSeen);
  EXPECT_FALSE(fs::exists(run.folder));
}

TEST(PoseRun, ACancelLeavesNothing) {
  const Body& b = body();
  ScratchDir dir;
  FrameRun run;
  run.folder = dir.file("cancelled");
  run.progress = [](double, const std::string&) { return false; };
  EXPECT_THROW(runPoseFrame(*b.job, *b.rig, 0, b.organs, b.parts, run), Cancelled);
  EXPECT_FALSE(fs::exists(run.folder));
}

TEST(PoseRun, AFrameBeyondThePoseIsOneLineNamingIt) {
  const Body& b = body();
  try {
    runPoseFrame(*b.job, *b.rig, b.rig->frameCount(), b.organs, b.parts, FrameRun());
    FAIL() << "a frame beyond the pose was posed";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("elbow90"), std::string::npos) << e.what();
  }
}

TEST(PoseableLabels, FloatEmptyAndSkewedMapsAreRefusedNamingThem) {
  VolumeGeometry g;
  g.dims = {4, 4, 4};
  g.ijkToRas = Eigen::Matrix4d::Identity();
  Volume labels(g, ScalarType::UInt8);
  labels.setLabelMap(true);
  auto refusal = [](const Volume& v) {
    try {
      requirePoseableLabels(v, "S.nii.gz");
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  // Every voxel 0: no body.
  EXPECT_NE(refusal(labels).find("S.nii.gz"), std::string::npos);
  EXPECT_NE(refusal(labels).find("empty"), std::string::npos);
  labels.data<std::uint8_t>()[21] = 3;
  EXPECT_EQ(refusal(labels), "");
  // Float voxels are an image, not labels.
  Volume image(g, ScalarType::Float32);
  image.data<float>()[21] = 3;
  EXPECT_NE(refusal(image).find("not a label map"), std::string::npos);
  // An integer image its reader did not take for labels: a CT's negative Hounsfield units, or
  // more distinct values than a label set holds. The same values flagged as labels pass.
  Volume ct(g, ScalarType::Int16);
  for (std::int64_t v = 0; v < ct.numVoxels(); ++v) ct.data<std::int16_t>()[v] = -1000;
  ct.data<std::int16_t>()[21] = 40;
  EXPECT_NE(refusal(ct).find("values below 0"), std::string::npos) << refusal(ct);
  ct.setLabelMap(true);
  EXPECT_EQ(refusal(ct), "");
  VolumeGeometry large = g;
  large.dims = {80, 80, 1};
  Volume mr(large, ScalarType::UInt16);
  for (std::int64_t v = 0; v < mr.numVoxels(); ++v) mr.data<std::uint16_t>()[v] = std::uint16_t(v);
  EXPECT_NE(refusal(mr).find("6399 distinct values"), std::string::npos) << refusal(mr);
  // Voxel axes that are not orthogonal.
  VolumeGeometry skew = g;
  skew.ijkToRas(0, 1) = 0.5;
  Volume skewed(skew, ScalarType::UInt8);
  skewed.data<std::uint8_t>()[21] = 3;
  EXPECT_NE(refusal(skewed).find("S.nii.gz"), std::string::npos);
}

TEST(PoseableLabels, UnnamedLabelsAreOneLineListingTenAtMost) {
  EXPECT_EQ(unnamedLabelsWarning(std::vector<int>{}, "G.nii.gz"), "");
  EXPECT_EQ(unnamedLabelsWarning(std::vector<int>{7}, "G.nii.gz"),
            "G.nii.gz: label 7 has voxels but no name in its label table; posed like the others, "
            "reported by value");
  std::vector<int> many;
  for (int v = 1; v <= 12; ++v) many.push_back(v);
  const std::string line = unnamedLabelsWarning(many, "G.nii.gz");
  EXPECT_NE(line.find("labels 1, 2, 3, 4, 5, 6, 7, 8, 9, 10 and 2 more have voxels"),
            std::string::npos)
      << line;
  EXPECT_EQ(line.find('\n'), std::string::npos);
}

TEST(PoseRun, ARigIsBuiltAndSavedOnceThenReusedFromItsScene) {
  const Body& b = body();
  ScratchDir dir;
  SceneRigRun run;
  run.folder = dir.file("scene");
  run.inputs = {"G.nii.gz", "S.nii.gz", ""};
  run.threads = 2;
  std::vector<std::string> said, notes;
  run.say = [&](const std::string& line) { said.push_back(line); };
  run.note = [&](const std::string& line) { notes.push_back(line); };
  const SceneRig built = rigForScene(*b.job, run);
  EXPECT_FALSE(built.reused);
  EXPECT_TRUE(fs::exists(fs::path(run.folder) / "scene.json"));
  EXPECT_TRUE(notes.empty());  // no scene there yet: nothing to explain
  ASSERT_FALSE(said.empty());
  EXPECT_EQ(said.front().rfind("building the cage (200 vertices)", 0), 0u) << said.front();

  said.clear();
  const SceneRig again = rigForScene(*b.job, run);
  EXPECT_TRUE(again.reused);
  EXPECT_TRUE(notes.empty());
  EXPECT_EQ(said.front(), "reusing the cage and transfer mesh of " + run.folder);
  // The same rig: the same cage, mesh and frame.
  EXPECT_EQ(again.rig->cage().vertices, built.rig->cage().vertices);
  EXPECT_EQ(again.rig->mesh().tets, built.rig->mesh().tets);
  EXPECT_TRUE(again.rig->frame(0).deformed.isApprox(built.rig->frame(0).deformed, 1e-9));
  // The cage's choice is kept with the scene and read back with it.
  EXPECT_EQ(again.rig->cageChoice().json(), built.rig->cageChoice().json());
  EXPECT_EQ(again.rig->cageChoice().used.vertices, 200);
  // Green coordinates: written with the scene, then read back rather than computed.
  EXPECT_TRUE(again.rig->deformation().coordinatesRead())
      << again.rig->deformation().coordinatesNote();

  // A scene built for other settings is not reused, and the note says why.
  PoseJobRequest other;
  other.organsName = "G.nii.gz";
  other.partsPath = b.partsPath;
  other.tissues = b.job->tissues().table;
  other.skeleton = b.job->skeleton();
  other.settings.cageVertices = 150;
  other.settings.threads = 2;
  const PoseJob coarser(readPoseFile(suitePosePath("elbow90")), b.organs, b.parts,
                        std::move(other));
  run.saveBuilt = false;
  const SceneRig rebuilt = rigForScene(coarser, run);
  EXPECT_FALSE(rebuilt.reused);
  ASSERT_EQ(notes.size(), 1u);
  EXPECT_EQ(notes[0].rfind("the scene's rig is built again: ", 0), 0u) << notes[0];
  // Not saved over the scene: the first rig is still reused.
  EXPECT_TRUE(rigForScene(*b.job, run).reused);
}

// A label whose final count misses the volume the deformation gives it (tissue lost to a fold:
// here a target 5 % above what was written) is named, not reported as rounded; one on its target
// is rounded.
TEST(PoseReport, ARoundingThatMissedIsNamedNotReportedAsRounded) {
  const Body& b = body();
  const PosedFrame posed = poseFrame(*b.rig, 0, b.organs, b.parts, b.job->frameOptions());
  const PoseRig::Frame frame = b.rig->frame(0);
  std::map<int, std::int64_t> counts;
  const auto* g = posed.organs.data<std::uint8_t>();
  for (std::int64_t v = 0; v < posed.organs.numVoxels(); ++v) ++counts[g[v]];
  // The two largest labels but the background: one on its target, one 5 % short of it.
  std::vector<std::pair<std::int64_t, int>> bySize;
  for (const auto& [label, n] : counts)
    if (label != 0) bySize.emplace_back(n, label);
  std::sort(bySize.rbegin(), bySize.rend());
  ASSERT_GE(bySize.size(), 2u);
  const int onTarget = bySize[0].second, short5 = bySize[1].second;
  const std::map<int, double> targets = {{onTarget, double(bySize[0].first)},
                                         {short5, 1.05 * double(bySize[1].first)}};
  PoseReportInput in;
  in.organs = &b.organs, in.parts = &b.parts;
  in.posedOrgans = &posed.organs, in.posedParts = &posed.parts;
  in.mesh = &b.rig->mesh(), in.tetMaps = &frame.tetMaps, in.handles = &frame.handles;
  for (const PoseGroup& group : b.rig->pose().groups) in.groupNames.push_back(group.name);
  in.tissues = &*b.job->tissues().table;
  in.labelTargets = &targets;
  const nlohmann::json report = nlohmann::json::parse(poseReportJson(in));
  for (const auto& row : report["labels"]) {
    if (row["value"] == onTarget) {
      EXPECT_EQ(row["rounded"], true);
      EXPECT_NEAR(row["rounding"]["missed_by_percent"].get<double>(), 0, 1e-9);
    } else if (row["value"] == short5) {
      EXPECT_EQ(row["rounded"], false);
      EXPECT_NEAR(row["rounding"]["missed_by_percent"].get<double>(), 100 * (1 / 1.05 - 1), 1e-6);
    } else {
      EXPECT_FALSE(row.contains("rounding")) << row["name"];
    }
  }
  ASSERT_EQ(report["label_rounding_missed"].size(), 1u);
  EXPECT_EQ(report["label_rounding_missed"][0]["value"], short5);
}
