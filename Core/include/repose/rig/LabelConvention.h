// What the labels of a user's organ map G mean to the rig: which are bones (and which bone), which
// body region a region-split tissue belongs to (ICRP 110 splits skin, muscle, adipose and vessels
// into head, trunk, arms and legs), and each label's name, mass density and rigidity for the
// tissue table. Built-in conventions: the generated phantom, ICRP 110 AF/AM organ IDs,
// TotalSegmentator v2 class names; or a CSV mapping the user's labels to bones.
#pragma once

#include "repose/volume/LabelStatistics.h"
#include "repose/volume/TissueTable.h"
#include "repose/volume/Volume.h"

#include <map>
#include <string>
#include <vector>

namespace repose {

// The bones the rig knows. Each moves with one body part.
enum class BoneKind {
  None,
  Skull,  // cranium; with the mandible and teeth: the head
  Mandible,
  Teeth,
  Spine,  // cervical to sacrum: the torso
  Ribs,
  Sternum,
  Clavicle,
  Scapula,
  Pelvis,
  Humerus,  // upper arm
  Forearm,  // radius and ulna
  Hand,     // carpals, metacarpals, phalanges
  Femur,    // thigh
  Patella,  // with the tibia: the shank (ICRP puts patellae with the tibiae)
  Shank,    // tibia and fibula
  Foot,     // tarsals, metatarsals, phalanges
  Skeleton  // every bone in one label: the rig splits it by geometry (RigSkeletonSplit.cpp)
};
const char* boneKindName(BoneKind kind);

enum class BodyRegion { Unknown, Head, Trunk, Arms, Legs };

struct LabelRole {
  std::string name;
  BoneKind bone = BoneKind::None;
  int side = 0;  // -1 left, +1 right, 0 unknown or midline (sides then come from the geometry)
  BodyRegion region = BodyRegion::Unknown;  // for region-split soft tissue
  bool rigid = false;                       // bone tissue: moves as a rigid copy
  double densityKgM3 = 1050;
  std::string boneName;   // the bone this label is part of ("humerus"), for the tissue table
  bool cervical = false;  // spine labels of the neck (the neck joint is at their top)
  bool outline = false;   // the body's outline (a CSV's `body`, a coarse map's body label)
};

struct LabelConvention {
  std::string name;                // "phantom", "icrp110 (AF)", "totalsegmentator", "FILE.csv"
  std::string detection;           // how it was chosen (for the report)
  std::map<int, LabelRole> roles;  // per label value present in G
  // Labels present in G that the convention does not know: soft tissue, not rigid, of no body
  // region (a label is never a reason to refuse G); rig.json lists them and notes says so.
  std::vector<int> unknown;
  std::vector<std::string> notes;  // labels it did not know, density sources
};

// `requested`: "auto", "phantom", "icrp110", "totalsegmentator" or a CSV path
// (`label,bone[,side][,name][,density_kg_m3]` with a header; bone one of boneKindName's names,
// side left/right). "auto" takes G for ICRP 110 when nearly all its labels are organ IDs 1-141
// (unnamed, or named as ICRP names them) with the humeri's and femora's among them. Labels a
// convention does not know become soft tissue (LabelConvention::unknown), never an error.
// Throws repose::Error with a one-line message when the convention cannot be told ("auto").
LabelConvention labelConvention(const Volume& organs, const std::string& requested,
                                const std::string& source);

// What a viewer shows of a user's G whose file names or colours not every label (a converted
// ICRP 110 array, a NIfTI without a colour table): every label present in layer 0 gets a name,
// from the file, else `tissues` (when given), else the convention "auto" detects (ICRP 110's
// organ names for its IDs); labels no source names keep their number. Labels without a colour of
// their own get their structure's colour by that name (LabelTable::defaultColor(value, name)),
// marked colorGenerated. Returns one line saying where the names came from, "" when the file
// named every label. Never throws for a G no convention fits: that only leaves the numbers.
// `counts`: countLabels(organs) when the caller has it already (a viewer opening a file), so the
// map is not read again; the convention is told from the same labels.
std::string completeLabelNamesAndColors(Volume& organs, const TissueTable* tissues,
                                        const std::string& source,
                                        const std::vector<LabelCount>* counts = nullptr);

}  // namespace repose
