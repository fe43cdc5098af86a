// `repose rig`: from a user's organ map G alone to what posing needs — the body-part map S (the
// phantom's part names: head, torso, upper_arm_left, forearm_left, hand_left, ... foot_right;
// and where G has the clavicles and the pelvis, shoulder_girdle_left/right and pelvis, which the
// pose's rhythms move: pose/PoseRhythm.h),
// the skeleton (named joints with their anatomical axes, fitted to the bones' articular ends) and
// the tissue table (names, densities, which labels are bone and which bone). Works from the bones
// of G under a label convention (LabelConvention.h); a body part whose bones are missing (a scan
// without arms) is left out and said so.
#pragma once

#include "repose/skeleton/Skeleton.h"
#include "repose/rig/LabelConvention.h"
#include "repose/util/Progress.h"
#include "repose/volume/TissueTable.h"
#include "repose/volume/Volume.h"

#include <string>
#include <vector>

namespace repose {

struct RigOptions {
  std::string labels = "auto";  // phantom, icrp110, totalsegmentator, auto, or a CSV path
  std::string source = "G";     // the file G came from, for messages
  // The scan G was segmented from (CT, MR; any grid over the same place): the body's outline,
  // so S covers the skin, fat and muscle an organ segmentation leaves unlabelled.
  const Volume* image = nullptr;
  std::string imageSource = "the image";
  int threads = 0;
  ProgressFn progress;
};

struct RigResult {
  Volume parts;  // S on G's grid, uint8, with the part names
  Skeleton skeleton;
  TissueTable tissues;
  LabelConvention convention;
  std::vector<std::string> missing;   // joints not made, one line each, saying why
  std::vector<std::string> warnings;  // orientation doubts, labels the convention did not know
  std::string reportJson;             // rig.json: all of the above with the bones found
};

// Throws repose::Error "<source>: <problem>" for a G that is not a label map, whose convention
// cannot be told, or whose bones give no limb to rig (no humerus and no femur).
RigResult rigBody(const Volume& organs, const RigOptions& options = {});

// Writes `folder`/S.nii.gz, skeleton.json, tissues.csv and rig.json (the folder is created; its
// parent must exist), all four or none. `input` names G in the files.
void writeRigFolder(const RigResult& rig, const std::string& folder, const std::string& input);

// The part names `repose rig` and `repose phantom` give S's values (1 head, 2 torso, 3
// upper_arm_left, ... 14 foot_right; the rig's 15 and 16 shoulder_girdle_left and _right, 17
// pelvis). Names S when it carries no label table at all and its values
// all lie in that range: a plain NRRD or NIfTI without a table, as 3D Slicer hands a CLI module
// the label map volumes it exports. Returns the warning to give (empty when S was left alone).
std::string nameBodyPartsByRigConvention(Volume& parts, const std::string& source);

}  // namespace repose
