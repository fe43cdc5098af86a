// `repose rig --input G --out DIR`: a user's own segmentation made ready to pose. Writes
// DIR/S.nii.gz (body parts), DIR/skeleton.json (named joints with their axes), DIR/tissues.csv
// (names, densities, bones) and DIR/rig.json (what was found), together or not at all. Then
// `repose pose --input G --parts DIR/S.nii.gz --pose P` finds the skeleton and tissues beside S.
#include "ArgParser.h"
#include "StderrLine.h"
#include "Commands.h"
#include "InputChecks.h"
#include "MemoryBudget.h"
#include "TerminalProgress.h"

#include "repose/io/VolumeIO.h"
#include "repose/rig/Rig.h"
#include "repose/util/Error.h"

#include <nlohmann/json.hpp>

#include <chrono>
#include <filesystem>
#include <iostream>
#include <optional>

namespace repose::cli {

int runRig(const Args& args) {
  ArgParser p("rig",
              "Rig a segmentation for posing, from its bones: the body-part map S (head, torso,\n"
              "upper_arm_left, forearm_left, hand_left, ..., thigh_left, shank_left, foot_left,\n"
              "... and the right side), the skeleton (joints neck, shoulder_*, elbow_*, wrist_*,\n"
              "hip_*, knee_*, ankle_* with their centres and anatomical axes) and the tissue\n"
              "table. Soft tissue goes to the part it belongs to through the body; parts that\n"
              "touch (an arm resting on the trunk) stay apart. Writes DIR/S.nii.gz,\n"
              "DIR/skeleton.json, DIR/tissues.csv and DIR/rig.json.");
  p.option("input", "FILE", "label map G (NIfTI, NRRD, .seg.nrrd, DICOM)")
      .option("out", "DIR", "output folder (created if missing; its parent must exist)")
      .option("labels", "NAME",
              "G's label convention: auto, phantom, icrp110 (ICRP 110 AF/AM organ IDs), "
              "totalsegmentator (v2 class names from G's label table), or a CSV "
              "label,bone[,side][,name][,density_kg_m3]; auto also recognises a coarse map (the "
              "whole skeleton as one label inside a body label, by name or by shape) and splits "
              "its skeleton into bones (a CSV names them with the kinds skeleton and body)",
              "auto")
      .option("image", "FILE",
              "the scan G was segmented from (CT or MR, any grid over the same place): the "
              "body's outline, for segmentations that label organs and bones but not the skin, "
              "fat and muscle between them (TotalSegmentator's)")
      .option("threads", "N", "worker threads (0: all cores)", "0")
      .flag("json", "print rig.json on stdout");
  declareMemoryOption(p, "G larger than this is refused before it is read");
  if (!p.parse(args)) return 0;
  for (const char* required : {"input", "out"})
    if (!p.has(required)) throw UsageError{std::string("--") + required + " is required"};
  const bool quiet = p.has("json");
  const std::string input = p.get("input"), out = p.get("out");
  namespace fs = std::filesystem;
  if (!fs::exists(fs::absolute(out).parent_path()))
    throw Error(out + ": its parent folder does not exist");
  if (fs::exists(out) && !fs::is_directory(out)) throw Error(out + ": exists and is not a folder");
  if (fs::exists(input) && fs::exists(out) && fs::equivalent(input, out))
    throw UsageError{"--out names the input"};
  const auto start = std::chrono::steady_clock::now();
  const double budget = parseMemoryBudget(p.get("memory"));
  const Volume organs = readVolume(input, readOptionsWithin(budget, !quiet));
  requirePoseableLabels(organs, input);

  std::optional<Volume> image;
  if (p.has("image")) image = readVolume(p.get("image"), readOptionsWithin(budget, !quiet));

  RigOptions options;
  options.image = image ? &*image : nullptr;
  options.imageSource = p.has("image") ? p.get("image") : "the image";
  options.labels = p.get("labels");
  options.source = input;
  options.threads = static_cast<int>(p.getInt("threads"));
  options.progress = quiet ? ProgressFn{} : terminalProgress();
  const RigResult rig = rigBody(organs, options);

  writeRigFolder(rig, out, input);
  const fs::path dir(out);
  const nlohmann::json rigReport = nlohmann::json::parse(rig.reportJson);

  for (const std::string& w : rig.warnings) stderrLine("repose rig: warning: " + w);
  for (const std::string& m : rig.missing) stderrLine("repose rig: not rigged: " + m);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (quiet) {
    std::cout << rigReport.dump(2) << "\n";
    return 0;
  }
  std::cout << "convention " << rig.convention.name << " (" << rig.convention.detection << ")\n";
  for (const SkeletonJoint& j : rig.skeleton.joints)
    std::cout << "  " << j.name << " at (" << std::lround(j.centre.x()) << ", "
              << std::lround(j.centre.y()) << ", " << std::lround(j.centre.z())
              << ") mm: " << j.method << "\n";
  std::cout << "wrote " << (dir / "S.nii.gz").string()
            << ", skeleton.json, tissues.csv, rig.json in " << int(seconds) << " s\n";
  return 0;
}

}  // namespace repose::cli
