// rigBody: bones, body frame, joints, parts, joint radii, tissue table and the report, in order.
#include "repose/rig/Rig.h"

#include "RigInternal.h"
#include "repose/io/AtomicOutput.h"
#include "repose/io/VolumeIO.h"
#include "repose/util/Error.h"
#include "repose/volume/LabelStatistics.h"

#include <nlohmann/json.hpp>

#include <Eigen/LU>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <fstream>

namespace repose {

using rig::V;

namespace {
// Whether G names any soft tissue of the body's wall (skin, fat, muscle, ICRP's residual tissue,
// a body mask): without one, an organ segmentation's bones float in unlabelled space.
bool labelsSoftTissue(const LabelConvention& convention) {
  for (const auto& [value, role] : convention.roles) {
    if (role.outline) return true;
    std::string name = role.name;
    std::transform(name.begin(), name.end(), name.begin(),
                   [](unsigned char c) { return char(std::tolower(c)); });
    for (const char* word : {"skin", "fat", "adipose", "muscle", "residual", "body"})
      if (name.find(word) != std::string::npos) return true;
  }
  return false;
}
}  // namespace

RigResult rigBody(const Volume& organs, const RigOptions& options) {
  const std::string& source = options.source;
  if (organs.layers() != 1)
    throw Error(source + ": a segmentation with overlapping layers cannot be rigged (flatten it)");
  organs.geometry().requireOrthogonalAxes(source);
  RigResult out;
  reportProgress(options.progress, 0.0, "rig: labels");
  out.convention = labelConvention(organs, options.labels, source);
  const rig::Grid grid(organs.geometry());
  // A skeleton in one label says nothing of the body around it: without an outline (a body,
  // skin, fat or muscle label, or the scan) there would be bones alone to pose.
  const bool skeletonLabel =
      std::any_of(out.convention.roles.begin(), out.convention.roles.end(),
                  [](const auto& r) { return r.second.bone == BoneKind::Skeleton; });
  if (skeletonLabel && !options.image && !labelsSoftTissue(out.convention))
    throw Error(source +
                ": a skeleton label but no body outline (no body, skin, fat or muscle label): "
                "give the scan it was segmented from (--image), or a map with the body");
  reportProgress(options.progress, 0.1, "rig: bones");
  const rig::Bones bones = rig::findBones(organs, out.convention, grid, source);
  if (bones.byKind.empty())
    throw Error(source + ": no bones found under the " + out.convention.name +
                " convention (give --labels, or a CSV naming the bone labels)");
  bool limb = false;
  for (const int side : {-1, 1})
    limb = limb || bones.find(BoneKind::Humerus, side) || bones.find(BoneKind::Femur, side);
  if (!limb) throw Error(source + ": no humerus or femur found: nothing to rig beyond the torso");
  out.warnings = bones.frame.warnings;
  // A limb bone the scan cuts (a chest CT through the humeral heads): its end may be the cut,
  // not the joint's surface, and a joint fitted to it is a guess.
  for (const auto& [key, bone] : bones.byKind) {
    if (bone.side == 0) continue;
    const bool cut = std::any_of(bone.voxels.begin(), bone.voxels.end(), [&](std::int64_t v) {
      const std::int64_t ijk[3] = {v % grid.dims[0], (v / grid.dims[0]) % grid.dims[1],
                                   v / (grid.dims[0] * grid.dims[1])};
      for (int a = 0; a < 3; ++a)
        if (ijk[a] == 0 || ijk[a] == grid.dims[a] - 1) return true;
      return false;
    });
    if (cut)
      out.warnings.push_back(std::string("the scan's edge cuts the ") +
                             (bone.side < 0 ? "left " : "right ") + boneKindName(bone.kind) +
                             ": a joint fitted to its cut end is a guess");
  }
  out.warnings.insert(out.warnings.end(), out.convention.notes.begin(), out.convention.notes.end());

  reportProgress(options.progress, 0.3, "rig: joints");
  std::vector<rig::FittedJoint> joints = rig::fitJoints(bones, out.missing);
  reportProgress(options.progress, 0.4, "rig: body parts");
  rig::PartStats stats;
  std::vector<std::uint8_t> outline;
  std::string outlineHow;
  if (options.image) {
    try {
      outline = rig::bodyOutline(*options.image, organs, grid, outlineHow);
    } catch (const Error& e) {
      throw Error(options.imageSource + ": " + e.what());
    }
  } else if (!labelsSoftTissue(out.convention)) {
    out.warnings.push_back(
        "G labels no skin, fat or muscle: S holds only its labelled structures, and the tissue "
        "between them is not posed; give the scan it was segmented from (--image) for the body's "
        "outline, or a segmentation of the body");
  }
  out.parts = rig::assignParts(organs, out.convention, bones, joints, grid, options.threads, stats,
                               options.image ? &outline : nullptr);
  rig::fitDistalJointsFromOutline(out.parts, organs, out.convention, bones, joints, grid,
                                  out.missing);
  if (stats.unreached > 0)
    out.warnings.push_back(std::to_string(stats.unreached) +
                           " body voxels are joined to no bone (a separate piece): put in the "
                           "torso");
  reportProgress(options.progress, 0.9, "rig: joints' reach");

  const LabelTable names = rig::rigPartLabels();
  auto partName = [&](int v) { return names.find(v) ? names.find(v)->name : std::string(); };
  const V up = bones.frame.superior, ant = bones.frame.anterior;
  for (const rig::FittedJoint& j : joints) {
    SkeletonJoint s;
    s.name = j.name;
    const std::string sfx = j.side < 0 ? "_left" : "_right";
    s.parent = j.kind == JointKind::Elbow      ? "shoulder" + sfx
               : j.kind == JointKind::Wrist    ? "elbow" + sfx
               : j.kind == JointKind::Knee     ? "hip" + sfx
               : j.kind == JointKind::Ankle    ? "knee" + sfx
               : j.kind == JointKind::Shoulder ? "sternoclavicular" + sfx
               : j.kind == JointKind::Hip      ? std::string("lumbosacral")
                                               : "";
    if (!s.parent.empty() && !std::any_of(joints.begin(), joints.end(),
                                          [&](const auto& o) { return o.name == s.parent; }))
      s.parent.clear();
    s.centre = j.centre;
    s.axes = jointAxes(j.kind, j.distal, ant, up, j.side, j.palmar);
    if (j.flexion) s.axes[0].second = *j.flexion;  // the condyles' own line
    s.parts = {partName(j.parts[0]), partName(j.parts[1])};
    s.radiusMm = rig::jointRadius(out.parts, j, grid);
    // Where the joint's bones came from: labelled, or split from one skeleton label.
    s.method = bones.split > 0 ? j.method + " (bones split from the skeleton label)" : j.method;
    s.fitRmsMm = j.rms;
    out.skeleton.joints.push_back(s);
  }

  for (const auto& [value, r] : out.convention.roles) {
    Tissue t;
    t.name = r.name;
    t.densityKgM3 = r.densityKgM3;
    t.rigid = r.rigid;
    t.bone = r.rigid ? r.boneName : "";
    out.tissues[value] = t;
  }

  nlohmann::json bonesJson = nlohmann::json::array();
  for (const auto& [key, b] : bones.byKind)
    bonesJson.push_back({{"bone", boneKindName(b.kind)},
                         {"side", b.side < 0   ? "left"
                                  : b.side > 0 ? "right"
                                               : "axial"},
                         {"voxels", b.voxels.size()},
                         {"length_mm", b.length}});
  nlohmann::json partsJson = nlohmann::json::array();
  {
    std::vector<std::int64_t> count(rig::kPartPelvis + 1, 0);
    const std::uint8_t* s = out.parts.data<std::uint8_t>();
    for (std::int64_t i = 0; i < out.parts.numVoxels(); ++i)
      ++count[s[i] <= rig::kPartPelvis ? s[i] : 0];
    const double ml = std::fabs(organs.geometry().ijkToRas.block<3, 3>(0, 0).determinant()) / 1000;
    for (int v = 1; v <= rig::kPartPelvis; ++v)
      if (count[std::size_t(v)] > 0)
        partsJson.push_back({{"part", partName(v)},
                             {"voxels", count[std::size_t(v)]},
                             {"volume_ml", double(count[std::size_t(v)]) * ml}});
  }
  nlohmann::json unknownJson = nlohmann::json::array();
  for (const int v : out.convention.unknown) {
    const auto r = out.convention.roles.find(v);
    unknownJson.push_back(
        {{"label", v},
         {"name", r != out.convention.roles.end() ? r->second.name : ""},
         {"taken_as", "soft tissue"},
         {"density_kg_m3", r != out.convention.roles.end() ? r->second.densityKgM3 : 0.0}});
  }
  nlohmann::json jointsJson = nlohmann::json::parse(skeletonToJson(out.skeleton))["joints"];
  nlohmann::json report = {
      {"input", source},
      {"convention", out.convention.name},
      {"detection", out.convention.detection},
      {"unknown_labels", unknownJson},
      {"body_frame",
       {{"superior", {up.x(), up.y(), up.z()}},
        {"anterior", {ant.x(), ant.y(), ant.z()}},
        {"midline_x_mm", bones.frame.midlineX}}},
      {"bones", bonesJson},
      {"skeleton_split", bones.split > 0
                             ? nlohmann::json{{"pieces", bones.split}, {"notes", bones.splitNotes}}
                             : nlohmann::json()},
      {"joints", jointsJson},
      {"missing", out.missing},
      {"warnings", out.warnings},
      {"parts", partsJson},
      {"body_outline", options.image
                           ? nlohmann::json{{"image", options.imageSource}, {"method", outlineHow}}
                           : nlohmann::json()},
      {"unreached_voxels", stats.unreached}};
  out.reportJson = report.dump();
  out.skeleton.source = "";
  reportProgress(options.progress, 1.0, "rig: done");
  return out;
}

void writeRigFolder(const RigResult& rig, const std::string& folder, const std::string& input) {
  namespace fs = std::filesystem;
  const fs::path dir = fs::absolute(folder);
  if (!fs::exists(dir.parent_path())) throw Error(folder + ": its parent folder does not exist");
  if (fs::exists(dir) && !fs::is_directory(dir))
    throw Error(folder + ": exists and is not a folder");
  fs::create_directories(dir);
  for (const char* name : {"S.nii.gz", "skeleton.json", "tissues.csv", "rig.json"})
    refuseOverwritingInput(input, (dir / name).string());
  AtomicOutput parts((dir / "S.nii.gz").string()), skeleton((dir / "skeleton.json").string()),
      tissues((dir / "tissues.csv").string()), report((dir / "rig.json").string());
  writeVolume(rig.parts, parts.tempPath());
  auto text = [](const std::string& path, const std::string& content) {
    std::ofstream f(path, std::ios::binary);
    f << content;
    if (!f.flush()) throwFileError(path, "write failed (disk full?)");
  };
  const nlohmann::json made = {
      {"made_by", "repose rig"}, {"input", input}, {"convention", rig.convention.name}};
  text(skeleton.tempPath(), skeletonToJson(rig.skeleton, made.dump()));
  text(tissues.tempPath(),
       tissueTableCsv(rig.tissues, "Tissues of " + input + " (" + rig.convention.name +
                                       " convention), made by repose rig.\nrigid = 1 for bone "
                                       "(a pose moves it as a rigid copy); bone names the bone a "
                                       "label is part of."));
  text(report.tempPath(), nlohmann::json::parse(rig.reportJson).dump(2) + "\n");
  commitTogether({&parts, &skeleton, &tissues, &report});
}

std::string nameBodyPartsByRigConvention(Volume& parts, const std::string& source) {
  if (!parts.labels().empty() || !isIntegerType(parts.scalarType())) return "";
  const LabelTable names = rig::rigPartLabels();
  const std::vector<LabelCount> present = countLabels(parts);
  if (present.empty()) return "";
  for (const LabelCount& c : present)
    if (c.layer != 0 || !names.find(c.value)) return "";
  parts.labels() = names;
  return source +
         ": no part names in the file; its values are named as `repose rig` names them (1 head, "
         "2 torso, 3 upper_arm_left, ... 14 foot_right, 15-16 shoulder_girdle_left/right, 17 "
         "pelvis)";
}

}  // namespace repose
