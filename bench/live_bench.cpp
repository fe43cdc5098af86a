// The workbench's live path end to end, driven through the Logic with the calls the widget makes
// during a drag (issue 25): a group's motion set on the pose node (SetPoseGroupTransform: the
// edit, then the frame it triggers: the posed cage, Green coordinates, the rigidity solves),
// then the three 512-pixel slices the views show (axial, coronal, sagittal through the posed
// body's centre). Prints the median and 99th percentile of each stage and of the whole event as
// JSON; also the cost of the body's volume change the frame predicts ("prediction", which the
// panel shows when a drag ends, so it is not in "event"; computed on the Logic's worker, the
// asking thread paying "prediction_request"). Single-shot: run by bench/run_bench.py
// (`make bench`).
//
//   ReposeLiveBench SCENE_DIR [--events 200] [--pixels 512] [--group NAME] [--degrees 90]
//                   [--pose FILE]
// --pose replaces the scene's pose before the live pose starts, e.g.
// bench/live/elbow90_free_upper_arm.pose.json, whose free cage vertices put the cage's ARAP
// (warm-started from event to event) into every frame.
#include "vtkMRMLReposePoseNode.h"
#include "vtkMRMLReposeScene.h"
#include "vtkMRMLReposeTransferMeshNode.h"
#include "vtkSlicerReposeLogic.h"

#include <nlohmann/json.hpp>

#include <vtkImageData.h>
#include <vtkNew.h>
#include <vtkUnstructuredGrid.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <iterator>
#include <map>
#include <string>
#include <vector>

namespace {

using Clock = std::chrono::steady_clock;

double ms(Clock::time_point a, Clock::time_point b) {
  return std::chrono::duration<double, std::milli>(b - a).count();
}

nlohmann::json statistics(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const auto at = [&](double q) {
    return v[std::min(v.size() - 1, static_cast<std::size_t>(q * double(v.size() - 1) + 0.5))];
  };
  return {{"median_ms", at(0.5)}, {"p99_ms", at(0.99)}, {"max_ms", v.back()}, {"min_ms", v[0]}};
}

[[noreturn]] void fail(const std::string& what) {
  std::cerr << "ReposeLiveBench: " << what << "\n";
  std::exit(1);
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2)
    fail(
        "usage: ReposeLiveBench SCENE_DIR [--events N] [--pixels N] [--group NAME] "
        "[--degrees D] [--pose FILE]");
  const std::string sceneDir = argv[1];
  int events = 200, pixels = 512;
  double degrees = 90;
  std::string group, poseFile;
  for (int i = 2; i + 1 < argc; i += 2) {
    const std::string key = argv[i], value = argv[i + 1];
    if (key == "--events")
      events = std::stoi(value);
    else if (key == "--pixels")
      pixels = std::stoi(value);
    else if (key == "--group")
      group = value;
    else if (key == "--degrees")
      degrees = std::stod(value);
    else if (key == "--pose")
      poseFile = value;
    else
      fail("unknown option " + key);
  }
  if (events < 2) fail("--events must be at least 2");

  vtkNew<vtkSlicerReposeLogic> logic;
  if (!logic->LoadScene(sceneDir)) fail(logic->GetLastErrorMessage());
  auto* pose = vtkMRMLReposePoseNode::SafeDownCast(
      logic->GetScene()->GetNodesByClass("vtkMRMLReposePoseNode").at(0));
  auto* meshNode = vtkMRMLReposeTransferMeshNode::SafeDownCast(
      logic->GetScene()->GetNodesByClass("vtkMRMLReposeTransferMeshNode").at(0));
  if (!poseFile.empty()) {
    std::ifstream in(poseFile);
    if (!in) fail(poseFile + ": cannot be read");
    pose->SetPoseJSON(std::string(std::istreambuf_iterator<char>(in), {}));
  }
  const auto prepareStart = Clock::now();
  if (!logic->GetLive()->StartLivePose(pose) ||
      logic->GetJobs()->WaitForJob() != vtkSlicerReposeJobsLogic::JobSucceeded)
    fail("live pose: " + logic->GetLastErrorMessage());
  const double prepareMs = ms(prepareStart, Clock::now());

