// What `repose pose` (and the Logic's pose job) reports for one posed frame (report.json,
// docs/FORMATS.md): per-label and whole-body volume and mass before and after, the distribution of
// per-tet distortion and volume change, inverted tets and outliers, the rigidity of bones against
// their analytically posed copies, holes, and the quality targets of docs/QUALITY.md each checked.
#pragma once

#include "repose/mesh/RigidHandles.h"
#include "repose/mesh/TransferMesh.h"
#include "repose/pose/PosedTally.h"
#include "repose/volume/TissueTable.h"
#include "repose/volume/Volume.h"

#include <Eigen/Core>

#include <map>
#include <optional>
#include <string>
#include <vector>

namespace repose {

struct PoseReportInput {
  const Volume* organs = nullptr;  // G at rest
  const Volume* parts = nullptr;   // S at rest
  // The posed maps, whole; or, for a frame made slab by slab, their tally (then these are null).
  const Volume* posedOrgans = nullptr;
  const Volume* posedParts = nullptr;
  const PosedTally* posed = nullptr;
  const TransferMesh* mesh = nullptr;
  const std::vector<Eigen::Matrix3d>* tetMaps = nullptr;  // B_t of every tet
  const std::vector<RigidHandle>* handles = nullptr;      // with this frame's motions
  std::vector<std::string> groupNames;
  const TissueTable* tissues = nullptr;  // null: no masses and no rigidity check
  int outlierVertices = 0;
  // Vertices of mesh components with no vertex inside the cage: the cage cannot move them, so
  // they stay at rest (RigiditySolver). Reported so a user sees a body part the cage missed.
  int unreachableVertices = 0;
  int rigidVertices = 0;
  // RasterReport::labelTargets when G's soft labels were rounded to the deformation's volumes
  // (PoseFrameOptions::preserveLabelVolumes): those labels' rows say "rounded" and give the
  // change the deformation itself makes ("deformation_change_percent"); their nearest-neighbour
  // floor is still reported but not taken off, since the same rounding of a rigid motion keeps
  // their rest volume.
  const std::map<int, double>* labelTargets = nullptr;
};

// The report as a JSON object (text), the keys of docs/FORMATS.md from "labels" on; callers add
// what they know of the job (pose, frame, files). Shared by `repose pose` and the Logic.
std::string poseReportJson(const PoseReportInput& in);

// Whether every label of G has a tissue of the same value and name in `table` (so its densities
// and rigid flags are meant for this map).
bool tissueTableCovers(const TissueTable& table, const LabelTable& labels);

}  // namespace repose
