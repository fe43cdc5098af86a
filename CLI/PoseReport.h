// What `repose pose` reports for one posed frame (report.json, docs/FORMATS.md): per-label and
// whole-body volume and mass before and after, the distribution of per-tet distortion and volume
// change, inverted tets and outliers, the rigidity of bones against their analytically posed
// copies, holes, and the quality targets of docs/QUALITY.md each checked.
#pragma once

#include "repose/mesh/RigidHandles.h"
#include "repose/mesh/TransferMesh.h"
#include "repose/volume/TissueTable.h"
#include "repose/volume/Volume.h"

#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include <optional>
#include <string>
#include <vector>

namespace repose::cli {

struct PoseReportInput {
  const Volume* organs = nullptr;  // G at rest
  const Volume* parts = nullptr;   // S at rest
  const Volume* posedOrgans = nullptr;
  const Volume* posedParts = nullptr;
  const TransferMesh* mesh = nullptr;
  const std::vector<Eigen::Matrix3d>* tetMaps = nullptr;  // B_t of every tet
  const std::vector<RigidHandle>* handles = nullptr;      // with this frame's motions
  std::vector<std::string> groupNames;
  const TissueTable* tissues = nullptr;  // null: no masses and no rigidity check
  int outlierVertices = 0;
  int rigidVertices = 0;
};

nlohmann::json makePoseReport(const PoseReportInput& in);

}  // namespace repose::cli
