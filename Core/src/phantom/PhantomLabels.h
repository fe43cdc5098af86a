// The organ label values of the phantom's map G, and the label tables (names, colours) of G
// and S. The values are stable: tests, pose files and downstream users rely on them.
#pragma once

#include "repose/volume/LabelTable.h"

#include <cstdint>

namespace repose::phantom {

// Left and right bones share a label (S tells the side); paired organs have one label each.
enum Organ : std::uint8_t {
  kSkin = 1,
  kFat = 2,  // subcutaneous fat
  kMuscle = 3,
  kSkull = 4,
  kBrain = 5,
  kEye = 6,
  kVertebrae = 7,
  kRibs = 8,
  kSternum = 9,
  kPelvis = 10,
  kHumerus = 11,
  kRadiusUlna = 12,
  kHandBones = 13,
  kFemur = 14,
  kTibiaFibula = 15,
  kFootBones = 16,
  kLungLeft = 17,
  kLungRight = 18,
  kHeart = 19,
  kLiver = 20,
  kKidneyLeft = 21,
  kKidneyRight = 22,
  kStomach = 23,
  kSpleen = 24,
  kBladder = 25,
  kSmallBowel = 26,
  kSpinalCord = 27,
  kOrganCount = 28  // one past the last value
};

LabelTable makeOrganLabels();
LabelTable makePartLabels();

}  // namespace repose::phantom
