// The policy of a pose job that every front end shares (the command line, the module's Logic,
// Python): which tissue table applies to G, which skeleton belongs to S, the pose's joints, which
// separations the pose needs (its own and the automatic contact separations), how the rig is
// built (whole pieces, finer tets at the bent joints) and bent, and what the report says of the
// job. Front ends translate their arguments into a PoseJobRequest, build a PoseJob, and show
// progress; they decide nothing of this themselves, so the same request gives the same voxels
// from `repose pose`, the workbench and Python.
#pragma once

#include "repose/cage/CageBuilder.h"
#include "repose/pose/ContactSeparation.h"
#include "repose/pose/Pose.h"
#include "repose/pose/PoseFrame.h"
#include "repose/pose/PoseRhythm.h"
#include "repose/pose/PoseRig.h"
#include "repose/skeleton/Skeleton.h"
#include "repose/volume/TissueTable.h"
#include "repose/volume/Volume.h"

#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace repose {

struct TissueChoice {
  std::optional<TissueTable> table;
  std::string name = "none";  // how report.json names it: the file, "phantom default", "none"
  std::string warning;        // one line when a table beside S was found but does not fit G
};

// The table at explicitPath when given; else the one `repose rig` wrote beside S
// (findTissuesBeside) when it has every label present in G; else the phantom's when G's label
// table names every label present as the phantom does; else none.
TissueChoice chooseTissues(const Volume& organs, const std::string& explicitPath,
                           const std::string& partsPath);
std::vector<int> rigidLabelsOf(const TissueTable& table);

// The skeleton at explicitPath when given (an error if it cannot be read), else the one beside
// S (findSkeletonBeside), else none.
std::optional<Skeleton> skeletonFor(const std::string& partsPath, const std::string& explicitPath);

// Resolves the pose's joint names with the skeleton; without one, a pose that names joints is
// refused with a one-line error saying where the skeleton is looked for.
void resolveJointsWith(Pose& pose, const Skeleton* skeleton, const std::string& partsPath);

struct PoseSeparations {
  std::vector<LimbSeparation> all;  // the pose's own (names resolved), then the automatic ones
  ContactSeparations automatic;     // what the automatic separation made and left joined
  bool automaticOn = false;
  std::string reportJson() const;  // report.json's "separations"
};
// The automatic ones are found within contactReachMm of the rig's cage (settings' dilation).
PoseSeparations poseSeparations(const Pose& pose, const Volume& parts, const Skeleton* skeleton,
                                bool automatic, const RigSettings& settings = {});

// The joints whose two body parts the pose moves with different groups (not both fixed): the
// balls where the rig's transfer mesh is made finer (RigSettings::refineJoints), tets of a sixth
// of the joint's radius_mm (at least two voxels) within 1.5 radii of its centre.
std::vector<JointRefinement> jointRefinements(const Pose& pose, const Volume& parts,
                                              const Skeleton* skeleton);

// The skeleton's joints as PoseRig bends them: each joint with its two parts (labels of S by
// name), its centre, its distal direction (its "rotation" axis) and its radius.
std::vector<BendJoint> bendJoints(const Skeleton* skeleton, const LabelTable& partLabels);

// What a front end was given, translated from its own arguments.
struct PoseJobRequest {
  std::string organsName = "G";  // G's file or node: the report's "input", messages
  std::string partsPath;  // S's file, where tissues.csv and skeleton.json are looked for beside it
  std::string imageName = "the image";  // the image's file, for messages
  std::string tissuesPath;  // an explicit tissue table ("": beside S, else the phantom's)
  bool tissuesAuto = true;  // without an explicit table: look beside S, then the phantom's
  std::optional<TissueTable> tissues;  // a table in memory (a rig just made); wins over the paths
  std::string tissuesName = "given";   // how the report names an in-memory table
  std::string skeletonPath;            // an explicit skeleton ("": beside S)
  std::optional<Skeleton> skeleton;    // a skeleton in memory; wins over the paths
  RigSettings settings;  // cage vertices, dilation, mesh size, threads, wholeOrgans; the job adds
                         // the rigid labels and the joints' refinement
  int jointRings = -1;   // -1: the pose file's
  bool autoSeparate = true;
  // Restore the soft tissue's volume after each frame's solve (VolumeRestoration.h).
  bool volumeRestoration = true;
  // What G's reader decided (ReadOptions::note: a DICOM SEG's grid, a fractional SEG
  // thresholded), kept in every report of the job as "input_notes".
  std::vector<std::string> organsNotes;
};

// One pose of one body, decided: everything above, resolved once. G and S must outlive the job.
class PoseJob {
 public:
  // Checks S (and the image, when given) against G's grid (dimensions and matrix), resolves the
  // pose's joints, picks the tissue table and skeleton, finds the separations and the joints to
  // refine. Throws repose::Error with one line naming what is wrong.
  PoseJob(Pose pose, const Volume& organs, const Volume& parts, PoseJobRequest request,
          const Volume* image = nullptr);

  // Joints resolved to places and axes, with the rhythms' groups (PoseRhythm.h) after the user's.
  const Pose& pose() const { return pose_; }
  // The same without the rhythms' groups: what makeRig(geometry, threads) rigs and edits change.
  const Pose& userPose() const { return userPose_; }
  const RigSettings& settings() const { return settings_; }
  const PoseSeparations& separations() const { return separations_; }
  const TissueChoice& tissues() const { return tissues_; }
  const std::optional<Skeleton>& skeleton() const { return skeleton_; }
  int jointRings() const { return jointRings_; }
  // One line each: a tissue table beside S that does not fit G, touching parts left joined, turns
  // beyond a joint's range of motion.
  const std::vector<std::string>& warnings() const { return warnings_; }
  // The scene key of the rig this job builds (SceneFolder.h: sceneRigKey), for S at partsPath
  // ("": the request's).
  std::string sceneKey(const std::string& partsPath = "") const;

  // Cage and transfer mesh as this job builds them (progress: cage 0-0.5, mesh 0.5-1).
  RigGeometry buildGeometry(const ProgressFn& progress = {}) const;
  // The rig of a geometry (built here, or a scene's) for this job's pose, with its joints bent.
  std::unique_ptr<PoseRig> makeRig(RigGeometry geometry, int threads = 0) const;
  // A rig for another pose of the same body (an edit of the groups, a live session; as its user
  // wrote it: the rhythms' groups are added here): the same joints bent.
  std::unique_ptr<PoseRig> makeRig(RigGeometry geometry, const Pose& pose, int threads) const;
  // The frame options the job decides (the tissue table and its name); the caller adds output
  // spacing, image, progress and warnings.
  PoseFrameOptions frameOptions() const;
  // report.json completed with what the job knows: the input and what its reader decided
  // ("input_notes", when it said anything), whether the rig came from a scene,
  // the joint rings, the separations, the skeleton, and whether the rig's Green coordinates were
  // read from a file (CageDeformation::coordinatesRead) or computed, and why.
  std::string completeReport(const std::string& reportJson, bool sceneReused,
                             const PoseRig& rig) const;

 private:
  const Volume* organs_;
  const Volume* parts_;
  PoseJobRequest request_;
  Pose pose_, userPose_;
  PoseRhythms rhythms_;
  std::vector<std::string> rhythmNotes_;  // report.json's rhythms.applied
  RigSettings settings_;
  std::vector<int> bendingPieces_;  // PoseFrameOptions::bendingPieces
  PoseSeparations separations_;
  TissueChoice tissues_;
  std::optional<Skeleton> skeleton_;
  int jointRings_ = 0;
  std::vector<std::string> warnings_;
};

}  // namespace repose
