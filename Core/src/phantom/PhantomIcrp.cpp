#include "PhantomIcrp.h"

#include "PhantomLabels.h"

#include "repose/util/Error.h"

namespace repose::phantom {
namespace {

// ICRP 110 organ IDs (ICRP Publication 110, Annex A; ../shared/labels/icrp110_organs.csv).
namespace id {
constexpr std::uint8_t kVessels[4] = {9, 10, 11, 12};  // head, trunk, arms, legs
constexpr std::uint8_t kMuscle[4] = {106, 107, 108, 109};
constexpr std::uint8_t kAdipose[4] = {116, 117, 118, 119};  // "residual tissue"
constexpr std::uint8_t kSkin[4] = {122, 123, 124, 125};
// Cortical, spongiosa, medullary cavity.
constexpr std::uint8_t kHumerusUpper[3] = {13, 14, 15}, kHumerusLower[3] = {16, 17, 18};
constexpr std::uint8_t kForearm[3] = {19, 20, 21};
constexpr std::uint8_t kFemurUpper[3] = {28, 29, 30}, kFemurLower[3] = {31, 32, 33};
constexpr std::uint8_t kTibia[3] = {34, 35, 36};
constexpr std::uint8_t kHand = 22, kFoot = 37, kCranium = 26, kPelvis = 41, kRibs = 43;
constexpr std::uint8_t kClavicles = 24, kScapulae = 45;  // cortical (the phantom's are solid)
constexpr std::uint8_t kCervical = 47, kThoracic = 49, kLumbar = 51, kSacrum = 53, kSternum = 55;
constexpr std::uint8_t kBrain = 61, kEyeBulbLeft = 67, kEyeBulbRight = 69;
constexpr std::uint8_t kStomachWall = 72, kSmallIntestineWall = 74, kHeartWall = 87;
constexpr std::uint8_t kKidneyLeftCortex = 89, kKidneyRightCortex = 92, kLiver = 95;
constexpr std::uint8_t kLungLeft = 97, kLungRight = 99, kSpinalCord = 126, kSpleen = 127;
constexpr std::uint8_t kBladderWall = 137;
}  // namespace id

int regionIndex(std::uint8_t part) {
  return static_cast<int>(regionOf(part));  // Head, Trunk, Arms, Legs
}

int sideOf(std::uint8_t part) {  // 0 left, 1 right
  return (part >= kPartUpperArmLeft && part <= kPartHandLeft) ||
                 (part >= kPartThighLeft && part <= kPartFootLeft)
             ? 0
             : 1;
}

const Joint& jointNamed(const BodyModel& m, const std::string& name) {
  for (const Joint& j : m.joints)
    if (j.name == name) return j;
  throw Error("phantom: no joint named " + name);
}

}  // namespace

double IcrpLabeller::Axis::fraction(const Eigen::Vector3d& p) const {
  const Eigen::Vector3d d = to - from;
  return (p - from).dot(d) / d.squaredNorm();
}

IcrpLabeller::IcrpLabeller(const BodyModel& m) {
  for (int side = 0; side < 2; ++side) {
    const std::string s = side == 0 ? "_left" : "_right";
    auto at = [&](const char* joint) { return jointNamed(m, joint + s).ras; };
    humerus_[side] = {at("shoulder"), at("elbow")};
    forearm_[side] = {at("elbow"), at("wrist")};
    femur_[side] = {at("hip"), at("knee")};
    tibia_[side] = {at("knee"), at("ankle")};
  }
}

std::uint8_t IcrpLabeller::label(std::uint8_t organ, std::uint8_t part,
                                 const Eigen::Vector3d& p) const {
  const int region = regionIndex(part), side = sideOf(part);
  // Marrow is spongiosa within a fifth of the bone's length from either end, medullary cavity
  // along the shaft between.
  auto tissue = [](double f, bool marrow) { return !marrow ? 0 : (f < 0.2 || f > 0.8 ? 1 : 2); };
  switch (organ) {
    case 0:
      return 0;
    case kSkin:
      return id::kSkin[region];
    case kFat:
      return id::kAdipose[region];
    case kMuscle:
      return id::kMuscle[region];
    case kVesselsTrunk:
    case kVesselsArms:
    case kVesselsLegs:
      return id::kVessels[region];
    case kHumerus:
    case kHumerusMarrow: {
      const double f = humerus_[side].fraction(p);
      const auto& ids = f < 0.5 ? id::kHumerusUpper : id::kHumerusLower;
      return ids[tissue(f, organ == kHumerusMarrow)];
    }
    case kRadiusUlna:
    case kRadiusUlnaMarrow:
      return id::kForearm[tissue(forearm_[side].fraction(p), organ == kRadiusUlnaMarrow)];
    case kFemur:
    case kFemurMarrow: {
      const double f = femur_[side].fraction(p);
      const auto& ids = f < 0.5 ? id::kFemurUpper : id::kFemurLower;
      return ids[tissue(f, organ == kFemurMarrow)];
    }
    case kTibiaFibula:
    case kTibiaFibulaMarrow:
      return id::kTibia[tissue(tibia_[side].fraction(p), organ == kTibiaFibulaMarrow)];
    case kHandBones:
      return id::kHand;
    case kFootBones:
      return id::kFoot;
    case kSkull:
      return id::kCranium;
    case kPelvis:
      return id::kPelvis;
    case kRibs:
      return id::kRibs;
    case kClavicle:
      return id::kClavicles;
    case kScapula:
      return id::kScapulae;
    case kSternum:
      return id::kSternum;
    // Levels by height on the phantom's spine (T1 at z = 1000 mm). The sacrum reaches up to the
    // lumbosacral disc (747-758 mm, detailed anatomy), as ICRP's does to L5/S1: split lower (at
    // 725 mm, the bone under the disc labelled lumbar) the rig put the lumbosacral joint 30 mm
    // below the disc, in bone, and sitting's pelvic tilt ran the sacrum into the lumbar spine
    // (22 voxels, -1.02 % on the ICRP adult male's grid).
    case kVertebrae:
      return p.z() >= 1000  ? id::kCervical
             : p.z() >= 860 ? id::kThoracic
             : p.z() >= 752 ? id::kLumbar
                            : id::kSacrum;
    case kBrain:
      return id::kBrain;
    case kEye:
      return p.x() < 0 ? id::kEyeBulbLeft : id::kEyeBulbRight;  // RAS: the left is -x
    case kLungLeft:
      return id::kLungLeft;
    case kLungRight:
      return id::kLungRight;
    case kHeart:
      return id::kHeartWall;
    case kLiver:
      return id::kLiver;
    case kKidneyLeft:
      return id::kKidneyLeftCortex;
    case kKidneyRight:
      return id::kKidneyRightCortex;
    case kStomach:
      return id::kStomachWall;
    case kSpleen:
      return id::kSpleen;
    case kBladder:
      return id::kBladderWall;
    case kSmallBowel:
      return id::kSmallIntestineWall;
    case kSpinalCord:
      return id::kSpinalCord;
    default:
      throw Error("phantom: no ICRP 110 ID for organ label " + std::to_string(organ));
  }
}

}  // namespace repose::phantom
