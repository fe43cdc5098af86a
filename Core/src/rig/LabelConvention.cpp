// The rig's label conventions: the phantom (by name), ICRP 110 (by organ ID), TotalSegmentator v2
// (by class name, from the file's label table), a user's CSV; and "auto", which tells them apart.
#include "repose/rig/LabelConvention.h"

#include "CoarseMap.h"

#include "Icrp110Organs.h"
#include "repose/util/Error.h"
#include "repose/volume/LabelStatistics.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <fstream>
#include <set>
#include <sstream>

namespace repose {
namespace {

// Typical mass densities (kg/m^3) of the IT'IS Foundation tissue properties database, for the
// soft tissues of conventions that carry no densities of their own (TotalSegmentator, a user's
// CSV). A dosimetry study should give its own table (`repose pose --tissues`).
struct Density {
  const char* prefix;
  double kgM3;
};
constexpr Density kTypicalDensities[] = {{"skin", 1109},
                                         {"subcutaneous_fat", 911},
                                         {"torso_fat", 911},
                                         {"fat", 911},
                                         {"skeletal_muscle", 1090},
                                         {"muscle", 1090},
                                         {"gluteus", 1090},
                                         {"iliopsoas", 1090},
                                         {"autochthon", 1090},
                                         {"brain", 1046},
                                         {"spinal_cord", 1075},
                                         {"lung", 394},
                                         {"heart", 1081},
                                         {"atrial_appendage", 1081},
                                         {"liver", 1079},
                                         {"spleen", 1089},
                                         {"kidney", 1066},
                                         {"stomach", 1088},
                                         {"small_bowel", 1030},
                                         {"duodenum", 1030},
                                         {"colon", 1088},
                                         {"urinary_bladder", 1086},
                                         {"prostate", 1045},
                                         {"pancreas", 1087},
                                         {"gallbladder", 1071},
                                         {"adrenal", 1028},
                                         {"esophagus", 1040},
                                         {"trachea", 1080},
                                         {"thyroid", 1050},
                                         {"aorta", 1102},
                                         {"vena", 1050},
                                         {"vein", 1050},
                                         {"artery", 1050},
                                         {"trunk", 1050},
                                         {"intervertebral_disc", 1100},
                                         {"costal_cartilage", 1100},
                                         {"eye", 1050},
                                         {"blood", 1050}};
constexpr double kCorticalBoneKgM3 = 1908;  // IT'IS "Bone (Cortical)"
constexpr double kMarrowKgM3 = 1178;        // IT'IS "Bone (Cancellous)"
constexpr double kSoftTissueKgM3 = 1050;    // when nothing closer is known

double typicalDensity(const std::string& name, bool* known) {
  for (const Density& d : kTypicalDensities)
    if (name.rfind(d.prefix, 0) == 0 ||
        name.find(std::string("_") + d.prefix) != std::string::npos) {
      if (known) *known = true;
      return d.kgM3;
    }
  if (known) *known = false;
  return kSoftTissueKgM3;
}

std::string lower(std::string s) {
  for (char& c : s) c = char(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

bool endsWith(const std::string& s, const std::string& tail) {
  return s.size() >= tail.size() && s.compare(s.size() - tail.size(), tail.size(), tail) == 0;
}

const char* kBoneNames[] = {"none",         "skull",       "mandible", "teeth",   "spine",
                            "ribs",         "sternum",     "clavicle", "scapula", "pelvis",
                            "humerus",      "radius_ulna", "hand",     "femur",   "patella",
                            "tibia_fibula", "foot",        "skeleton"};

BoneKind boneFromName(const std::string& n) {
  for (int k = 0; k < int(sizeof(kBoneNames) / sizeof(*kBoneNames)); ++k)
    if (n == kBoneNames[k]) return BoneKind(k);
  return BoneKind::None;
}

// Layer 0's labels, from the caller's counts when it has them (one pass over the map fewer).
std::vector<int> present(const Volume& organs, const std::vector<LabelCount>* counts = nullptr) {
  std::vector<int> out;
  for (const LabelCount& c : counts ? *counts : countLabels(organs))
    if (c.layer == 0 && c.value != 0 && c.voxels > 0) out.push_back(c.value);
  return out;
}

std::string nameOf(const Volume& organs, int value) {
  const Label* l = organs.labels().find(value);
  return l ? l->name : std::string();
}

// ---- the generated phantom (Resources/Tissues/phantom.csv names) ----
bool phantomRole(const std::string& name, LabelRole& r) {
  static const std::map<std::string, BoneKind> bones = {
      {"skull", BoneKind::Skull},         {"vertebrae", BoneKind::Spine},
      {"ribs", BoneKind::Ribs},           {"sternum", BoneKind::Sternum},
      {"pelvis", BoneKind::Pelvis},       {"humerus", BoneKind::Humerus},
      {"radius_ulna", BoneKind::Forearm}, {"hand_bones", BoneKind::Hand},
      {"femur", BoneKind::Femur},         {"tibia_fibula", BoneKind::Shank},
      {"foot_bones", BoneKind::Foot},     {"clavicle", BoneKind::Clavicle},
      {"scapula", BoneKind::Scapula}};
  std::string bone = name;
  const bool marrow = endsWith(name, "_marrow");
  if (marrow) bone = name.substr(0, name.size() - 7);
  const auto it = bones.find(bone);
  if (it != bones.end()) {
    r.bone = it->second;
    r.rigid = true;
    r.boneName = bone;
    r.densityKgM3 = marrow ? kMarrowKgM3 : kCorticalBoneKgM3;
    return true;
  }
  static const std::map<std::string, BodyRegion> regions = {
      {"blood_vessels_trunk", BodyRegion::Trunk},
      {"blood_vessels_arms", BodyRegion::Arms},
      {"blood_vessels_legs", BodyRegion::Legs}};
  if (regions.count(name)) r.region = regions.at(name);
  static const std::set<std::string> soft = {"skin",
                                             "subcutaneous_fat",
                                             "muscle",
                                             "brain",
                                             "eye",
                                             "lung_left",
                                             "lung_right",
                                             "heart",
                                             "liver",
                                             "kidney_left",
                                             "kidney_right",
                                             "stomach",
                                             "spleen",
                                             "urinary_bladder",
                                             "small_bowel",
                                             "spinal_cord",
                                             "blood_vessels_trunk",
                                             "blood_vessels_arms",
                                             "blood_vessels_legs"};
  if (!soft.count(name)) return false;
  r.densityKgM3 = typicalDensity(name, nullptr);
  return true;
}

// ---- ICRP 110 (organ IDs; regions from the structure names) ----
BoneKind icrpBone(int id) {
  if (id >= 13 && id <= 18) return BoneKind::Humerus;
  if (id >= 19 && id <= 21) return BoneKind::Forearm;
  if (id == 22 || id == 23) return BoneKind::Hand;
  if (id == 24 || id == 25) return BoneKind::Clavicle;
  if (id == 26 || id == 27) return BoneKind::Skull;
  if (id >= 28 && id <= 33) return BoneKind::Femur;
  if (id >= 34 && id <= 36) return BoneKind::Shank;  // tibiae, fibulae and patellae
  if (id == 37 || id == 38) return BoneKind::Foot;
  if (id == 39 || id == 40) return BoneKind::Mandible;
  if (id == 41 || id == 42) return BoneKind::Pelvis;
  if (id == 43 || id == 44) return BoneKind::Ribs;
  if (id == 45 || id == 46) return BoneKind::Scapula;
  if (id >= 47 && id <= 54) return BoneKind::Spine;
  if (id == 55 || id == 56) return BoneKind::Sternum;
  if (id == 128) return BoneKind::Teeth;
  return BoneKind::None;
}

const char* icrpBoneName(int id) {
  static const std::pair<int, const char*> first[] = {{13, "humerus"},
                                                      {19, "radius_ulna"},
                                                      {22, "hand_bones"},
                                                      {24, "clavicles"},
                                                      {26, "cranium"},
                                                      {28, "femur"},
                                                      {34, "tibia_fibula_patella"},
                                                      {37, "foot_bones"},
                                                      {39, "mandible"},
                                                      {41, "pelvis"},
                                                      {43, "ribs"},
                                                      {45, "scapulae"},
                                                      {47, "cervical_spine"},
                                                      {49, "thoracic_spine"},
                                                      {51, "lumbar_spine"},
                                                      {53, "sacrum"},
                                                      {55, "sternum"},
                                                      {57, nullptr}};
  if (id == 128) return "teeth";
  const char* name = nullptr;
  for (const auto& [from, n] : first)
    if (id >= from) name = n;
  return name ? name : "";
}

const rig::IcrpOrgan* icrpOrgan(int id) {
  for (const rig::IcrpOrgan& o : rig::kIcrp110Organs)
    if (o.id == id) return &o;
  return nullptr;
}

// The role of a label no convention knows: soft, not rigid, of no one body region (the rig's
// flood gives each of its voxels the part around it), with the density its name suggests, else
// soft tissue's. Never a reason to refuse G.
LabelRole unknownRole(const Volume& organs, int value) {
  LabelRole r;
  r.name = nameOf(organs, value);
  bool known = false;
  r.densityKgM3 = r.name.empty() ? kSoftTissueKgM3 : typicalDensity(lower(r.name), &known);
  return r;
}

// One warning line listing the labels a convention did not know (at most 8 by number and name).
std::string unknownLabelsNote(const std::vector<std::string>& unknown, const std::string& name) {
  std::string list;
  for (std::size_t i = 0; i < unknown.size() && i < 8; ++i) list += (i ? ", " : "") + unknown[i];
  return std::to_string(unknown.size()) + " label(s) not in the " + name +
         " convention, taken as soft tissue (not rigid, no body region): " + list +
         (unknown.size() > 8 ? ", ..." : "");
}

LabelConvention icrp110(const Volume& organs, const std::vector<int>& labels) {
  // The female phantom has ovaries and a uterus, the male a prostate and testes.
  const std::set<int> has(labels.begin(), labels.end());
  const bool male = has.count(115) || has.count(129) || has.count(130);
  const bool female = has.count(111) || has.count(112) || has.count(139);
  LabelConvention c;
  c.name = std::string("icrp110 (") + (male && !female ? "AM" : "AF") + ")";
  if (!male && !female) c.notes.push_back("no sex-specific organ found: the AF densities are used");
  std::vector<std::string> unknown;
  for (const int v : labels) {
    const rig::IcrpOrgan* organ = icrpOrgan(v);
    if (!organ) {
      // A label the ICRP 110 list does not have (a user's addition, a later release's ID).
      c.roles[v] = unknownRole(organs, v);
      c.unknown.push_back(v);
      const std::string n = nameOf(organs, v);
      unknown.push_back(std::to_string(v) + (n.empty() ? "" : " " + n));
      continue;
    }
    LabelRole r;
    r.name = organ->name;
    r.densityKgM3 = male && !female ? organ->densityAm : organ->densityAf;
    r.bone = icrpBone(v);
    r.rigid = r.bone != BoneKind::None;
    r.boneName = icrpBoneName(v);
    r.cervical = v == 47 || v == 48;
    const std::string n = lower(organ->name);
    if (endsWith(n, ", head")) r.region = BodyRegion::Head;
    if (endsWith(n, ", trunk")) r.region = BodyRegion::Trunk;
    if (endsWith(n, ", arms")) r.region = BodyRegion::Arms;
    if (endsWith(n, ", legs")) r.region = BodyRegion::Legs;
    c.roles[v] = r;
  }
  if (!unknown.empty()) c.notes.push_back(unknownLabelsNote(unknown, "icrp110"));
  return c;
}

// Whether G's labels are ICRP 110 organ IDs: at least 20 labels, unnamed or named as ICRP names
// them, nearly all of them IDs of the list (a real file holds 1-141; a few may be missing, a few
// added), among them the humeri's and femora's.
bool looksLikeIcrp110(const Volume& organs, const std::vector<int>& labels) {
  if (labels.size() < 20) return false;
  std::size_t ids = 0, foreignNames = 0;
  for (const int v : labels) {
    const rig::IcrpOrgan* organ = icrpOrgan(v);
    ids += organ != nullptr;
    const std::string n = nameOf(organs, v);
    if (!n.empty() && !(organ && lower(n) == lower(organ->name))) ++foreignNames;
  }
  const std::size_t extra = labels.size() - ids;
  const std::set<int> has(labels.begin(), labels.end());
  const bool bones = has.count(13) + has.count(16) + has.count(28) + has.count(31) >= 2;
  return bones && foreignNames == 0 && extra <= std::max<std::size_t>(3, labels.size() / 10);
}

// ---- TotalSegmentator v2 (class names of its label table) ----
bool totalSegmentatorRole(const std::string& name, LabelRole& r) {
  int side = 0;
  std::string base = name;
  if (endsWith(name, "_left")) side = -1, base = name.substr(0, name.size() - 5);
  if (endsWith(name, "_right")) side = +1, base = name.substr(0, name.size() - 6);
  static const std::map<std::string, BoneKind> bones = {
      {"skull", BoneKind::Skull},         {"sacrum", BoneKind::Spine},
      {"vertebrae", BoneKind::Spine},     {"sternum", BoneKind::Sternum},
      {"clavicula", BoneKind::Clavicle},  {"scapula", BoneKind::Scapula},
      {"hip", BoneKind::Pelvis},          {"humerus", BoneKind::Humerus},
      {"radius", BoneKind::Forearm},      {"ulna", BoneKind::Forearm},
      {"carpal", BoneKind::Hand},         {"metacarpal", BoneKind::Hand},
      {"phalanges_hand", BoneKind::Hand}, {"femur", BoneKind::Femur},
      {"patella", BoneKind::Patella},     {"tibia", BoneKind::Shank},
      {"fibula", BoneKind::Shank},        {"tarsal", BoneKind::Foot},
      {"metatarsal", BoneKind::Foot},     {"phalanges_feet", BoneKind::Foot}};
  BoneKind bone = BoneKind::None;
  if (bones.count(base)) bone = bones.at(base);
  if (base.rfind("vertebrae_", 0) == 0) bone = BoneKind::Spine;
  if (base.rfind("rib_", 0) == 0 || base == "rib") bone = BoneKind::Ribs;
  if (name.rfind("rib_left_", 0) == 0) side = -1;
  if (name.rfind("rib_right_", 0) == 0) side = +1;
  if (bone != BoneKind::None) {
    r.bone = bone;
    r.side = side;
    r.rigid = true;
    r.boneName =
        base.rfind("vertebrae_", 0) == 0 ? "spine" : (bone == BoneKind::Ribs ? "ribs" : base);
    r.densityKgM3 = kCorticalBoneKgM3;
    r.cervical = base.rfind("vertebrae_C", 0) == 0;
    return true;
  }
  bool known = false;
  r.densityKgM3 = typicalDensity(name, &known);
  return known;
}

// ---- a user's CSV: label,bone[,side][,name][,density_kg_m3] ----
LabelConvention fromCsv(const Volume& organs, const std::string& path,
                        const std::vector<int>& labels) {
  std::ifstream in(path);
  if (!in) throw Error(path + ": cannot open");
  LabelConvention c;
  c.name = path;
  std::vector<std::string> header;
  std::string line;
  int number = 0;
  std::map<int, LabelRole> given;
  while (std::getline(in, line)) {
    ++number;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.empty() || line[0] == '#') continue;
    std::vector<std::string> f;
    std::stringstream row(line);
    for (std::string x; std::getline(row, x, ',');) f.push_back(x);
    const std::string where = path + ":" + std::to_string(number) + ": ";
    if (header.empty()) {
      header = f;
      if (f.size() < 2 || f[0] != "label" || f[1] != "bone")
        throw Error(where + "expected the header label,bone[,side][,name][,density_kg_m3]");
      continue;
    }
    if (f.size() > header.size()) throw Error(where + "more fields than the header");
    LabelRole r;
    int value = 0;
    try {
      std::size_t used = 0;
      value = std::stoi(f[0], &used);
      if (used != f[0].size()) throw std::invalid_argument("label");
    } catch (const std::exception&) {
      throw Error(where + "label must be an integer");
    }
    const std::string bone = f.size() > 1 ? lower(f[1]) : "";
    // "body": the body's outline (soft tissue wherever no other label is), not a bone.
    const bool outline = bone == "body";
    r.bone = boneFromName(bone.empty() || outline ? "none" : bone);
    if (!bone.empty() && bone != "none" && !outline && r.bone == BoneKind::None)
      throw Error(where + "unknown bone \"" + f[1] +
                  "\" (skull, mandible, teeth, spine, ribs, sternum, clavicle, scapula, pelvis, "
                  "humerus, radius_ulna, hand, femur, patella, tibia_fibula, foot, skeleton: "
                  "every bone in one label; body: the body's outline; none)");
    r.rigid = r.bone != BoneKind::None;
    r.boneName = r.rigid ? bone : "";
    r.name = nameOf(organs, value);
    r.outline = outline;
    if (outline && r.name.empty()) r.name = "body";
    for (std::size_t k = 2; k < f.size(); ++k) {
      if (header[k] == "side") {
        const std::string s = lower(f[k]);
        if (s == "left")
          r.side = -1;
        else if (s == "right")
          r.side = +1;
        else if (!s.empty())
          throw Error(where + "side must be left, right or empty");
      } else if (header[k] == "name") {
        if (!f[k].empty()) r.name = f[k];
      } else if (header[k] == "density_kg_m3") {
        try {
          r.densityKgM3 = std::stod(f[k]);
        } catch (const std::exception&) {
          throw Error(where + "density_kg_m3 must be a number");
        }
        if (!(r.densityKgM3 > 0)) throw Error(where + "density_kg_m3 must be positive");
      } else {
        throw Error(where + "unknown column " + header[k]);
      }
    }
    if (r.densityKgM3 == 1050 && !r.rigid) {
      bool known = false;
      const double d = typicalDensity(lower(r.name), &known);
      if (known) r.densityKgM3 = d;
    }
    if (r.rigid && r.densityKgM3 == 1050) r.densityKgM3 = kCorticalBoneKgM3;
    if (!given.emplace(value, r).second)
      throw Error(where + "label " + std::to_string(value) + " given twice");
  }
  if (header.empty()) throw Error(path + ": empty");
  for (const int v : labels) {
    if (given.count(v)) {
      c.roles[v] = given[v];
    } else {
      // The CSV lists the bones (and what else its author chose): the rest is soft tissue.
      c.roles[v] = unknownRole(organs, v);
    }
  }
  return c;
}

int countMatches(const Volume& organs, const std::vector<int>& labels,
                 bool (*role)(const std::string&, LabelRole&), int* bonesFound) {
  int matched = 0, bones = 0;
  for (const int v : labels) {
    LabelRole r;
    if (role(nameOf(organs, v), r)) ++matched, bones += r.bone != BoneKind::None;
  }
  if (bonesFound) *bonesFound = bones;
  return matched;
}

LabelConvention byNames(const Volume& organs, const std::vector<int>& labels,
                        const std::string& name, bool (*role)(const std::string&, LabelRole&)) {
  LabelConvention c;
  c.name = name;
  std::vector<std::string> unknown;
  for (const int v : labels) {
    LabelRole r;
    r.name = nameOf(organs, v);
    if (!role(r.name, r)) {
      unknown.push_back(std::to_string(v) + (r.name.empty() ? "" : " " + r.name));
      r = unknownRole(organs, v);
      c.unknown.push_back(v);
    }
    c.roles[v] = r;
  }
  if (!unknown.empty()) c.notes.push_back(unknownLabelsNote(unknown, name));
  return c;
}

}  // namespace

const char* boneKindName(BoneKind kind) {
  return kBoneNames[int(kind)];
}

namespace {

// A coarse map: its skeleton one rigid label the rig splits into bones, its body the outline,
// the rest soft tissue.
LabelConvention coarseConvention(const Volume& organs, const std::vector<int>& labels,
                                 const rig::CoarseMap& m) {
  LabelConvention c;
  c.name = "coarse (body and skeleton)";
  c.detection = m.how;
  for (const int v : labels) {
    LabelRole r = unknownRole(organs, v);
    if (v == m.skeleton) {
      r.bone = BoneKind::Skeleton;
      r.rigid = true;
      r.boneName = "skeleton";
      r.densityKgM3 = kCorticalBoneKgM3;
      if (r.name.empty()) r.name = "skeleton";
    } else if (v == m.body) {
      r.outline = true;
      if (r.name.empty()) r.name = "body";
    } else {
      c.unknown.push_back(v);
    }
    c.roles[v] = r;
  }
  return c;
}

// labelConvention on the labels present in G (in increasing order), counted by the caller.
LabelConvention conventionOf(const Volume& organs, const std::vector<int>& labels,
                             const std::string& requested, const std::string& source) {
  if (labels.empty()) throw Error(source + ": no labelled voxel, nothing to rig");
  LabelConvention c;
  if (requested == "phantom") {
    c = byNames(organs, labels, "phantom", phantomRole);
    c.detection = "--labels phantom";
  } else if (requested == "totalsegmentator") {
    c = byNames(organs, labels, "totalsegmentator", totalSegmentatorRole);
    c.detection = "--labels totalsegmentator";
  } else if (requested == "icrp110") {
    c = icrp110(organs, labels);
    c.detection = "--labels icrp110";
  } else if (requested == "auto") {
    int phantomBones = 0, tsBones = 0;
    const int phantomNames = countMatches(organs, labels, phantomRole, &phantomBones);
    const int tsNames = countMatches(organs, labels, totalSegmentatorRole, &tsBones);
    const bool icrpValues = looksLikeIcrp110(organs, labels);
    if (phantomBones >= 3 && phantomNames * 2 >= int(labels.size())) {
      c = byNames(organs, labels, "phantom", phantomRole);
      c.detection = "auto: G's label names are the phantom's";
    } else if ((tsBones >= 3 || tsNames >= 5) && tsNames * 2 >= int(labels.size())) {
      // Names alone tell TotalSegmentator (an abdominal MR of its total_mr task names one bone,
      // the vertebrae): whether its bones make a rig is said next, by name.
      c = byNames(organs, labels, "totalsegmentator", totalSegmentatorRole);
      c.detection = "auto: G's label names are TotalSegmentator's";
    } else if (icrpValues) {
      c = icrp110(organs, labels);
      c.detection =
          "auto: labels that are ICRP 110 organ IDs (1-141), with its humerus and femur IDs";
    } else if (const auto coarse = rig::recogniseCoarseMap(organs, labels)) {
      c = coarseConvention(organs, labels, *coarse);
    } else {
      throw Error(
          source + ": cannot tell the label convention (" + std::to_string(labels.size()) +
          " labels; not the phantom's or TotalSegmentator's names, not ICRP 110 IDs 1-141, "
          "not a body and one skeleton label): give --labels phantom|icrp110|totalsegmentator|"
          "FILE.csv (label,bone rows; bone skeleton for a label holding every bone, body for "
          "the body's outline)");
    }
  } else {
    c = fromCsv(organs, requested, labels);
    c.detection = "--labels " + requested;
  }
  for (auto& [v, r] : c.roles)
    if (r.name.empty()) r.name = "label_" + std::to_string(v);
  return c;
}

}  // namespace

LabelConvention labelConvention(const Volume& organs, const std::string& requested,
                                const std::string& source) {
  if (!organs.isLabelMap()) throw Error(source + ": not a label map (float voxels)");
  return conventionOf(organs, present(organs), requested, source);
}

std::string completeLabelNamesAndColors(Volume& organs, const TissueTable* tissues,
                                        const std::string& source,
                                        const std::vector<LabelCount>* counts) {
  if (!organs.isLabelMap()) return "";
  const std::vector<int> values = present(organs, counts);
  std::vector<int> unnamed;
  for (const int v : values)
    if (nameOf(organs, v).empty()) unnamed.push_back(v);
  std::map<int, std::string> names;  // value -> name from the table or the convention
  std::string from;
  if (!unnamed.empty() && tissues) {
    for (const int v : unnamed)
      if (const auto t = tissues->find(v); t != tissues->end() && !t->second.name.empty()) {
        // The table's CSV has no quoting, so its writer turned commas into ';' (ICRP 110's
        // "Humeri, upper half, cortical"): shown with its commas again.
        std::string name = t->second.name;
        std::replace(name.begin(), name.end(), ';', ',');
        names[v] = name;
      }
    from = "the tissue table";
  } else if (!unnamed.empty()) {
    try {
      const LabelConvention c = conventionOf(organs, values, "auto", source);
      for (const int v : unnamed)
        if (const auto r = c.roles.find(v);
            r != c.roles.end() && r->second.name != "label_" + std::to_string(v))
          names[v] = r->second.name;
      from = "the " + c.name + " convention (" + c.detection + ")";
    } catch (const Error&) {
      // No convention fits: the labels keep their numbers.
    }
  }
  LabelTable& table = organs.labels();
  // Colours the file gave stay; the made-up ones are kept apart from every colour already taken
  // (two shades of one class, or two hues, can come out alike): in value order, the first
  // variant at least kMinApart from the others in some channel, as the slice views draw them.
  constexpr double kMinApart = 6.0 / 255;
  std::vector<std::array<double, 3>> taken;
  std::vector<Label> made;
  for (const int v : values) {
    const Label* had = table.find(v);
    Label l = had ? *had : Label{};
    l.value = v;
    if (l.name.empty()) {
      const auto n = names.find(v);
      l.name = n != names.end() ? n->second : std::to_string(v);
    }
    if (had && !had->colorGenerated) {
      taken.push_back(l.color);
      table.set(l);  // `had` is not used after this: set() may move the entries
    } else {
      made.push_back(l);
    }
  }
  auto apart = [&](const std::array<double, 3>& c) {
    double nearest = 1;
    for (const auto& t : taken)
      nearest = std::min(nearest, std::max({std::fabs(c[0] - t[0]), std::fabs(c[1] - t[1]),
                                            std::fabs(c[2] - t[2])}));
    return nearest;
  };
  for (Label& l : made) {
    std::array<double, 3> best = LabelTable::defaultColor(l.value, l.name);
    double bestApart = apart(best);
    for (int variant = 1; variant < 64 && bestApart < kMinApart; ++variant) {
      const std::array<double, 3> c = LabelTable::defaultColor(l.value, l.name, variant);
      if (const double d = apart(c); d > bestApart) best = c, bestApart = d;
    }
    l.color = best;
    l.colorGenerated = true;
    taken.push_back(best);
  }
  for (const Label& l : made) table.set(l);
  if (unnamed.empty()) return "";
  const std::size_t named = names.size();
  return source + ": " + std::to_string(unnamed.size()) + " of " + std::to_string(values.size()) +
         " labels unnamed in the file; " +
         (named > 0 ? std::to_string(named) + " named from " + from
                    : std::string("no label convention or tissue table names them")) +
         (named < unnamed.size() ? ", the rest keep their numbers" : "");
}

}  // namespace repose
