// The phantom's CT-like image: each tissue of G at a typical Hounsfield value, with a small
// noise that depends only on the voxel's index (so slabs give the same voxels as a whole volume,
// and every run the same file).
#include "PhantomLabels.h"

#include "repose/phantom/Phantom.h"
#include "repose/util/Error.h"

#include <array>

namespace repose {

namespace {

// Typical CT values (HU) of adult tissue; a bone without marrow of its own is the mean of cortex
// and marrow at this scale.
constexpr std::array<std::int16_t, phantom::kOrganCount> kHounsfield = [] {
  std::array<std::int16_t, phantom::kOrganCount> hu{};
  hu[0] = -1000;  // air
  hu[phantom::kSkin] = 20;
  hu[phantom::kFat] = -100;
  hu[phantom::kMuscle] = 45;
  hu[phantom::kSkull] = 1100;
  hu[phantom::kBrain] = 35;
  hu[phantom::kEye] = 10;
  hu[phantom::kVertebrae] = 650;
  hu[phantom::kRibs] = 600;
  hu[phantom::kSternum] = 550;
  hu[phantom::kPelvis] = 650;
  hu[phantom::kHumerus] = 800;
  hu[phantom::kRadiusUlna] = 800;
  hu[phantom::kHandBones] = 700;
  hu[phantom::kFemur] = 850;
  hu[phantom::kTibiaFibula] = 800;
  hu[phantom::kFootBones] = 700;
  hu[phantom::kClavicle] = 700;
  hu[phantom::kScapula] = 650;
  hu[phantom::kLungLeft] = -820;
  hu[phantom::kLungRight] = -820;
  hu[phantom::kHeart] = 40;
  hu[phantom::kLiver] = 60;
  hu[phantom::kKidneyLeft] = 35;
  hu[phantom::kKidneyRight] = 35;
  hu[phantom::kStomach] = 25;
  hu[phantom::kSpleen] = 50;
  hu[phantom::kBladder] = 5;
  hu[phantom::kSmallBowel] = 30;
  hu[phantom::kSpinalCord] = 35;
  for (auto m : {phantom::kHumerusMarrow, phantom::kRadiusUlnaMarrow, phantom::kFemurMarrow,
                 phantom::kTibiaFibulaMarrow})
    hu[m] = 250;  // spongiosa and yellow marrow together
  for (auto v : {phantom::kVesselsTrunk, phantom::kVesselsArms, phantom::kVesselsLegs}) hu[v] = 45;
  return hu;
}();

// Uniform noise in [-12, 12] HU from the voxel index (splitmix64).
std::int16_t noise(std::uint64_t index) {
  std::uint64_t z = index + 0x9e3779b97f4a7c15ull;
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
  z ^= z >> 31;
  return static_cast<std::int16_t>(int(z % 25) - 12);
}

}  // namespace

std::int16_t phantomHounsfield(int organLabel) {
  if (organLabel < 0 || organLabel >= phantom::kOrganCount) return 0;
  return kHounsfield[std::size_t(organLabel)];
}

void syntheticCTVoxels(const std::uint8_t* organs, std::int16_t* ct, std::int64_t count,
                       std::int64_t firstVoxel) {
  for (std::int64_t v = 0; v < count; ++v) {
    const std::uint8_t label = organs[v];
    // Air stays exactly -1000: the background of a posed image is then the same value.
    ct[v] = label == 0
                ? std::int16_t(-1000)
                : std::int16_t(phantomHounsfield(label) + noise(std::uint64_t(firstVoxel + v)));
  }
}

Volume syntheticCT(const Volume& organs) {
  if (organs.scalarType() != ScalarType::UInt8)
    throw Error("synthetic CT: the phantom's organ map is uint8");
  Volume ct(organs.geometry(), ScalarType::Int16);
  syntheticCTVoxels(organs.data<std::uint8_t>(), ct.data<std::int16_t>(), organs.numVoxels(), 0);
  return ct;
}

}  // namespace repose
