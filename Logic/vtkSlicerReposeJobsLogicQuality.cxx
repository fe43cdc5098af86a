// The last export's quality as the panel shows it (from the report its segmentation node keeps):
// report.json's "quality" checks turned into
// rows (what was measured, the target, met or not) and its per-label volume changes. The report
// is the one `repose pose` writes (Core pose/PoseReport.cpp); the rows say the same in words.
#include "vtkSlicerReposeJobsLogic.h"

#include "vtkMRMLReposeSegmentationNode.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace {

std::string percent(double v) {
  char text[32];
  std::snprintf(text, sizeof text, "%+.2f %%", v);
  return text;
}

}  // namespace

std::vector<vtkSlicerReposeJobsLogic::QualityCheck> vtkSlicerReposeJobsLogic::GetLastPoseQuality()
    const {
  std::vector<QualityCheck> rows;
  const vtkMRMLReposeSegmentationNode* posed = this->GetLastPosedSegmentation();
  if (!posed || posed->GetPoseReportJSON().empty()) return rows;
  const nlohmann::json report = nlohmann::json::parse(posed->GetPoseReportJSON(), nullptr, false);
  if (report.is_discarded() || !report.contains("quality")) return rows;
  const nlohmann::json& q = report["quality"];
  auto met = [&](const char* key) { return q[key].value("met", false); };
  if (q.contains("body_within_half_percent"))
    rows.push_back({"Body volume",
                    percent(q["body_within_half_percent"].value("change_percent", 0.0)),
                    "within ±0.5 %", met("body_within_half_percent")});
  if (q.contains("labels_within_1_percent")) {
    const nlohmann::json& l = q["labels_within_1_percent"];
    std::string worst = l.value("worst_name", std::string());
    if (worst.empty()) worst = std::to_string(l.value("worst_label", 0));
    rows.push_back({"Worst label",
                    worst + " (" + std::to_string(l.value("worst_label", 0)) +
                        "): " + percent(l.value("worst_change_beyond_floor_percent", 0.0)) +
                        " beyond resampling",
                    "every label within ±1 %", met("labels_within_1_percent")});
  }
  if (q.contains("bones_rigid")) {
    char dice[64];
    std::snprintf(dice, sizeof dice, "min Dice %.3f", q["bones_rigid"].value("min_dice", 0.0));
    const std::string bone = q["bones_rigid"].value("min_dice_bone", std::string());
    rows.push_back({"Bones rigid", std::string(dice) + (bone.empty() ? "" : " (" + bone + ")"),
                    "Dice ≥ 0.95 each", met("bones_rigid")});
  }
  if (q.contains("no_new_holes"))
    rows.push_back(
        {"Holes",
         std::to_string(q["no_new_holes"].value("new_enclosed_voxels", 0)) + " new enclosed voxels",
         "none new", met("no_new_holes")});
  if (q.contains("no_label_lost"))
    rows.push_back({"Labels lost", std::to_string(q["no_label_lost"].value("labels_lost", 0)),
                    "none", met("no_label_lost")});
  if (q.contains("pieces_apart")) {
    const nlohmann::json& c = q["pieces_apart"];
    std::string text = std::to_string(c.value("voxels", 0)) + " shared voxels";
    if (c.contains("most") && c["most"].is_array() && c["most"].size() == 2)
      text +=
          " (" + c["most"][0].get<std::string>() + " / " + c["most"][1].get<std::string>() + ")";
    rows.push_back({"Bones collided", text, "none", met("pieces_apart")});
  }
  if (q.contains("prediction_within_targets")) {
    const nlohmann::json& p = q["prediction_within_targets"];
    const std::string part = p.value("worst_part", std::string());
    rows.push_back({"Mesh prediction",
                    "body " + percent(p.value("body_change_percent", 0.0)) +
                        (part.empty() ? std::string()
                                      : ", " + part + " " +
                                            percent(p.value("worst_part_change_percent", 0.0))),
                    "body ±0.5 %, each part ±1 %", met("prediction_within_targets")});
  }
  return rows;
}

std::vector<vtkSlicerReposeJobsLogic::LabelChange>
vtkSlicerReposeJobsLogic::GetLastPoseLabelChanges() const {
  std::vector<LabelChange> out;
  const vtkMRMLReposeSegmentationNode* posed = this->GetLastPosedSegmentation();
  if (!posed || posed->GetPoseReportJSON().empty()) return out;
  const nlohmann::json report = nlohmann::json::parse(posed->GetPoseReportJSON(), nullptr, false);
  if (report.is_discarded() || !report.contains("labels")) return out;
  for (const nlohmann::json& row : report["labels"]) {
    // The change the deformation makes beyond resampling, as the quality check counts it.
    const double change =
        row.value("change_beyond_floor_percent", row.value("change_percent", 0.0));
    out.push_back({row.value("value", 0), row.value("name", std::string()), change});
  }
  std::sort(out.begin(), out.end(), [](const LabelChange& a, const LabelChange& b) {
    return std::fabs(a.changePercent) > std::fabs(b.changePercent);
  });
  return out;
}
