// Names and colours of the phantom's organ labels (G) and body parts (S). Names follow
// TotalSegmentator's snake_case; colours are close to 3D Slicer's GenericAnatomyColors.
#include "PhantomLabels.h"

#include "repose/phantom/Phantom.h"

namespace repose::phantom {

namespace {

void add(LabelTable& table, int value, const char* name, int r, int g, int b) {
  Label label;
  label.value = value;
  label.name = name;
  label.color = {r / 255.0, g / 255.0, b / 255.0};
  table.set(label);
}

}  // namespace

Region regionOf(std::uint8_t part) {
  switch (part) {
    case kPartHead:
      return Region::Head;
    case kPartUpperArmLeft:
    case kPartForearmLeft:
    case kPartHandLeft:
    case kPartUpperArmRight:
    case kPartForearmRight:
    case kPartHandRight:
      return Region::Arms;
    case kPartThighLeft:
    case kPartShankLeft:
    case kPartFootLeft:
    case kPartThighRight:
    case kPartShankRight:
    case kPartFootRight:
      return Region::Legs;
    default:
      return Region::Trunk;
  }
}

std::uint8_t vesselLabel(std::uint8_t part) {
  switch (regionOf(part)) {
    case Region::Arms:
      return kVesselsArms;
    case Region::Legs:
      return kVesselsLegs;
    default:
      return kVesselsTrunk;
  }
}

LabelTable makeOrganLabels(bool detailed) {
  LabelTable t;
  add(t, kSkin, "skin", 177, 122, 101);
  add(t, kFat, "subcutaneous_fat", 235, 225, 60);
  add(t, kMuscle, "muscle", 192, 104, 88);
  add(t, kSkull, "skull", 241, 214, 145);
  add(t, kBrain, "brain", 250, 250, 225);
  add(t, kEye, "eye", 194, 195, 164);
  add(t, kVertebrae, "vertebrae", 241, 213, 144);
  add(t, kRibs, "ribs", 226, 202, 134);
  add(t, kSternum, "sternum", 244, 217, 154);
  add(t, kPelvis, "pelvis", 220, 194, 130);
  add(t, kHumerus, "humerus", 229, 204, 134);
  add(t, kRadiusUlna, "radius_ulna", 235, 210, 150);
  add(t, kHandBones, "hand_bones", 246, 222, 160);
  add(t, kFemur, "femur", 212, 188, 120);
  add(t, kTibiaFibula, "tibia_fibula", 238, 206, 140);
  add(t, kFootBones, "foot_bones", 250, 226, 170);
  add(t, kLungLeft, "lung_left", 197, 165, 145);
  add(t, kLungRight, "lung_right", 172, 138, 120);
  add(t, kHeart, "heart", 206, 110, 84);
  add(t, kLiver, "liver", 221, 130, 101);
  add(t, kKidneyLeft, "kidney_left", 185, 102, 83);
  add(t, kKidneyRight, "kidney_right", 160, 85, 70);
  add(t, kStomach, "stomach", 216, 132, 105);
  add(t, kSpleen, "spleen", 157, 108, 162);
  add(t, kBladder, "urinary_bladder", 222, 154, 132);
  add(t, kSmallBowel, "small_bowel", 205, 167, 142);
  add(t, kSpinalCord, "spinal_cord", 200, 160, 240);
  if (!detailed) return t;
  add(t, kHumerusMarrow, "humerus_marrow", 196, 138, 90);
  add(t, kRadiusUlnaMarrow, "radius_ulna_marrow", 200, 146, 96);
  add(t, kFemurMarrow, "femur_marrow", 188, 132, 84);
  add(t, kTibiaFibulaMarrow, "tibia_fibula_marrow", 204, 150, 100);
  add(t, kVesselsTrunk, "blood_vessels_trunk", 200, 40, 40);
  add(t, kVesselsArms, "blood_vessels_arms", 216, 60, 60);
  add(t, kVesselsLegs, "blood_vessels_legs", 180, 30, 50);
  add(t, kClavicle, "clavicle", 232, 220, 184);
  add(t, kScapula, "scapula", 224, 210, 170);
  return t;
}

LabelTable makePartLabels() {
  LabelTable t;
  add(t, kPartHead, "head", 250, 210, 160);
  add(t, kPartTorso, "torso", 128, 174, 128);
  add(t, kPartUpperArmLeft, "upper_arm_left", 80, 120, 230);
  add(t, kPartForearmLeft, "forearm_left", 110, 170, 250);
  add(t, kPartHandLeft, "hand_left", 160, 210, 255);
  add(t, kPartUpperArmRight, "upper_arm_right", 230, 90, 80);
  add(t, kPartForearmRight, "forearm_right", 250, 140, 110);
  add(t, kPartHandRight, "hand_right", 255, 190, 160);
  add(t, kPartThighLeft, "thigh_left", 60, 160, 150);
  add(t, kPartShankLeft, "shank_left", 90, 200, 180);
  add(t, kPartFootLeft, "foot_left", 150, 230, 210);
  add(t, kPartThighRight, "thigh_right", 200, 150, 40);
  add(t, kPartShankRight, "shank_right", 230, 190, 70);
  add(t, kPartFootRight, "foot_right", 250, 225, 130);
  return t;
}

std::uint8_t coarseLabel(std::uint8_t organ) {
  switch (organ) {
    case 0:
      return 0;
    case kSkull:
    case kVertebrae:
    case kRibs:
    case kSternum:
    case kPelvis:
    case kHumerus:
    case kRadiusUlna:
    case kHandBones:
    case kFemur:
    case kTibiaFibula:
    case kFootBones:
    case kHumerusMarrow:
    case kRadiusUlnaMarrow:
    case kFemurMarrow:
    case kTibiaFibulaMarrow:
    case kClavicle:
    case kScapula:
      return 2;
    case kBrain:
      return 3;
    case kLungLeft:
    case kLungRight:
      return 4;
    case kLiver:
      return 5;
    default:
      return 1;
  }
}

}  // namespace repose::phantom