  // The group to drag: the one named, else the first the pose moves (a turn or a shift in its
  // current keyframe), else the first a user can turn; whatever the groups are called (a pose
  // of named joints, a file written by hand).
  if (group.empty()) {
    const auto summary = logic->GetPoseEdits()->GetPoseSummary(pose);
    for (const std::string& candidate : summary.movableGroups) {
      const auto t = logic->GetPoseEdits()->GetPoseGroupTransform(pose, candidate);
      const bool moves = t && (t->angleDeg != 0 || t->translation != std::array<double, 3>{});
      if (moves) {
        group = candidate;
        break;
      }
    }
    if (group.empty() && !summary.movableGroups.empty()) group = summary.movableGroups.front();
  }
  const auto rest = logic->GetPoseEdits()->GetPoseGroupTransform(pose, group);
  if (group.empty() || !rest)
    fail("no movable group \"" + group + "\" in the scene's pose (--group NAME)");
  const std::array<double, 3> axis = rest->axis, pivot = rest->pivot,
                              translation = rest->translation;

  const std::array<double, 6> box = logic->GetLive()->GetLiveBounds();
  const std::array<double, 3> centre{(box[0] + box[1]) / 2, (box[2] + box[3]) / 2,
                                     (box[4] + box[5]) / 2};
  std::map<std::string, std::vector<double>> stages;
  logic->GetPoseEdits()->BeginPoseInteraction();
  for (int e = 0; e < events; ++e) {
    // A steady drag from rest to `degrees` about the group's own axis and pivot.
    const double angle = degrees * double(e + 1) / double(events);
    const auto t0 = Clock::now();
    if (!logic->GetPoseEdits()->SetPoseGroupTransform(pose, group, axis, angle, pivot, translation))
      fail("drag: " + logic->GetLastErrorMessage());
    const auto t1 = Clock::now();
    const double frame = logic->GetLive()->GetLiveFrameMilliseconds();
    double slices = 0;
    for (int o = 0; o < 3; ++o) {
      const auto s0 = Clock::now();
      vtkSmartPointer<vtkImageData> slice = logic->GetLive()->ComputeLiveSlice(o,
                                                                               centre[o == 0   ? 2
                                                                                      : o == 1 ? 1
                                                                                               : 0],
                                                                               pixels);
      if (!slice) fail("slice: " + logic->GetLastErrorMessage());
      const double t = ms(s0, Clock::now());
      slices += t;
      stages[o == 0 ? "slice_axial" : o == 1 ? "slice_coronal" : "slice_sagittal"].push_back(t);
    }
    const double edit = ms(t0, t1);
    stages["edit_and_frame"].push_back(edit);
    stages["frame"].push_back(frame);
    stages["edit_outside_frame"].push_back(edit - frame);
    stages["slices"].push_back(slices);
    stages["event"].push_back(ms(t0, Clock::now()));
    // Not part of a drag's event: the panel's predicted body volume change, which the workbench
    // asks for when a drag ends (vtkSlicerReposeLogic::IsPoseInteractionActive) and computes on
    // the Logic's worker; timed here on every frame: what the asking thread pays
    // ("prediction_request", the panel's event loop), and until the prediction is ready.
    const auto p0 = Clock::now();
    logic->GetLive()->RequestLivePrediction();
    stages["prediction_request"].push_back(ms(p0, Clock::now()));
    if (!logic->GetLive()->GetLivePrediction().valid)
      fail("prediction: " + logic->GetLastErrorMessage());
    stages["prediction"].push_back(ms(p0, Clock::now()));
  }
  logic->GetPoseEdits()->EndPoseInteraction();

  nlohmann::json out = {
      {"scene", sceneDir},
      {"group", group},
      {"events", events},
      {"degrees", degrees},
      {"pixels", pixels},
      {"prepare_ms", prepareMs},
      {"tm_vertices", meshNode->GetMesh()->GetNumberOfPoints()},
      {"cage_vertices", logic->GetLive()->GetLiveRestCage().size()},
  };
  for (const auto& [name, values] : stages) out["stages"][name] = statistics(values);
  std::cout << out.dump(2) << "\n";
  return 0;
}
