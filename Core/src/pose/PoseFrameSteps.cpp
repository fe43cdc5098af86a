// The steps a posed frame shares, made whole or slab by slab (PoseFrameSteps.h).
#include "PoseFrameSteps.h"

#include "repose/io/AtomicOutput.h"
#include "repose/io/FolderLock.h"
#include "repose/mesh/VolumePrediction.h"
#include "repose/pose/PoseReport.h"
#include "repose/pose/SlicerSceneMrml.h"
#include "repose/raster/PieceOverlap.h"
#include "repose/util/Interrupt.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <optional>
#include <set>

namespace repose::frame {
namespace {

std::string percent(double value, int digits = 1) {
  char text[32];
  std::snprintf(text, sizeof text, "%+.*f %%", digits, value);
  return text;
}

// A label of S by name ("part 7" without one), and the pose group that carries it.
std::string partName(const Volume& parts, int label) {
  const Label* l = parts.labels().find(label);
  return l && !l->name.empty() ? l->name : "part " + std::to_string(label);
}
std::string groupCarrying(const PoseRig& rig, const std::vector<RigidHandle>& handles, int part) {
  for (std::size_t g = 0; g < handles.size() && g < rig.pose().groups.size(); ++g)
    if (std::find(handles[g].parts.begin(), handles[g].parts.end(), part) != handles[g].parts.end())
      return rig.pose().groups[g].name;
  return "";
}

// The guard rail: the volumes the posed mesh predicts, and when the body's breaks its target
// (docs/QUALITY.md: +-0.5 %) or a part's its own (+-1 %), one line naming the part, saying which
// part drags it and what to do.
nlohmann::json predictionReport(const VolumePrediction& p, const PoseRig& rig,
                                const std::vector<RigidHandle>& handles, const Volume& parts,
                                std::string& warning) {
  nlohmann::json out = {{"body_change_percent", p.changePercent()}};
  nlohmann::json perPart = nlohmann::json::array();
  const PartVolumeChange* worstPart = nullptr;  // furthest from its rest volume, in percent
  for (const PartVolumeChange& c : p.parts) {
    perPart.push_back({{"part", partName(parts, c.part)}, {"change_percent", c.changePercent()}});
    if (c.restMm3 > 0 &&
        (!worstPart || std::fabs(c.changePercent()) > std::fabs(worstPart->changePercent())))
      worstPart = &c;
  }
  out["parts"] = perPart;
  const double worstPartChange = worstPart ? worstPart->changePercent() : 0.0;
  out["worst_part_change_percent"] = worstPartChange;
  out["worst_part_by_percent"] = worstPart ? partName(parts, worstPart->part) : std::string();
  const bool bodyMissed = std::fabs(p.changePercent()) > kBodyTargetPercent;
  const bool partMissed = std::fabs(worstPartChange) > kLabelTargetPercent;
  out["met"] = !bodyMissed && !partMissed;
  if (!bodyMissed && !partMissed) return out;
  // The part named: the one changing most in mm^3 when the body misses, else the one furthest
  // from its own volume.
  const int named = bodyMissed && p.worstPart != 0 ? p.worstPart : worstPart->part;
  const auto it = std::find_if(p.parts.begin(), p.parts.end(),
                               [&](const PartVolumeChange& c) { return c.part == named; });
  const std::string worstName = partName(parts, named);
  warning = bodyMissed
                ? "the posed mesh predicts a body volume change of " + percent(p.changePercent()) +
                      " (target within 0.5 %): " + worstName + " " + percent(it->changePercent())
                : "the posed mesh predicts a volume change of " + percent(it->changePercent()) +
                      " for " + worstName + " (target within 1 %)";
  out["worst_part"] = worstName;
  const std::string worstGroup = groupCarrying(rig, handles, named);
  const int draggedBy = named == p.worstPart ? p.draggedBy : 0;
  const std::string dragGroup = draggedBy ? groupCarrying(rig, handles, draggedBy) : "";
  if (draggedBy != 0 && dragGroup != worstGroup) {
    const std::string dragName = partName(parts, draggedBy);
    out["dragged_by"] = dragName;
    warning += ", dragged where it is tied to " + dragName +
               (dragGroup.empty() ? std::string() : " (group \"" + dragGroup + "\")") +
               ": cut the two apart where they touch (automatic separation, or \"separations\" "
               "in the pose) or move them with one group";
  } else {
    warning +=
        ", folded or stretched inside itself: widen its joints (--joint-rings) or pose it "
        "less far";
  }
  out["message"] = warning;
  return out;
}

// report.json's "targets": whether the frame met every target of docs/QUALITY.md, and one line
// for each it missed (the front ends print them; `repose pose` exits with kExitTargetsMissed).
nlohmann::json targetsOf(const nlohmann::json& report) {
  const nlohmann::json& q = report["quality"];
  std::vector<std::string> missed;
  auto row = [&](const char* key) -> const nlohmann::json* {
    return q.contains(key) && !q[key]["met"].get<bool>() ? &q[key] : nullptr;
  };
  if (const nlohmann::json* r = row("body_within_half_percent"))
    missed.push_back("body volume " + percent((*r)["change_percent"].get<double>(), 2) +
                     " (target within 0.5 %)");
  if (const nlohmann::json* r = row("labels_within_1_percent"))
    missed.push_back((*r)["worst_name"].get<std::string>() + " " +
                     percent((*r)["worst_change_beyond_floor_percent"].get<double>(), 2) +
                     " beyond its resampling floor (target within 1 %)");
  if (const nlohmann::json* r = row("bones_rigid"))
    missed.push_back("bone " + (*r)["min_dice_bone"].get<std::string>() + " Dice " +
                     std::to_string((*r)["min_dice"].get<double>()).substr(0, 5) +
                     " (target at least 0.95)");
  if (const nlohmann::json* r = row("no_new_holes"))
    missed.push_back(std::to_string((*r)["new_enclosed_voxels"].get<std::int64_t>()) +
                     " new enclosed background voxels (target none)");
  if (const nlohmann::json* r = row("no_label_lost"))
    missed.push_back(std::to_string((*r)["labels_lost"].get<std::int64_t>()) +
                     " label(s) lost (target none)");
  if (const nlohmann::json* r = row("pieces_apart"))
    missed.push_back(
        (r->contains("most") ? (*r)["most"][0].get<std::string>() + " and " +
                                   (*r)["most"][1].get<std::string>() + " run into each other"
                             : std::string("rigid pieces run into each other")) +
        " in " +
        std::to_string((*r)[r->contains("most") ? "most_voxels" : "voxels"].get<std::int64_t>()) +
        " voxels (target at most 0.1 % of the smaller)");
  if (const nlohmann::json* r = row("prediction_within_targets")) {
    if (std::fabs((*r)["body_change_percent"].get<double>()) > kBodyTargetPercent)
      missed.push_back("predicted body volume " +
                       percent((*r)["body_change_percent"].get<double>(), 2) +
                       " (target within 0.5 %)");
    if (std::fabs((*r)["worst_part_change_percent"].get<double>()) > kLabelTargetPercent)
      missed.push_back("predicted " + (*r)["worst_part"].get<std::string>() + " " +
                       percent((*r)["worst_part_change_percent"].get<double>(), 2) +
                       " (target within 1 %)");
  }
  return {{"met", q["all_met"].get<bool>()}, {"missed", missed}};
}

// The rest voxels of each piece asked for (label of G, body part of S): one pass over the maps.
std::map<PieceId, std::int64_t> pieceVoxels(const Volume& organs, const Volume& parts,
                                            const std::set<PieceId>& pieces) {
  std::map<PieceId, std::int64_t> out;
  if (pieces.empty()) return out;
  std::set<int> labels;
  for (const PieceId& p : pieces) labels.insert(p.label);
  for (std::int64_t v = 0; v < organs.numVoxels(); ++v) {
    const int label = int(organs.valueAsDouble(v));
    if (!labels.count(label)) continue;
    const PieceId id{label, int(parts.valueAsDouble(v))};
    if (pieces.count(id)) ++out[id];
  }
  return out;
}

// Rigid pieces that run into each other on the output grid, by bone (the tissue table's bone
// column: a bone's cortex and marrow are one) or label, in their body parts.
//
// Each pair has an allowance: a tenth of the label target (0.1 %) of the smaller bone's volume,
// at least one rest voxel's (in output voxels: `voxelMm3`). Two bones that touch at rest across a
// joint thinner than a voxel (the elbow's 3 mm of cartilage on 8 mm slices) are two staircases
// of rest voxels; turned against each other about the joint's exact centre their corners still
// share a voxel or two, which no pivot can avoid. Beyond the allowance the collision is a
// missed target naming the two bones.
nlohmann::json collisionReport(const std::vector<PieceOverlap>& meshOverlaps,
                               const std::vector<PieceOverlap>& groupOverlaps, const Volume& organs,
                               const Volume& parts, const TissueTable* tissues, double voxelMm3,
                               std::string& warning) {
  auto pieceName = [&](const PieceId& id) {
    std::string name;
    if (tissues) {
      const auto t = tissues->find(id.label);
      if (t != tissues->end()) name = !t->second.bone.empty() ? t->second.bone : t->second.name;
    }
    if (name.empty()) {
      const Label* l = organs.labels().find(id.label);
      name = l && !l->name.empty() ? l->name : "label " + std::to_string(id.label);
    }
    return name + " (" + partName(parts, id.part) + ")";
  };
  // Each source counts a voxel once per pair of pieces; the two see the same collision where
  // both see it, so a pair takes the larger of its two sums.
  std::map<std::pair<std::string, std::string>, std::int64_t> byName;
  std::set<PieceId> involved;
  for (const std::vector<PieceOverlap>* overlaps : {&meshOverlaps, &groupOverlaps}) {
    std::map<std::pair<std::string, std::string>, std::int64_t> sums;
    for (const PieceOverlap& o : *overlaps) {
      std::string a = pieceName(o.a), b = pieceName(o.b);
      if (a == b) continue;  // a bone's own labels (cortex and marrow) in one part
      if (b < a) std::swap(a, b);
      sums[{a, b}] += o.voxels;
      involved.insert(o.a), involved.insert(o.b);
    }
    for (const auto& [names, n] : sums) byName[names] = std::max(byName[names], n);
  }
  // Each bone's rest voxels, all its pieces of one name together.
  const double restVoxelMm3 = organs.geometry().voxelVolumeMm3();
  std::map<std::string, std::int64_t> boneVoxels;
  for (const auto& [id, n] : pieceVoxels(organs, parts, involved)) boneVoxels[pieceName(id)] += n;
  std::int64_t total = 0, beyond = 0;
  nlohmann::json pairs = nlohmann::json::array();
  // The pair beyond its allowance with most voxels, else the one with most.
  std::pair<std::string, std::string> worst;
  std::pair<bool, std::int64_t> most{false, 0};
  for (const auto& [names, n] : byName) {
    // In output voxels: the staircases' corners are the rest grid's voxels, whatever the output's.
    const double smallerMm3 =
        restVoxelMm3 * double(std::min(boneVoxels[names.first], boneVoxels[names.second]));
    const std::int64_t allowed = std::max<std::int64_t>(
        1, std::int64_t(std::max(restVoxelMm3, kCollisionAllowancePercent / 100 * smallerMm3) /
                        voxelMm3));
    const bool over = n > allowed;
    pairs.push_back({{"a", names.first},
                     {"b", names.second},
                     {"voxels", n},
                     {"volume_ml", double(n) * voxelMm3 / 1000},
                     {"allowed_voxels", allowed},
                     {"beyond_allowance", over}});
    total += n;
    if (over) beyond += n;
    if (std::make_pair(over, n) > most) most = {over, n}, worst = names;
  }
  if (beyond > 0) {
    char ml[32];
    std::snprintf(ml, sizeof ml, "%.2f", double(most.second) * voxelMm3 / 1000);
    warning = "rigid pieces run into each other in " + std::to_string(total) + " voxels; most " +
              worst.first + " and " + worst.second + " (" + std::to_string(most.second) +
              " voxels, " + ml +
              " ml): a turn about a pivot off the joint's own centre (check the skeleton's "
              "joint, or the pose's pivot), or a pose beyond the joint's range";
  }
  nlohmann::json out = {{"voxels", total},
                        {"volume_ml", double(total) * voxelMm3 / 1000},
                        {"beyond_allowance_voxels", beyond},
                        {"pairs", pairs}};
  if (!byName.empty()) out["most"] = {worst.first, worst.second, most.second};
  return out;
}

}  // namespace

nlohmann::json outputFiles(LabelMapFiles files, bool withImage) {
  const bool nifti = files == LabelMapFiles::Nifti || files == LabelMapFiles::Both;
  const bool seg = files == LabelMapFiles::SegNrrd || files == LabelMapFiles::Both;
  const char* ext = nifti ? ".nii.gz" : seg ? ".seg.nrrd" : ".dcm";
  nlohmann::json out = {{"posed_labels", std::string("posed_G") + ext},
                        {"posed_parts", std::string("posed_S") + ext},
                        {"transform", "transform.nrrd"}};
  if (nifti) out["color_tables"] = {"posed_G.ctbl", "posed_S.ctbl"};
  if (seg) out["segmentations"] = {"posed_G.seg.nrrd", "posed_S.seg.nrrd"};
  if (withImage) out["posed_image"] = "posed_image.nii.gz";
  return out;
}

void warn(FrameStart& start, const PoseFrameOptions& options, const std::string& line) {
  if (line.empty()) return;
  start.warnings.push_back(line);
  if (options.warn) options.warn(line);
}

FrameStart startFrame(const PoseRig& rig, std::size_t index, const Volume& organs,
                      const Volume& parts, const PoseFrameOptions& options) {
  if (parts.dims() != organs.dims())
    throw Error("the body-part map is not on the organ map's grid");
  if (options.image && options.image->dims() != organs.dims())
    throw Error("the image is not on the organ map's grid");
  if (!(options.spacingMm >= 0)) throw Error("the output voxel size must be >= 0 mm");
  FrameStart start;
  start.frame = rig.frame(index);
  // Before any voxel: what the posed mesh predicts for the body's volume.
  std::string predictionWarning;
  start.prediction = predictionReport(predictVolumeChange(rig.mesh(), start.frame.deformed), rig,
                                      start.frame.handles, parts, predictionWarning);
  warn(start, options, predictionWarning);
  start.grid = deformedGrid(organs.geometry(), start.frame.deformed, options.spacingMm);
  start.outer = outerFaces(rig.mesh());
  return start;
}

RasterOptions rasterOptions(const FrameStart& start, const Volume& organs, const Volume& parts,
                            const PoseFrameOptions& options) {
  RasterOptions ro;
  ro.threads = options.threads;
  ro.outerFaces = &start.outer;
  ro.restParts = &parts;
  ro.pieceLabels = &organs;
  ro.bonePieces = &options.bonePieces;
  return ro;
}

std::vector<int> rigidLabels(const TransferMesh& mesh, const PoseFrameOptions& options) {
  if (mesh.rigid.empty()) return {};
  std::set<int> labels;
  for (const int label : mesh.rigid)
    if (label > 0) labels.insert(label);
  for (const auto& [label, piece] : options.bonePieces)
    if (label > 0 && piece > 0) labels.insert(label);
  for (const int label : options.bendingPieces) labels.erase(label);
  return {labels.begin(), labels.end()};
}

std::string frameReport(FrameStart& start, const PoseRig& rig, const Volume& organs,
                        const Volume& parts, const PoseFrameOptions& options,
                        const RasterReport& raster, const PocketReport& pockets,
                        const PosedTally& posed, bool withImage) {
  const TransferMesh& mesh = rig.mesh();
  const PoseRig::Frame& frame = start.frame;
  const VolumeGeometry& grid = start.grid;
  // Rigid pieces run into each other: where their tets overlap on the output grid, and where
  // the groups' analytically posed bones do (a bone carried by another part's tets, whose ghosts
  // the tets cannot show); per pair, the larger count.
  std::string collisionWarning;
  const nlohmann::json collisions = collisionReport(
      pieceOverlaps(mesh, frame.deformed, grid), posed.collisions(), organs, parts, options.tissues,
      std::fabs(grid.ijkToRas.block<3, 3>(0, 0).determinant()), collisionWarning);
  warn(start, options, collisionWarning);
  std::set<int> pieceLabels;
  std::int64_t pieceTets = 0;
  for (const int label : mesh.rigid)
    if (label != 0) pieceLabels.insert(label), ++pieceTets;
  for (const auto& [label, piece] : options.bonePieces)
    if (pieceLabels.count(piece)) pieceLabels.insert(label);
  std::vector<std::string> groupNames;
  for (const PoseGroup& g : rig.pose().groups) groupNames.push_back(g.name);
  PoseReportInput ri;
  ri.organs = &organs, ri.parts = &parts;
  ri.posed = &posed;
  ri.mesh = &mesh, ri.tetMaps = &frame.tetMaps, ri.handles = &frame.handles;
  ri.groupNames = groupNames;
  ri.tissues = options.tissues;
  ri.outlierVertices = rig.deformation().embedding().outliers();
  ri.unreachableVertices = rig.deformation().solver().unconstrainedVertices();
  ri.rigidVertices = rig.influence().rigidVertices();
  if (options.preserveLabelVolumes) ri.labelTargets = &raster.labelTargets;
  const Eigen::Vector3d spacing = grid.spacing();
  const nlohmann::json outputs = outputFiles(options.labelMapFiles, withImage);
  nlohmann::json report = {
      {"pose", rig.pose().name},
      {"frame", frame.name},
      {"outputs", outputs},
      {"grid",
       {{"dims", {grid.dims[0], grid.dims[1], grid.dims[2]}},
        {"spacing_mm", {spacing[0], spacing[1], spacing[2]}}}},
      {"cage_vertices", rig.cage().vertices.rows()},
      {"whole_pieces", {{"labels", pieceLabels}, {"tets", pieceTets}}},
      {"tissue_table", options.tissues ? options.tissueTableName : std::string("none")},
      {"voxels_in_shell", raster.shellVoxels},
      {"label_volumes",
       {{"rounding",
         options.preserveLabelVolumes && raster.roundingSkipped.empty() ? "preserve" : "nearest"},
        {"relabelled_voxels", raster.roundedVoxels}}},
      {"raster_inverted_tets", raster.invertedTets},
      {"pockets",
       {{"filled_voxels", pockets.filled},
        {"kept_cavity_voxels", pockets.keptCavities},
        {"filled", options.fillPockets}}}};
  if (!raster.roundingSkipped.empty())
    report["label_volumes"]["skipped"] = "not rounded: " + raster.roundingSkipped;
  report["predicted"] = start.prediction;
  const VolumeRestorationReport& vr = frame.restoration;
  report["volume_restoration"] = {{"on", rig.volumeRestoration()},
                                  {"free_vertices", vr.freeVertices},
                                  {"parts_held", vr.parts},
                                  {"tissues_held", vr.tissues},
                                  {"rounds", vr.iterations},
                                  {"max_correction_mm", vr.maxCorrectionMm},
                                  {"worst_part_before_percent", vr.worstPartBefore},
                                  {"worst_part_after_percent", vr.worstPartAfter},
                                  {"inverted_tets_before", vr.invertedBefore},
                                  {"inverted_tets_after", vr.invertedAfter},
                                  {"untangled_tets", vr.untangled},
                                  {"untangle_relaxed", vr.relaxedUntangle},
                                  {"untangle_crushed", vr.crushedUntangle},
                                  {"knots_reset", vr.knotsReset},
                                  {"fold_contacts_before", vr.contactsBefore},
                                  {"fold_contacts_after", vr.contactsAfter},
                                  {"deepest_fold_before_mm", vr.deepestContactBeforeMm},
                                  {"deepest_fold_after_mm", vr.deepestContactAfterMm}};
  report["bone_collisions"] = collisions;
  // Groups moved off a joint whose bones the turn drove together (JointClearance.h).
  nlohmann::json cleared = nlohmann::json::array();
  for (const JointClearance::Shift& c : frame.clearances) {
    const std::string group = std::size_t(c.group) < groupNames.size()
                                  ? groupNames[std::size_t(c.group)]
                                  : std::to_string(c.group);
    cleared.push_back({{"joint", c.joint},
                       {"group", group},
                       {"shift_mm", {c.shiftMm.x(), c.shiftMm.y(), c.shiftMm.z()}},
                       {"distance_mm", c.shiftMm.norm()},
                       {"voxels_before", c.voxelsBefore},
                       {"voxels_after", c.voxelsAfter}});
    char line[256];
    std::snprintf(line, sizeof line,
                  "%s: the turn drove the bones together in %lld voxels; \"%s\" moved %.1f mm "
                  "off the joint along its bone (%lld left)",
                  c.joint.c_str(), static_cast<long long>(c.voxelsBefore), group.c_str(),
                  c.shiftMm.norm(), static_cast<long long>(c.voxelsAfter));
    warn(start, options, line);
  }
  report["joint_clearance"] = cleared;
  report.update(nlohmann::json::parse(poseReportJson(ri)));
  // The labels whose rounding did not hold: named, and said (docs/FORMATS.md).
  if (report.contains("label_rounding_missed")) {
    report["label_volumes"]["rounding_missed"] = report["label_rounding_missed"];
    report.erase("label_rounding_missed");
    std::string names;
    for (const nlohmann::json& l : report["label_volumes"]["rounding_missed"])
      names += (names.empty() ? "" : ", ") + l["name"].get<std::string>() + " " +
               percent(l["missed_by_percent"].get<double>(), 2);
    if (!names.empty())
      warn(start, options,
           "the label rounding missed the volume the deformation gives " + names +
               " (where the pose folds the body, overlapping tissue is counted once)");
  }
  // Where the tets inside out are: by the joint nearest each (docs/FORMATS.md).
  nlohmann::json byJoint = nlohmann::json::object();
  for (const auto& [joint, tets] : rig.invertedTetsByJoint(frame.deformed))
    byJoint[joint.empty() ? "body" : joint] = tets;
  report["mesh"]["inverted_tets_by_joint"] = byJoint;
  // The prediction is a target too: a part the posed mesh stretches or squeezes beyond +-1 % is
  // a frame that missed, even where the voxels' rounding hides it.
  report["quality"]["prediction_within_targets"] = {
      {"met", start.prediction["met"]},
      {"body_change_percent", start.prediction["body_change_percent"]},
      {"worst_part", start.prediction["worst_part_by_percent"]},
      {"worst_part_change_percent", start.prediction["worst_part_change_percent"]},
      {"rule",
       "the posed transfer mesh keeps the body within +-0.5% and every body part within +-1%"}};
  // Two rigid pieces running into each other take voxels from one another: beyond the pair's
  // allowance (collisionReport) a missed target naming the two bones (a pivot off the joint's
  // centre, or a pose beyond its range).
  nlohmann::json apart = {
      {"met", collisions["beyond_allowance_voxels"].get<std::int64_t>() == 0},
      {"voxels", collisions["voxels"]},
      {"rule",
       "no two rigid pieces (bones, whole organs) share more than 0.1 % of the smaller's volume "
       "(at least one rest voxel's: two voxel staircases touching at a joint)"}};
  if (collisions.contains("most")) {
    apart["most"] = {collisions["most"][0], collisions["most"][1]};
    apart["most_voxels"] = collisions["most"][2];
  }
  report["quality"]["pieces_apart"] = apart;
  report["quality"]["all_met"] = report["quality"]["all_met"].get<bool>() &&
                                 start.prediction["met"].get<bool>() && apart["met"].get<bool>();
  report["targets"] = targetsOf(report);
  // Folds, parts the cage cannot reach, labels gone (docs/RELIABILITY.md, degenerate geometry).
  auto count = [&](std::int64_t n, const std::string& what) {
    if (n > 0) warn(start, options, std::to_string(n) + " " + what);
  };
  count(report["mesh"]["inverted_tets"].get<std::int64_t>(),
        "tets turned inside out (the pose folds the body there; overlapping tissue is resolved "
        "bone first)");
  count(report["mesh"]["unreachable_vertices_left_at_rest"].get<std::int64_t>(),
        "mesh vertices in parts with no vertex inside the cage, left at rest");
  count(report["labels_lost"].get<std::int64_t>(), "labels vanished from the output");
  report["warnings"] = start.warnings;
  return report.dump();
}

struct FrameFolder::Impl {
  std::optional<FolderLock> lock;
};

FrameFolder::FrameFolder(const std::string& folder, bool lockFolder)
    : impl_(std::make_unique<Impl>()), folder_(folder) {
  namespace fs = std::filesystem;
  dir_ = fs::absolute(fs::path(folder)).lexically_normal();
  if (!dir_.has_filename()) dir_ = dir_.parent_path();  // "OUT/frame/"
  if (!fs::exists(dir_.parent_path())) throw Error(folder + ": its parent folder does not exist");
  // A folder made by this write appears whole (one rename), and a second writer's rename then
  // fails; an existing one is locked first, when asked.
  if (lockFolder && fs::is_directory(dir_)) impl_->lock.emplace(dir_.string());
  // The frame's files are one result: written into a hidden folder beside `folder` and moved in
  // together at the end, so an error, a Cancel or an interrupt never leaves half a frame.
  temp_ = makeTemporaryFolder(dir_.parent_path().string(), folder);
}

FrameFolder::~FrameFolder() {
  std::error_code ignored;
  std::filesystem::remove_all(temp_, ignored);
}

Error FrameFolder::named(const Error& e) const {
  std::string message = e.what();
  const std::string hidden = temp_.string();
  for (std::size_t at; (at = message.find(hidden)) != std::string::npos;)
    message.replace(at, hidden.size(), dir_.string());
  return Error(message);
}

std::string FrameFolder::commit(nlohmann::json report, const FrameWriteOptions& options,
                                bool withImage) {
  namespace fs = std::filesystem;
  const LabelMapFiles files = options.labelMapFiles;
  const bool nifti = files == LabelMapFiles::Nifti || files == LabelMapFiles::Both;
  const bool dcm = files == LabelMapFiles::DicomSeg;
  const fs::path& dir = dir_;
  const fs::path& temp = temp_;
  const std::string& folder = folder_;
  std::string written;
  try {
    // The report names the files this write made, whatever the frame's report said before.
    report["outputs"] = outputFiles(files, withImage);
    if (!options.sceneInputLabels.empty()) {
      // Written as it will lie in `dir`: the frame's files relative to it.
      SlicerSceneFiles scene;
      scene.inputLabels = fs::absolute(options.sceneInputLabels).string();
      // A DICOM SEG is loaded through Slicer's DICOM database, not a scene: not listed.
      if (!dcm)
        scene.posedLabels = (dir / (nifti ? "posed_G.nii.gz" : "posed_G.seg.nrrd")).string();
      if (nifti) scene.colorTable = (dir / "posed_G.ctbl").string();
      scene.transform = (dir / "transform.nrrd").string();
      scene.cage = options.sceneCage;
      scene.transferMesh = options.sceneTransferMesh;
      writeTextFileAtomically((temp / "scene.mrml").string(),
                              formatSlicerScene(scene, dir.string()));
      report["outputs"]["slicer_scene"] = "scene.mrml";
    }
    written = report.dump();
    writeTextFileAtomically((temp / "report.json").string(), report.dump(2) + "\n");
  } catch (const Cancelled&) {
    throw;
  } catch (const Error& e) {
    throw named(e);
  }
  throwIfInterrupted();
  std::error_code ec;
  if (!fs::exists(dir)) {
    // The files on the disk before the folder appears under its name, and the name after (a
    // power cut must not leave a frame folder of empty files; AtomicOutput.h, commitFiles).
    for (fs::directory_iterator it(temp, ec), end; !ec && it != end; it.increment(ec))
      if (it->is_regular_file(ec))
        syncToDisk(it->path().string(), false, (dir / it->path().filename()).string());
    syncToDisk(temp.string(), true, folder);
    fs::rename(temp, dir, ec);
    if (ec) throwFileError(folder, "cannot move the frame into place: " + ec.message());
    syncToDisk(dir.parent_path().empty() ? "." : dir.parent_path().string(), true, folder);
    return written;
  }
  // An existing folder (a re-run): its files are replaced, the report last, and ours that this
  // frame does not write are removed (a report never sits beside another run's files), as one
  // commit that a kill cannot leave half done (commitFiles).
  std::vector<CommitStep> steps;
  for (const char* name : {"posed_G.nii.gz", "posed_G.ctbl", "posed_G.seg.nrrd", "posed_S.nii.gz",
                           "posed_S.ctbl", "posed_S.seg.nrrd", "posed_G.dcm", "posed_S.dcm",
                           "posed_image.nii.gz", "transform.nrrd", "scene.mrml", "report.json"}) {
    if (fs::exists(temp / name))
      steps.push_back({(temp / name).string(), (dir / name).string()});
    else if (fs::exists(dir / name))
      steps.push_back({"", (dir / name).string()});
  }
  commitFiles({temp.string()}, steps, folder);
  return written;
}

}  // namespace repose::frame
