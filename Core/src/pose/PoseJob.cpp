#include "repose/pose/PoseJob.h"

#include "repose/pose/EncasedTissue.h"

#include "repose/pose/SceneFolder.h"
#include "repose/raster/RestTissues.h"
#include "repose/util/Error.h"
#include "repose/volume/LabelStatistics.h"

#include <nlohmann/json.hpp>

#include <cstdlib>
#include <filesystem>
#include <map>

namespace repose {
namespace {

std::vector<int> presentLabels(const Volume& organs) {
  std::vector<int> out;
  for (const LabelCount& c : countLabels(organs))
    if (c.layer == 0 && c.value != 0 && c.voxels > 0) out.push_back(c.value);
  return out;
}

}  // namespace

std::vector<int> rigidLabelsOf(const TissueTable& table) {
  std::vector<int> out;
  for (const auto& [label, tissue] : table)
    if (tissue.rigid) out.push_back(label);
  return out;
}

TissueChoice chooseTissues(const Volume& organs, const std::string& explicitPath,
                           const std::string& partsPath) {
  TissueChoice out;
  if (!explicitPath.empty()) {
    out.table = readTissueTable(explicitPath);
    out.name = explicitPath;
    return out;
  }
  const std::vector<int> present = presentLabels(organs);
  const std::string beside = findTissuesBeside(partsPath);
  if (!beside.empty()) {
    TissueTable t = readTissueTable(beside);
    std::string missing;
    int count = 0;
    for (const int label : present)
      if (!t.count(label) && count++ < 5)
        missing += (missing.empty() ? "" : ", ") + std::to_string(label);
    if (count == 0) {
      out.table = std::move(t);
      out.name = beside;
      return out;
    }
    out.warning = beside + " lacks " + std::to_string(count) + " label(s) of G (" + missing +
                  (count > 5 ? ", ..." : "") + "): not used (was it made for another G?)";
  }
  // The phantom's table only for the phantom's labels: every label present named as it names it.
  TissueTable phantom = phantomTissueTable();
  bool phantomLabels = !present.empty();
  for (const int label : present) {
    const Label* l = organs.labels().find(label);
    const auto it = phantom.find(label);
    phantomLabels = phantomLabels && l && it != phantom.end() && it->second.name == l->name;
  }
  if (phantomLabels) {
    out.table = std::move(phantom);
    out.name = "phantom default";
  }
  return out;
}

std::optional<Skeleton> skeletonFor(const std::string& partsPath, const std::string& explicitPath) {
  if (!explicitPath.empty()) return readSkeleton(explicitPath);
  const std::string beside = findSkeletonBeside(partsPath);
  if (beside.empty()) return std::nullopt;
  return readSkeleton(beside);
}

void resolveJointsWith(Pose& pose, const Skeleton* skeleton, const std::string& partsPath) {
  if (!poseNamesJoints(pose)) return;
  if (!skeleton) {
    const std::string folder = std::filesystem::path(partsPath).has_parent_path()
                                   ? std::filesystem::path(partsPath).parent_path().string()
                                   : std::string(".");
    throw Error("pose " + pose.name + " names joints, but there is no skeleton.json beside " +
                (partsPath.empty() ? std::string("S") : partsPath) + " (in " + folder +
                "; `repose rig` writes one, or give --skeleton)");
  }
  resolvePoseJoints(pose, *skeleton);
}

PoseSeparations poseSeparations(const Pose& pose, const Volume& parts, const Skeleton* skeleton,
                                bool automatic, const RigSettings& settings) {
  PoseSeparations out;
  out.all = resolveSeparations(pose, parts.labels());
  out.automaticOn = automatic;
  if (automatic) {
    CageOptions cage;
    cage.dilateMm = settings.dilateMm;
    ContactOptions co;
    co.reachMm = contactReachMm(cage, parts);
    co.threads = settings.threads;
    out.automatic = findContactSeparations(parts, pose, skeleton, co);
    for (const LimbSeparation& s : out.automatic.separations()) out.all.push_back(s);
  }
  return out;
}

std::vector<JointRefinement> jointRefinements(const Pose& pose, const Volume& parts,
                                              const Skeleton* skeleton) {
  std::vector<JointRefinement> out;
  if (!skeleton) return out;
  std::map<std::string, int> group;
  for (const auto& [label, g] : groupOfParts(pose, parts))
    if (const Label* l = parts.labels().find(label)) group[l->name] = g;
  const double voxel = parts.geometry().spacing().maxCoeff();
  for (const SkeletonJoint& j : skeleton->joints) {
    const auto a = group.find(j.parts[0]), b = group.find(j.parts[1]);
    if (a == group.end() || b == group.end() || a->second == b->second || !(j.radiusMm > 0))
      continue;
    if (pose.groups[std::size_t(a->second)].fixed && pose.groups[std::size_t(b->second)].fixed)
      continue;
    JointRefinement r;
    r.centre = j.centre;
    r.radiusMm = 1.5 * j.radiusMm;
    // A sixth of the radius (at least two voxels): the bend's inner side is compressed several
    // times over its angle, and the volume restoration needs free vertices there; with a third
    // the thick slices' arm vessels lost 1.25 % at the 90-degree elbow (docs/QUALITY.md).
    r.sizeMm = std::max(2 * voxel, j.radiusMm / 6);
    out.push_back(r);
  }
  return out;
}

std::vector<BendJoint> bendJoints(const Skeleton* skeleton, const LabelTable& partLabels) {
  std::vector<BendJoint> out;
  if (!skeleton) return out;
  auto label = [&](const std::string& name) {
    for (const Label& l : partLabels.labels())
      if (l.name == name) return l.value;
    return 0;
  };
  auto kind = [](const std::string& name) { return name.substr(0, name.find('_')); };
  for (const SkeletonJoint& j : skeleton->joints) {
    // The girdle and the pelvis meet the trunk all around, not across a joint plane a hinge bend
    // could follow: their transitions are the blend's, relaxed by the volume restoration.
    if (kind(j.name) == "sternoclavicular" || kind(j.name) == "lumbosacral") continue;
    const Eigen::Vector3d* distal = j.axis("rotation");
    BendJoint b;
    b.name = j.name;
    b.centre = j.centre;
    b.proximalPart = label(j.parts[0]);
    b.distalPart = label(j.parts[1]);
    b.radiusMm = j.radiusMm;
    if (!distal || b.proximalPart == 0 || b.distalPart == 0 || !(b.radiusMm > 0)) continue;
    b.distal = *distal;
    // The part above a girdle or a pelvis (the torso) bends with it where they move together:
    // the armpit beside a shoulder, the groin beside a hip.
    for (const SkeletonJoint& above : skeleton->joints)
      if (above.parts[1] == j.parts[0] && !above.parts[0].empty())
        if (const int also = label(above.parts[0])) b.proximalAlso.push_back(also);
    // A limb's joint (elbow, wrist, knee, ankle) bends over 2 radii on each side, so the bend
    // fades into the solved blend along the limbs, where the two agree; over the outer 30 % of
    // 1.5 radii the fade also crossed the joint plane and crushed soft tets there (docs/QUALITY.md,
    // "What closed the thick slices"). A root joint's trunk side bends only near the joint and
    // its limb side over 1.5 radii: bent wider, a raised arm pulls the chest wall along.
    if (kind(j.name) == "shoulder" || kind(j.name) == "hip" || j.parts[0] == "torso")
      b.proximalReach = 0.5, b.distalReach = 1.5;
    else
      b.proximalReach = b.distalReach = 2.0;
    out.push_back(b);
  }
  return out;
}

std::string PoseSeparations::reportJson() const {
  nlohmann::json manual = nlohmann::json::array();
  const std::size_t manualCount = all.size() - automatic.made.size() * (automaticOn ? 1 : 0);
  for (std::size_t i = 0; i < manualCount; ++i)
    manual.push_back({{"labels", {all[i].labelA, all[i].labelB}},
                      {"region", nlohmann::json::parse(regionToJson(all[i].region))}});
  nlohmann::json doc = {{"manual", manual}, {"automatic", automaticOn}};
  if (automaticOn) doc.update(nlohmann::json::parse(automatic.json()));
  return doc.dump();
}

PoseJob::PoseJob(Pose pose, const Volume& organs, const Volume& parts, PoseJobRequest request,
                 const Volume* image)
    : organs_(&organs), parts_(&parts), request_(std::move(request)), pose_(std::move(pose)) {
  const std::string partsName = request_.partsPath.empty() ? "S" : request_.partsPath;
  auto sameGrid = [&](const Volume& v) {
    return v.dims() == organs.dims() &&
           v.geometry().ijkToRas.isApprox(organs.geometry().ijkToRas, 1e-6);
  };
  if (!sameGrid(parts)) throw Error(partsName + ": not on the grid of " + request_.organsName);
  if (image && image->dims() != organs.dims())
    throw Error(request_.imageName + ": not on the grid of " + request_.organsName);
  // The skeleton: given, else the file named, else the one beside S.
  if (request_.skeleton)
    skeleton_ = request_.skeleton;
  else
    skeleton_ = skeletonFor(request_.partsPath, request_.skeletonPath);
  // Turns beyond a joint's range of motion (the names are still there to say which).
  for (const std::string& w : jointRangeWarnings(pose_)) warnings_.push_back(w);
  resolveJointsWith(pose_, skeleton_ ? &*skeleton_ : nullptr, request_.partsPath);
  // The rhythms of the girdles and the pelvis, where the skeleton has their joints.
  if (skeleton_) rhythms_ = PoseRhythms(*skeleton_, parts.labels());
  userPose_ = pose_;
  pose_ = rhythms_.apply(userPose_, &rhythmNotes_);
  // The tissue table: given, else chooseTissues' order; its rigid labels move whole.
  if (request_.tissues) {
    tissues_.table = request_.tissues;
    tissues_.name = request_.tissuesName;
  } else if (request_.tissuesAuto || !request_.tissuesPath.empty()) {
    tissues_ = chooseTissues(organs, request_.tissuesPath, request_.partsPath);
  }
  if (!tissues_.warning.empty()) warnings_.push_back(tissues_.warning);
  settings_ = request_.settings;
  if (tissues_.table) {
    settings_.rigidLabels = rigidLabelsOf(*tissues_.table);
    settings_.bonePieces = bonePiecesOf(*tissues_.table);
  }
  jointRings_ = request_.jointRings >= 0 ? request_.jointRings : pose_.jointRings;
  const Skeleton* skeleton = skeleton_ ? &*skeleton_ : nullptr;
  separations_ = poseSeparations(pose_, parts, skeleton, request_.autoSeparate, settings_);
  for (const std::string& why : separations_.automatic.skipped)
    warnings_.push_back("not separated: " + why);
  settings_.refineJoints = jointRefinements(pose_, parts, skeleton);
  // The rig's pieces that bend at joints (PoseRig.h: labelsMovingWhole), found as it finds them.
  if (settings_.wholeOrgans) bendingPieces_ = labelsEncasedInBone(organs, settings_.rigidLabels);
}

std::string PoseJob::sceneKey(const std::string& partsPath) const {
  return sceneRigKey(partsPath.empty() ? request_.partsPath : partsPath, separations_.all,
                     settings_);
}

RigGeometry PoseJob::buildGeometry(const ProgressFn& progress) const {
  return buildRigGeometry(*parts_, separations_.all, settings_, progress, organs_);
}

std::unique_ptr<PoseRig> PoseJob::makeRig(RigGeometry geometry, int threads) const {
  return makeRig(std::move(geometry), userPose_, threads);
}

std::unique_ptr<PoseRig> PoseJob::makeRig(RigGeometry geometry, const Pose& pose,
                                          int threads) const {
  auto rig = std::make_unique<PoseRig>(
      std::move(geometry), rhythms_.apply(pose), parts_->labels(), threads, jointRings_,
      bendJoints(skeleton_ ? &*skeleton_ : nullptr, parts_->labels()));
  rig->setRhythms(pose, rhythms_);
  rig->setVolumeRestoration(request_.volumeRestoration);
  // Bones a joint's turn drives into each other are parted (JointClearance.h): every rigid label,
  // a bone's other labels too.
  if (skeleton_ && organs_ && parts_) {
    std::vector<int> rigid = settings_.rigidLabels;
    for (const auto& [label, piece] : settings_.bonePieces) rigid.push_back(label);
    rig->setJointClearance(JointClearance(rig->pose(), *skeleton_, *organs_, *parts_, rigid));
  }
  if (skeleton_) {
    std::vector<std::pair<int, int>> jointed;
    auto label = [&](const std::string& name) {
      for (const Label& l : parts_->labels().labels())
        if (l.name == name) return l.value;
      return 0;
    };
    for (const SkeletonJoint& j : skeleton_->joints)
      if (const int a = label(j.parts[0]), b = label(j.parts[1]); a > 0 && b > 0)
        jointed.emplace_back(a, b);
    rig->setJointedParts(std::move(jointed));
    std::vector<JointSite> sites;
    for (const SkeletonJoint& j : skeleton_->joints) sites.push_back({j.name, j.centre});
    rig->setJointSites(std::move(sites));
  }
  if (request_.volumeRestoration) {
    // Counted as the label rounding's rest scan counts them, the shell beyond the outer faces
    // included (raster/RestTissues.h), with the frame's body-part map.
    RasterOptions ro;
    ro.threads = threads;
    ro.restParts = parts_;
    rig->setTetTissues(restTetTissues(rig->mesh(), *organs_, ro));
  }
  return rig;
}

PoseFrameOptions PoseJob::frameOptions() const {
  PoseFrameOptions o;
  o.tissues = tissues_.table ? &*tissues_.table : nullptr;
  o.tissueTableName = tissues_.name;
  o.threads = settings_.threads;
  o.bonePieces = settings_.bonePieces;
  o.bendingPieces = bendingPieces_;
  return o;
}

std::string PoseJob::completeReport(const std::string& reportJson, bool sceneReused,
                                    const PoseRig& rig) const {
  nlohmann::json report = nlohmann::json::parse(reportJson);
  report["input"] = request_.organsName;
  if (!request_.organsNotes.empty()) report["input_notes"] = request_.organsNotes;
  report["scene_reused"] = sceneReused;
  const CageDeformation& d = rig.deformation();
  report["green_coordinates"] = {{"read", d.coordinatesRead()},
                                 {"note", d.coordinatesNote()},
                                 {"bytes", d.coefficientBytes()}};
  // The cage the rig has, and what the ladder tried before it (a scene of an older version
  // recorded none: the asked setting then).
  report["cage"] = nlohmann::json::parse(rig.cageChoice().json());
  report["joint_rings"] = jointRings_;
  report["separations"] = nlohmann::json::parse(separations_.reportJson());
  report["skeleton"] = skeleton_ ? nlohmann::json(skeleton_->source) : nlohmann::json();
  report["rhythms"] = {{"scapulohumeral", userPose_.scapulohumeralRhythm},
                       {"lumbopelvic", userPose_.lumbopelvicRhythm},
                       {"applied", rhythmNotes_}};
  return report.dump();
}

}  // namespace repose
