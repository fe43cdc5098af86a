#include "repose/pose/PoseRun.h"

#include "PoseFrameSteps.h"

#include "repose/util/Error.h"
#include "repose/volume/LabelStatistics.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <optional>

namespace repose {

void requirePoseableLabels(const Volume& volume, const std::string& name) {
  if (!isIntegerType(volume.scalarType()))
    throwFileError(name, "not a label map (float voxels); an image is posed beside the labels");
  volume.geometry().requireOrthogonalAxes(name);
  const std::vector<LabelCount> labels = countLabels(volume);
  if (labels.empty())
    throwFileError(name, "the segmentation is empty: every voxel is 0, there is no body to pose");
  // An integer image (a CT in Hounsfield units, an MR) that its reader did not take for labels:
  // values below 0, or more distinct values than any anatomical label set holds.
  constexpr std::size_t kMostLabels = 4096;
  const bool negative =
      std::any_of(labels.begin(), labels.end(), [](const LabelCount& c) { return c.value < 0; });
  if (!volume.isLabelMap() && (negative || labels.size() > kMostLabels))
    throwFileError(name, "not a label map (" +
                             (negative ? std::string("values below 0")
                                       : std::to_string(labels.size()) + " distinct values") +
                             ", an image such as a CT); an image is posed beside the labels");
}

std::string unnamedLabelsWarning(const Volume& volume, const std::string& name) {
  std::vector<int> values;
  for (const LabelCount& c : unnamedLabels(volume)) values.push_back(c.value);
  return unnamedLabelsWarning(values, name);
}

std::string unnamedLabelsWarning(const std::vector<int>& values, const std::string& name) {
  if (values.empty()) return "";
  std::string list;
  for (std::size_t i = 0; i < values.size() && i < 10; ++i)
    list += (i ? ", " : "") + std::to_string(values[i]);
  if (values.size() > 10) list += " and " + std::to_string(values.size() - 10) + " more";
  const bool several = values.size() > 1;
  return name + ": label" + (several ? "s " : " ") + list + (several ? " have" : " has") +
         " voxels but no name in its label table; posed like the others, reported by value";
}

std::string FrameOutcome::missedLine() const {
  std::string line;
  for (const std::string& m : missed) line += (line.empty() ? "" : "; ") + m;
  return line;
}

SceneRig rigForScene(const PoseJob& job, const SceneRigRun& run) {
  auto say = [&](const std::string& line) {
    if (run.say) run.say(line);
  };
  const std::string key = job.sceneKey();
  std::optional<RigGeometry> fromScene;
  if (!run.folder.empty()) {
    std::string why;
    fromScene = readSceneRig(run.folder, key, &why);
    if (!why.empty() && run.note)
      run.note(std::string("the scene's rig is built again") +
               (run.saveBuilt ? " and saved over it" : "") + ": " + why);
  }
  SceneRig out;
  out.reused = fromScene.has_value();
  RigGeometry geometry;
  if (out.reused) {
    geometry = std::move(*fromScene);
    say("reusing the cage and transfer mesh of " + run.folder);
  } else {
    say("building the cage (" + std::to_string(job.settings().cageVertices) +
        " vertices) and the mesh");
    geometry = job.buildGeometry(run.buildProgress);
    const CageChoice& cage = geometry.cageChoice;
    if (cage.fallback() && run.note)
      run.note("the cage of " + describeCageSetting(cage.asked.vertices, cage.asked.dilateMm) +
               " failed its checks (" + cage.tried.front().failure + "); built with " +
               describeCageSetting(cage.used.vertices, cage.used.dilateMm));
  }
  const std::string coordinates = geometry.coordinatesFile;
  say("embedding the mesh in the cage");
  out.rig = job.makeRig(std::move(geometry), run.threads);
  if (!run.folder.empty() && !out.reused && run.saveBuilt)
    writeSceneFolder(run.folder, *out.rig, key, run.inputs, job.settings());
  if (out.reused && out.rig->deformation().coordinatesRead()) {
    say("Green coordinates read from " + coordinates);
  } else if (out.reused) {
    // A scene of an older version, or one whose file does not belong to its mesh and cage:
    // computed here, and saved so that the next run reads them.
    say("Green coordinates computed again: " + out.rig->deformation().coordinatesNote());
    out.rig->deformation().saveCoordinates(coordinates);
  }
  return out;
}

FrameOutcome runPoseFrame(const PoseJob& job, const PoseRig& rig, std::size_t index,
                          const Volume& organs, const Volume& parts, const FrameRun& run) {
  PoseFrameOptions fo = job.frameOptions();
  fo.image = run.image;
  fo.background = run.background;
  fo.spacingMm = run.spacingMm;
  fo.fillPockets = run.fillPockets;
  fo.preserveLabelVolumes = run.preserveLabelVolumes;
  fo.labelMapFiles = run.labelMapFiles;
  fo.progress = run.progress;
  fo.warn = run.warn;
  FrameWriteOptions wo = run.write;
  wo.labelMapFiles = run.labelMapFiles;
  // One memory rule for every front end: the posed volumes (the image's too) beside what the
  // process holds now, checked on the frame's grid before anything is allocated for it. Beyond
  // it a frame with a folder to go to is made slab by slab when the front end allows it.
  const double bytesPerVoxel = posedBytesPerVoxel(organs, parts, run.image);
  std::optional<frame::FrameStart> started;
  if (run.ranks)
    run.ranks->together([&] { started = frame::startFrame(rig, index, organs, parts, fo); });
  else
    started = frame::startFrame(rig, index, organs, parts, fo);
  frame::FrameStart& start = *started;
  FrameOutcome out;
  // A DICOM SEG beyond its format's 4 GiB is said before the work (slab by slab: in
  // poseFrameToFolderFrom).
  const bool streams =
      !run.folder.empty() &&
      (run.alwaysOutOfCore || run.ranks ||
       (run.outOfCore && !frameFitsMemory(start.grid, bytesPerVoxel, run.memoryBudget)));
  nlohmann::json dicomSeg;
  if (!streams && !run.folder.empty() && run.labelMapFiles == LabelMapFiles::DicomSeg)
    dicomSeg = frame::checkDicomSegFits(start, rig.mesh(), organs, parts, run.folder);
  if (streams) {
    if (run.onGrid) run.onGrid(start.grid);
    out.streamed = true;
    out.frame.name = start.frame.name;
    out.frame.grid = start.grid;
    out.frame.labelMapFiles = run.labelMapFiles;
    out.reportJson = frame::poseFrameToFolderFrom(
        start, rig, organs, parts, fo, run.folder, wo, run.memoryBudget, 0,
        [&](const std::string& report) { return job.completeReport(report, run.sceneReused, rig); },
        run.ranks);
    out.frame.reportJson = out.reportJson;
    if (run.ranks && !run.ranks->root()) return out;  // rank 0 has the report
  } else {
    checkFrameMemory(start.grid, bytesPerVoxel, run.memoryBudget, run.budgetWhat, run.budgetHint);
    if (run.onGrid) run.onGrid(start.grid);
    out.frame = frame::poseFrameFrom(start, rig, organs, parts, fo);
    out.frame.reportJson = job.completeReport(out.frame.reportJson, run.sceneReused, rig);
    if (!dicomSeg.is_null()) {
      nlohmann::json report = nlohmann::json::parse(out.frame.reportJson);
      report["dicom_seg"] = dicomSeg;
      out.frame.reportJson = report.dump();
    }
    out.reportJson = out.frame.reportJson;
    if (!run.folder.empty()) out.reportJson = writePosedFrame(out.frame, run.folder, wo);
  }
  const nlohmann::json targets = nlohmann::json::parse(out.reportJson).at("targets");
  out.targetsMet = targets.at("met").get<bool>();
  for (const auto& line : targets.at("missed")) out.missed.push_back(line.get<std::string>());
  return out;
}

}  // namespace repose
