// The policy of a pose job that every front end shares (the command line, the module's Logic,
// Python): which tissue table applies to G, which skeleton belongs to S, and which separations a
// pose needs (its own and the automatic contact separations). Front ends translate their
// arguments into these calls and show progress; they decide nothing of this themselves.
#pragma once

#include "repose/cage/CageBuilder.h"
#include "repose/pose/ContactSeparation.h"
#include "repose/pose/Pose.h"
#include "repose/pose/PoseRig.h"
#include "repose/pose/Skeleton.h"
#include "repose/volume/TissueTable.h"
#include "repose/volume/Volume.h"

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
PoseSeparations poseSeparations(const Pose& pose, const Volume& parts, const Skeleton* skeleton,
                                bool automatic);

// The joints whose two body parts the pose moves with different groups (not both fixed): the
// balls where the rig's transfer mesh is made finer (RigSettings::refineJoints), tets of a third
// of the joint's radius_mm (at least two voxels) within 1.5 radii of its centre.
std::vector<JointRefinement> jointRefinements(const Pose& pose, const Volume& parts,
                                              const Skeleton* skeleton);

// The skeleton's joints as PoseRig bends them: each joint with its two parts (labels of S by
// name), its centre, its distal direction (its "rotation" axis) and its radius.
std::vector<BendJoint> bendJoints(const Skeleton* skeleton, const LabelTable& partLabels);

}  // namespace repose
