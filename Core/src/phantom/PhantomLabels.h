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
  // The detailed anatomy of `--arms-resting` only: the marrow (spongiosa and medullary cavity)
  // inside the long bones' cortical shells, and blood vessels by body region (as ICRP 110 splits
  // them).
  kHumerusMarrow = 28,
  kRadiusUlnaMarrow = 29,
  kFemurMarrow = 30,
  kTibiaFibulaMarrow = 31,
  kVesselsTrunk = 32,
  kVesselsArms = 33,
  kVesselsLegs = 34,
  // The shoulder girdle's bones (detailed anatomy): both clavicles, both scapulae.
  kClavicle = 35,
  kScapula = 36,
  kOrganCount = 37  // one past the last value
};
constexpr int kBasicOrganCount = 28;  // the labels of the basic anatomy

// Body regions, as ICRP 110 splits skin, muscle, adipose and vessels.
enum class Region { Head, Trunk, Arms, Legs };
Region regionOf(std::uint8_t part);
// The vessel label of a body part's region.
std::uint8_t vesselLabel(std::uint8_t part);

// PhantomLabelling::Coarse's value of an organ label: 1 body, 2 skeleton, 3 brain, 4 lungs,
// 5 liver (0 stays 0).
std::uint8_t coarseLabel(std::uint8_t organ);

// The labels of G: the basic anatomy's 27, or with `detailed` all 36.
LabelTable makeOrganLabels(bool detailed = false);
LabelTable makePartLabels();

}  // namespace repose::phantom
