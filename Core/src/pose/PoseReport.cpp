#include "repose/pose/PoseReport.h"

#include <nlohmann/json.hpp>

#include "repose/util/Error.h"
#include "repose/volume/LabelStatistics.h"

#include <Eigen/SVD>

#include <algorithm>
#include <cmath>
#include <map>
#include <optional>
#include <set>
#include <type_traits>

namespace repose {
namespace {

using nlohmann::json;

constexpr double kRoundingSlackPercent = 0.5;

double quantile(std::vector<double> v, double q) {
  if (v.empty()) return 0;
  const std::size_t k = std::min(v.size() - 1, std::size_t(q * double(v.size() - 1) + 0.5));
  std::nth_element(v.begin(), v.begin() + std::ptrdiff_t(k), v.end());
  return v[k];
}

}  // namespace

// Per label of G: the voxels (of the output grid) that moving each group's parts rigidly with
// nearest-neighbour sampling gives, summed over the groups — the change resampling alone makes,
// which no deformation can beat (a thin vessel turned on a thick-slice grid). Empty when some
// body part is carried by no group of parts (cage-vertex groups): the floor is then unknown.
static std::map<int, std::int64_t> floorCounts(const PoseReportInput& in,
                                               const std::vector<GroupDiceCounts>& groups) {
  std::map<int, std::int64_t> out;
  std::set<int> carried;
  for (const RigidHandle& h : *in.handles) carried.insert(h.parts.begin(), h.parts.end());
  for (const LabelCount& c : countLabels(*in.parts))
    if (c.layer == 0 && !carried.count(c.value)) return {};
  for (const GroupDiceCounts& g : groups)
    for (const auto& [label, n] : g.expected) out[label] += n;
  return out;
}

static json makePoseReport(const PoseReportInput& in) {
  json report;
  // The posed maps' counts: the caller's tally (a frame made slab by slab), else one over the
  // whole posed maps.
  std::optional<PosedTally> own;
  const PosedTally* tally = in.posed;
  if (!tally) {
    own.emplace(*in.organs, *in.parts, in.handles, in.posedOrgans->geometry());
    own->addWhole(*in.posedOrgans, *in.posedParts);
    tally = &*own;
  }
  if (!tally->complete()) throw Error("pose report: the posed maps' tally is not complete");
  // Each group's parts moved rigidly, voxel by voxel: the bones' reference and the floors.
  std::vector<GroupDiceCounts> groupCounts = tally->groups();
  const std::map<int, std::int64_t> floors =
      in.handles ? floorCounts(in, groupCounts) : std::map<int, std::int64_t>{};
  const double outVoxelMm3 = tally->grid().voxelVolumeMm3();
  // Per label: volume, and mass where the tissue table knows the label.
  std::map<int, std::pair<LabelCount, LabelCount>> counts;
  for (const LabelCount& c : countLabels(*in.organs))
    if (c.layer == 0) counts[c.value].first = c;
  for (const auto& [value, voxels] : tally->labelVoxels())
    counts[value].second = {0, value, voxels, double(voxels) * outVoxelMm3};
  json labels = json::array();
  double bodyBefore = 0, bodyAfter = 0, massBefore = 0, massAfter = 0;
  bool massKnown = in.tissues != nullptr;
  double worstChange = 0, worstBeyond = 0, worstFloor = 0;
  int worstLabel = 0, lost = 0;
  json roundingMissed = json::array();  // labels of >= 1000 voxels whose rounding did not hold
  for (const auto& [value, c] : counts) {
    const Label* l = in.organs->labels().find(value);
    // G's own label table names the label; without one (an ICRP phantom's bare IDs), the tissue
    // table does.
    std::string name = l ? l->name : "";
    if (name.empty() && in.tissues) {
      const auto t = in.tissues->find(value);
      if (t != in.tissues->end()) name = t->second.name;
    }
    const double before = c.first.volumeMm3, after = c.second.volumeMm3;
    const double change = before > 0 ? 100 * (after / before - 1) : 0;
    json row = {{"value", value},
                {"name", name},
                {"voxels_before", c.first.voxels},
                {"voxels_after", c.second.voxels},
                {"volume_before_ml", before / 1000},
                {"volume_after_ml", after / 1000},
                {"change_percent", change}};
    // The change beyond what resampling alone makes (docs/QUALITY.md): the nearest-neighbour
    // floor, reported for every label; a label rounded to its volume has none left, so its
    // change itself is held to the target.
    double floor = 0;
    const bool rounded = in.labelTargets && in.labelTargets->count(value);
    if (!floors.empty() && before > 0) {
      const auto it = floors.find(value);
      const double nearest =
          100 * (double(it == floors.end() ? 0 : it->second) * outVoxelMm3 / before - 1);
      row["resampling_floor_percent"] = nearest;
      if (!rounded) floor = nearest;
    }
    if (rounded && before > 0) {
      // Whether the rounding held: the final count within the label's floor (at least a voxel)
      // of the volume the deformation gives it. Where tissue folded over it (a crease's overlap
      // resolved bone first) or its border candidates ran out, it did not, and the label is
      // named, not reported as rounded.
      const double target = in.labelTargets->at(value);
      const double missedBy = target > 0 ? 100 * (double(c.second.voxels) / target - 1) : 0;
      const double nearest = row.contains("resampling_floor_percent")
                                 ? std::fabs(row["resampling_floor_percent"].get<double>())
                                 : 0.0;
      // At least half the label target (0.5 %) and a voxel: on coarse grids the greedy choice
      // stops short of a label's volume when no border voxel lowers the misfit further (0.1-0.3 %
      // on 8 mm slices); a fold's loss is more (muscle -0.8 % under arms raised 160 degrees).
      const double tolerance =
          std::max({nearest, kRoundingSlackPercent, target > 0 ? 100 / target : 100.0});
      const bool held = std::fabs(missedBy) <= tolerance;
      row["rounded"] = held;
      row["deformation_change_percent"] = 100 * (target * outVoxelMm3 / before - 1);
      row["rounding"] = {{"target_voxels", target},
                         {"missed_by_percent", missedBy},
                         {"tolerance_percent", tolerance},
                         {"held", held}};
      if (!held && c.first.voxels >= 1000)
        roundingMissed.push_back({{"value", value},
                                  {"name", name},
                                  {"voxels_after", c.second.voxels},
                                  {"target_voxels", target},
                                  {"missed_by_percent", missedBy},
                                  {"tolerance_percent", tolerance}});
    }
    if (row.contains("resampling_floor_percent") || rounded)
      row["change_beyond_floor_percent"] = change - floor;
    bodyBefore += before, bodyAfter += after;
    lost += c.first.voxels > 0 && c.second.voxels == 0;
    if (c.first.voxels >= 1000 && std::fabs(change - floor) > std::fabs(worstBeyond))
      worstBeyond = change - floor, worstChange = change, worstFloor = floor, worstLabel = value;
    if (in.tissues) {
      const auto t = in.tissues->find(value);
      if (t == in.tissues->end()) {
        massKnown = false;
      } else {
        const double rho = t->second.densityKgM3 * 1e-6;  // g per mm^3
        row["mass_before_g"] = before * rho;
        row["mass_after_g"] = after * rho;
        massBefore += before * rho, massAfter += after * rho;
      }
    }
    labels.push_back(row);
  }
  report["labels"] = labels;
  // The soft labels of >= 1000 voxels whose count missed the volume the deformation gives them by
  // more than their floor (frameReport puts them under label_volumes and warns).
  if (in.labelTargets) report["label_rounding_missed"] = roundingMissed;
  report["labels_lost"] = lost;
  json body = {{"volume_before_ml", bodyBefore / 1000},
               {"volume_after_ml", bodyAfter / 1000},
               {"volume_change_percent", bodyBefore > 0 ? 100 * (bodyAfter / bodyBefore - 1) : 0}};
  if (in.tissues && massKnown) {
    body["mass_before_kg"] = massBefore / 1000;
    body["mass_after_kg"] = massAfter / 1000;
    body["mass_change_percent"] = massBefore > 0 ? 100 * (massAfter / massBefore - 1) : 0;
  }
  report["body"] = body;

  // Per tet: conformal distortion (largest over smallest singular value of B_t) and volume
  // change (det B_t - 1), as distributions.
  std::vector<double> distortion, volumeChange;
  int inverted = 0;
  for (const Eigen::Matrix3d& B : *in.tetMaps) {
    const Eigen::Vector3d s = Eigen::JacobiSVD<Eigen::Matrix3d>(B).singularValues();
    const double det = B.determinant();
    inverted += det <= 0;
    distortion.push_back(s[2] > 0 ? s[0] / s[2] : std::numeric_limits<double>::infinity());
    volumeChange.push_back(det - 1);
  }
  const std::vector<double> edges{1.0, 1.05, 1.1, 1.25, 1.5, 2.0, 3.0, 5.0};
  json histogram = json::array();
  for (std::size_t b = 0; b < edges.size(); ++b) {
    const double lo = edges[b], hi = b + 1 < edges.size() ? edges[b + 1] : 1e300;
    const auto n = std::count_if(distortion.begin(), distortion.end(),
                                 [&](double d) { return d >= lo && d < hi; });
    histogram.push_back(
        {{"from", lo}, {"to", b + 1 < edges.size() ? json(hi) : json("inf")}, {"tets", n}});
  }
  report["distortion"] = {{"measure", "singular value ratio of B_t (1: conformal)"},
                          {"median", quantile(distortion, 0.5)},
                          {"p95", quantile(distortion, 0.95)},
                          {"p99", quantile(distortion, 0.99)},
                          {"max", quantile(distortion, 1.0)},
                          {"histogram", histogram}};
  report["tet_volume_change"] = {{"measure", "det B_t - 1"},
                                 {"min", quantile(volumeChange, 0.0)},
                                 {"p01", quantile(volumeChange, 0.01)},
                                 {"median", quantile(volumeChange, 0.5)},
                                 {"p99", quantile(volumeChange, 0.99)},
                                 {"max", quantile(volumeChange, 1.0)}};
  report["mesh"] = {{"vertices", in.mesh->vertices.rows()},
                    {"tets", in.mesh->tets.rows()},
                    {"outlier_vertices", in.outlierVertices},
                    {"unreachable_vertices_left_at_rest", in.unreachableVertices},
                    {"vertices_moving_rigidly_with_a_group", in.rigidVertices},
                    {"inverted_tets", inverted}};

  // Bones: each bone (all its rigid labels together: cortex, spongiosa, marrow) within each
  // group's body parts against its posed copy.
  json rigid = json::array();
  double minDice = 1;
  std::string minDiceBone;
  if (in.tissues && in.handles) {
    std::map<std::string, std::vector<int>> bones;
    for (const auto& [value, tissue] : *in.tissues)
      if (tissue.rigid) bones[tissue.boneName()].push_back(value);
    for (const auto& [bone, labels] : bones)
      for (std::size_t g = 0; g < in.handles->size(); ++g) {
        GroupDiceCounts& c = groupCounts[g];
        std::int64_t restVoxels = 0, both = 0, posed = 0, expected = 0;
        bool present = false;
        for (const int value : labels) {
          if (!c.rest.count(value)) continue;
          present = true;
          restVoxels += c.rest[value], both += c.both[value];
          posed += c.posed[value], expected += c.expected[value];
        }
        if (!present) continue;
        const double dice = posed + expected > 0 ? double(2 * both) / double(posed + expected) : 1;
        const bool checked = restVoxels >= 1000;
        if (checked && dice < minDice) minDice = dice, minDiceBone = bone;
        rigid.push_back({{"bone", bone},
                         {"labels", labels},
                         {"group", in.groupNames[g]},
                         {"voxels", restVoxels},
                         {"dice", dice},
                         {"checked", checked}});
      }
  }
  report["rigid_tissues"] = rigid;

  const std::int64_t holesBefore = countEnclosedBackground(*in.organs),
                     holesAfter = tally->enclosedBackground();
  report["holes"] = {{"enclosed_background_voxels_before", holesBefore},
                     {"enclosed_background_voxels_after", holesAfter}};

  const double bodyChange = report["body"]["volume_change_percent"].get<double>();
  json quality = {{"labels_within_1_percent",
                   {{"met", std::fabs(worstBeyond) <= 1.0},
                    {"worst_label", worstLabel},
                    {"worst_name",
                     [&] {
                       for (const json& row : labels)
                         if (row["value"] == worstLabel) return row["name"].get<std::string>();
                       return std::string();
                     }()},
                    {"worst_change_percent", worstChange},
                    // The floor taken off: 0 for a label rounded to its volume.
                    {"worst_resampling_floor_percent", worstFloor},
                    {"worst_change_beyond_floor_percent", worstBeyond},
                    {"rule",
                     "every label with >= 1000 voxels keeps its volume within +-1% beyond its "
                     "resampling floor"}}},
                  {"body_within_half_percent",
                   {{"met", std::fabs(bodyChange) <= 0.5},
                    {"change_percent", bodyChange},
                    {"rule", "whole-body volume within +-0.5%"}}},
                  {"no_new_holes",
                   {{"met", holesAfter <= holesBefore},
                    {"new_enclosed_voxels", std::max<std::int64_t>(0, holesAfter - holesBefore)}}},
                  {"no_label_lost", {{"met", lost == 0}, {"labels_lost", lost}}}};
  if (in.tissues)
    quality["bones_rigid"] = {{"met", minDice >= 0.95},
                              {"min_dice", minDice},
                              {"min_dice_bone", minDiceBone},
                              {"rule",
                               "each bone (all its rigid labels) of >= 1000 voxels in a group: "
                               "Dice >= 0.95 with its analytically posed copy"}};
  bool all = true;
  for (const auto& [name, q] : quality.items()) all = all && q["met"].get<bool>();
  quality["all_met"] = all;
  report["quality"] = quality;
  return report;
}

std::string poseReportJson(const PoseReportInput& in) {
  return makePoseReport(in).dump();
}

bool tissueTableCovers(const TissueTable& table, const LabelTable& labels) {
  for (const Label& l : labels.labels()) {
    const auto it = table.find(l.value);
    if (it == table.end() || it->second.name != l.name) return false;
  }
  return true;
}

}  // namespace repose
