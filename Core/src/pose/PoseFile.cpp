// Reading and writing pose files. Validation is written out by hand, field by field, so every
// message names the field as the JSON schema (docs/pose.schema.json) does; the schema and this
// reader are checked against each other on the pose suite (Testing/Python/test_pose_schema.py).
#include "repose/io/AtomicOutput.h"
#include "repose/pose/Pose.h"
#include "repose/util/Error.h"
#include "repose/util/JsonFields.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <fstream>
#include <limits>
#include <set>
#include <sstream>

namespace repose {
namespace {

using nlohmann::json;

struct Reader : JsonFields {
  const json& object(const json& j, const std::string& field) const {
    if (!j.is_object()) fail(field, "expected an object");
    return j;
  }
  void onlyKeys(const json& j, const std::string& field, std::set<std::string> allowed) const {
    for (const auto& [key, value] : j.items())
      if (!allowed.count(key)) fail(field.empty() ? key : field + "." + key, "unknown field");
  }
  int integer(const json& j, const std::string& field) const {
    if (!j.is_number_integer()) fail(field, "expected an integer");
    // get<int> would wrap 4294967297 to 1 silently; refuse what an int cannot hold.
    const auto wide = j.is_number_unsigned() ? static_cast<long double>(j.get<std::uint64_t>())
                                             : static_cast<long double>(j.get<std::int64_t>());
    if (wide < std::numeric_limits<int>::min() || wide > std::numeric_limits<int>::max())
      fail(field, "integer out of range");
    return j.get<int>();
  }

  Region region(const json& j, const std::string& field) const {
    object(j, field);
    onlyKeys(j, field, {"box", "sphere", "outside_sphere", "everywhere"});
    if (j.size() != 1)
      fail(field, "expected exactly one of box, sphere, outside_sphere, everywhere");
    Region r;
    if (j.contains("everywhere")) {
      if (!j["everywhere"].is_boolean() || !j["everywhere"].get<bool>())
        fail(field + ".everywhere", "expected true");
      r.shape = Region::Shape::Everywhere;
    } else if (j.contains("box")) {
      const json& b = j["box"];
      if (!b.is_array() || b.size() != 6) fail(field + ".box", "expected [x0,y0,z0,x1,y1,z1]");
      for (int c = 0; c < 3; ++c) {
        r.a[c] = number(b[c], field + ".box[" + std::to_string(c) + "]");
        r.b[c] = number(b[c + 3], field + ".box[" + std::to_string(c + 3) + "]");
        if (r.b[c] < r.a[c]) fail(field + ".box", "max below min");
      }
    } else {
      const std::string key = j.contains("sphere") ? "sphere" : "outside_sphere";
      const std::string f = field + "." + key;
      const json& s = j[key];
      if (!s.is_array() || s.size() != 4) fail(f, "expected [x,y,z,radius]");
      r.shape = key == "sphere" ? Region::Shape::Sphere : Region::Shape::OutsideSphere;
      for (int c = 0; c < 3; ++c) r.a[c] = number(s[c], f + "[" + std::to_string(c) + "]");
      r.b.x() = number(s[3], f + "[3]");
      if (r.b.x() <= 0) fail(f + "[3]", "radius must be positive");
    }
    return r;
  }

  PoseSelection selection(const json& j, const std::string& field) const {
    object(j, field);
    onlyKeys(j, field, {"cage_vertices", "region", "parts", "rest"});
    PoseSelection s;
    if (j.empty()) fail(field, "selects nothing (give cage_vertices, region, parts or rest)");
    if (j.contains("cage_vertices")) {
      const json& v = j["cage_vertices"];
      if (!v.is_array() || v.empty()) fail(field + ".cage_vertices", "expected a non-empty array");
      for (std::size_t i = 0; i < v.size(); ++i) {
        const int index = integer(v[i], field + ".cage_vertices[" + std::to_string(i) + "]");
        if (index < 0) fail(field + ".cage_vertices[" + std::to_string(i) + "]", "negative");
        s.cageVertices.push_back(index);
      }
    }
    if (j.contains("region")) s.region = region(j["region"], field + ".region");
    if (j.contains("parts")) {
      const json& v = j["parts"];
      if (!v.is_array() || v.empty()) fail(field + ".parts", "expected a non-empty array");
      for (std::size_t i = 0; i < v.size(); ++i) {
        const std::string f = field + ".parts[" + std::to_string(i) + "]";
        if (v[i].is_string()) {
          s.partNames.push_back(v[i].get<std::string>());
        } else {
          const int label = integer(v[i], f);
          if (label <= 0) fail(f, "a body part is a positive label of S");
          s.parts.push_back(label);
        }
      }
    }
    if (j.contains("rest")) {
      if (!j["rest"].is_boolean() || !j["rest"].get<bool>()) fail(field + ".rest", "expected true");
      if (j.size() != 1) fail(field, "rest cannot be combined with another selection");
      s.rest = true;
    }
    return s;
  }

  // "elbow_left" (a joint) or, for an axis, "elbow_left.flexion" (a joint's axis).
  std::string jointName(const json& j, const std::string& field, bool axis) const {
    const std::string name = string(j, field);
    const auto dot = name.find('.');
    const bool valid =
        !name.empty() && (axis ? dot != std::string::npos && dot > 0 && dot + 1 < name.size() &&
                                     name.find('.', dot + 1) == std::string::npos
                               : dot == std::string::npos);
    if (!valid)
      fail(field, axis ? "expected [x, y, z] or a joint's axis such as \"elbow_left.flexion\""
                       : "expected [x, y, z] or a joint such as \"elbow_left\"");
    return name;
  }

  // A turn's axis: a vector (normalised; not zero) or a joint's axis by name.
  void axisInto(const json& j, const std::string& field, Eigen::Vector3d& axis,
                std::string& name) const {
    if (j.is_string()) {
      name = jointName(j, field, true);
      return;
    }
    const Eigen::Vector3d v = vector3(j, field);
    if (v.norm() < 1e-9) fail(field, "zero vector");
    axis = v.normalized();
    name.clear();
  }

  // A transform's fields over `base` (keyframes change only what they name).
  PoseTransform transform(const json& j, const std::string& field, PoseTransform t) const {
    if (j.contains("rotation")) {
      const std::string f = field.empty() ? "rotation" : field + ".rotation";
      const json& r = object(j["rotation"], f);
      onlyKeys(r, f, {"axis", "angle_deg", "pivot", "then"});
      // Axis and pivot are numbers, or names of the skeleton's joint and axis.
      if (r.contains("axis")) axisInto(r["axis"], f + ".axis", t.axis, t.axisName);
      if (r.contains("angle_deg")) t.angleDeg = number(r["angle_deg"], f + ".angle_deg");
      if (r.contains("pivot")) {
        if (r["pivot"].is_string()) {
          t.pivotJoint = jointName(r["pivot"], f + ".pivot", false);
        } else {
          t.pivot = vector3(r["pivot"], f + ".pivot");
          t.pivotJoint.clear();
        }
      }
      // More turns about the pivot: the list replaces the base's (keyframes give all of them).
      if (r.contains("then")) {
        const json& list = r["then"];
        if (!list.is_array()) fail(f + ".then", "expected an array of turns");
        t.then.clear();
        for (std::size_t i = 0; i < list.size(); ++i) {
          const std::string tf = f + ".then[" + std::to_string(i) + "]";
          const json& turn = object(list[i], tf);
          onlyKeys(turn, tf, {"axis", "angle_deg"});
          if (!turn.contains("axis")) fail(tf + ".axis", "required");
          PoseTurn u;
          axisInto(turn["axis"], tf + ".axis", u.axis, u.axisName);
          if (turn.contains("angle_deg")) u.angleDeg = number(turn["angle_deg"], tf + ".angle_deg");
          t.then.push_back(u);
        }
      }
    }
    if (j.contains("translation"))
      t.translation =
          vector3(j["translation"], field.empty() ? "translation" : field + ".translation");
    return t;
  }
};

json vec(const Eigen::Vector3d& v) {
  return json::array({v.x(), v.y(), v.z()});
}

json transformJson(const PoseTransform& t) {
  json rotation = {{"axis", t.axisName.empty() ? vec(t.axis) : json(t.axisName)},
                   {"angle_deg", t.angleDeg},
                   {"pivot", t.pivotJoint.empty() ? vec(t.pivot) : json(t.pivotJoint)}};
  if (!t.then.empty()) {
    rotation["then"] = json::array();
    for (const PoseTurn& u : t.then)
      rotation["then"].push_back({{"axis", u.axisName.empty() ? vec(u.axis) : json(u.axisName)},
                                  {"angle_deg", u.angleDeg}});
  }
  return {{"rotation", rotation}, {"translation", vec(t.translation)}};
}

// Every transform of a pose with where it is, for resolving and for messages.
template <class PoseT, class F>
void forEachTransform(PoseT& pose, F&& f) {
  for (auto& g : pose.groups)
    if (!g.fixed) f(g.transform, "group \"" + g.name + "\"");
  for (auto& k : pose.keyframes)
    for (auto& [group, t] : k.transforms)
      f(t, "keyframe \"" + k.name + "\", group \"" + group + "\"");
}

}  // namespace

static json regionJson(const Region& r) {
  switch (r.shape) {
    case Region::Shape::Box:
      return {{"box", {r.a.x(), r.a.y(), r.a.z(), r.b.x(), r.b.y(), r.b.z()}}};
    case Region::Shape::Sphere:
      return {{"sphere", {r.a.x(), r.a.y(), r.a.z(), r.b.x()}}};
    case Region::Shape::OutsideSphere:
      return {{"outside_sphere", {r.a.x(), r.a.y(), r.a.z(), r.b.x()}}};
    case Region::Shape::Everywhere:
      break;
  }
  return {{"everywhere", true}};
}

std::string regionToJson(const Region& r) {
  return regionJson(r).dump();
}

bool PoseTransform::namesJoints() const {
  return !pivotJoint.empty() || !axisName.empty() ||
         std::any_of(then.begin(), then.end(),
                     [](const PoseTurn& u) { return !u.axisName.empty(); });
}

Eigen::Isometry3d PoseTransform::isometry() const {
  // x' = R (x - pivot) + pivot + translation, R the turns in order (the first rightmost).
  Eigen::Matrix3d R =
      Eigen::AngleAxisd(angleDeg * M_PI / 180, axis.normalized()).toRotationMatrix();
  for (const PoseTurn& u : then)
    R = Eigen::AngleAxisd(u.angleDeg * M_PI / 180, u.axis.normalized()).toRotationMatrix() * R;
  Eigen::Isometry3d m = Eigen::Isometry3d::Identity();
  m.linear() = R;
  m.translation() = translation + pivot - R * pivot;
  return m;
}

bool poseNamesJoints(const Pose& pose) {
  bool names = false;
  forEachTransform(
      pose, [&](const PoseTransform& t, const std::string&) { names = names || t.namesJoints(); });
  return names;
}

void resolvePoseJoints(Pose& pose, const Skeleton& skeleton) {
  const std::string who = "pose " + (pose.name.empty() ? std::string("(unnamed)") : pose.name);
  forEachTransform(pose, [&](PoseTransform& t, const std::string& where) {
    if (!t.pivotJoint.empty()) t.pivot = skeleton.centre(t.pivotJoint, who + ", " + where);
    if (!t.axisName.empty()) t.axis = skeleton.axis(t.axisName, who + ", " + where);
    for (PoseTurn& u : t.then) {
      if (!u.axisName.empty()) u.axis = skeleton.axis(u.axisName, who + ", " + where);
      u.axisName.clear();
    }
    t.pivotJoint.clear();
    t.axisName.clear();
  });
}

std::vector<std::pair<std::string, std::vector<Eigen::Isometry3d>>> Pose::frames() const {
  forEachTransform(*this, [&](const PoseTransform& t, const std::string& where) {
    if (t.namesJoints())
      throw Error("pose " + name + ", " + where + ": turns about the joint \"" +
                  (t.pivotJoint.empty() ? t.axisName : t.pivotJoint) +
                  "\": it needs the body's skeleton (skeleton.json beside S, or --skeleton)");
  });
  // Who each group follows, by index (-1: nobody), checked once for every frame.
  std::vector<int> parent(groups.size(), -1);
  for (std::size_t g = 0; g < groups.size(); ++g) {
    if (groups[g].follows.empty()) continue;
    for (std::size_t p = 0; p < groups.size(); ++p)
      if (groups[p].name == groups[g].follows) parent[g] = int(p);
    if (parent[g] < 0)
      throw Error("pose " + name + ", group \"" + groups[g].name + "\": follows no group named \"" +
                  groups[g].follows + "\"");
  }
  for (std::size_t g = 0; g < groups.size(); ++g) {
    std::size_t steps = 0;
    for (int p = parent[g]; p >= 0; p = parent[std::size_t(p)])
      if (++steps > groups.size() || p == int(g))
        throw Error("pose " + name + ", group \"" + groups[g].name +
                    "\": follows a chain of groups that comes back to it");
  }
  // Each group's own motion, then carried along its chain (the parent's motion after its own).
  auto chained = [&](const std::vector<Eigen::Isometry3d>& own) {
    std::vector<Eigen::Isometry3d> m(own.size());
    for (std::size_t g = 0; g < own.size(); ++g) {
      m[g] = own[g];
      for (int p = parent[g]; p >= 0; p = parent[std::size_t(p)]) m[g] = own[std::size_t(p)] * m[g];
    }
    return m;
  };
  std::vector<std::pair<std::string, std::vector<Eigen::Isometry3d>>> out;
  auto base = [&] {
    std::vector<Eigen::Isometry3d> m;
    for (const PoseGroup& g : groups)
      m.push_back(g.fixed ? Eigen::Isometry3d::Identity() : g.transform.isometry());
    return m;
  };
  if (keyframes.empty()) {
    out.emplace_back(name, chained(base()));
    return out;
  }
  for (const PoseKeyframe& k : keyframes) {
    std::vector<Eigen::Isometry3d> m = base();
    for (const auto& [group, t] : k.transforms)
      for (std::size_t g = 0; g < groups.size(); ++g)
        if (groups[g].name == group) m[g] = t.isometry();
    out.emplace_back(k.name, chained(m));
  }
  return out;
}

Pose parsePose(const std::string& text, const std::string& source) {
  const Reader r{{source}};
  json j;
  try {
    j = json::parse(text);
  } catch (const json::exception& e) {
    // parse_error for broken syntax, out_of_range for a number beyond double (1e99999): both are
    // a bad file, never a crash (found by the PoseJson fuzzer, docs/RELIABILITY.md).
    throw Error(source + ": not valid JSON (" + std::string(e.what()) + ")");
  }
  r.object(j, "(top level)");
  r.onlyKeys(j, "",
             {"format", "version", "name", "description", "joint_rings", "rhythms", "separations",
              "groups", "keyframes"});
  if (!j.contains("format") || j["format"] != "repose-pose")
    r.fail("format", "expected \"repose-pose\"");
  if (!j.contains("version") || r.integer(j["version"], "version") != 1)
    r.fail("version", "expected 1 (the only version so far)");
  Pose pose;
  if (j.contains("name")) pose.name = r.string(j["name"], "name");
  if (j.contains("description")) pose.description = r.string(j["description"], "description");
  if (j.contains("joint_rings")) {
    pose.jointRings = r.integer(j["joint_rings"], "joint_rings");
    if (pose.jointRings < 0 || pose.jointRings > 8) r.fail("joint_rings", "expected 0 to 8");
  }
  if (j.contains("rhythms")) {
    const json& rh = j["rhythms"];
    r.object(rh, "rhythms");
    r.onlyKeys(rh, "rhythms", {"scapulohumeral", "lumbopelvic"});
    for (const auto& [key, flag] :
         {std::pair<const char*, bool*>{"scapulohumeral", &pose.scapulohumeralRhythm},
          {"lumbopelvic", &pose.lumbopelvicRhythm}})
      if (rh.contains(key)) {
        if (!rh[key].is_boolean()) r.fail(std::string("rhythms.") + key, "expected true or false");
        *flag = rh[key].get<bool>();
      }
  }
  if (j.contains("separations")) {
    const json& s = j["separations"];
    if (!s.is_array()) r.fail("separations", "expected an array");
    for (std::size_t i = 0; i < s.size(); ++i) {
      const std::string f = "separations[" + std::to_string(i) + "]";
      r.object(s[i], f);
      r.onlyKeys(s[i], f, {"parts", "region"});
      if (!s[i].contains("parts") || !s[i]["parts"].is_array() || s[i]["parts"].size() != 2)
        r.fail(f + ".parts", "expected two body parts (labels or names of S)");
      if (!s[i].contains("region")) r.fail(f + ".region", "required");
      PoseSeparation sep;
      for (int k = 0; k < 2; ++k) {
        const json& part = s[i]["parts"][k];
        const std::string pf = f + ".parts[" + std::to_string(k) + "]";
        if (part.is_string()) {
          sep.partNames[k] = part.get<std::string>();
        } else if ((sep.parts[k] = r.integer(part, pf)) <= 0) {
          r.fail(pf, "a body part is a positive label of S");
        }
      }
      if (sep.parts[0] == sep.parts[1] && sep.partNames[0] == sep.partNames[1])
        r.fail(f + ".parts", "two different body parts");
      sep.region = r.region(s[i]["region"], f + ".region");
      pose.separations.push_back(sep);
    }
  }
  if (!j.contains("groups") || !j["groups"].is_array() || j["groups"].empty())
    r.fail("groups", "expected a non-empty array");
  std::set<std::string> names;
  int rests = 0;
  for (std::size_t i = 0; i < j["groups"].size(); ++i) {
    const std::string f = "groups[" + std::to_string(i) + "]";
    const json& g = r.object(j["groups"][i], f);
    r.onlyKeys(g, f, {"name", "select", "fixed", "follows", "rotation", "translation"});
    PoseGroup group;
    if (!g.contains("name")) r.fail(f + ".name", "required");
    group.name = r.string(g["name"], f + ".name");
    if (group.name.empty() || !names.insert(group.name).second)
      r.fail(f + ".name", "empty or used by another group");
    if (!g.contains("select")) r.fail(f + ".select", "required");
    group.select = r.selection(g["select"], f + ".select");
    rests += group.select.rest;
    if (g.contains("fixed")) {
      if (!g["fixed"].is_boolean()) r.fail(f + ".fixed", "expected true or false");
      group.fixed = g["fixed"].get<bool>();
    }
    if (group.fixed && (g.contains("rotation") || g.contains("translation")))
      r.fail(f, "a fixed group has no rotation or translation");
    group.transform = r.transform(g, f, {});
    if (g.contains("follows")) {
      group.follows = r.string(g["follows"], f + ".follows");
      if (group.fixed) r.fail(f + ".follows", "a fixed group stays in place: it follows nothing");
      if (group.follows == group.name) r.fail(f + ".follows", "a group cannot follow itself");
    }
    pose.groups.push_back(group);
  }
  if (rests > 1) r.fail("groups", "only one group can select the rest");
  // Chains: every group followed exists, and no chain comes back to where it started.
  for (std::size_t i = 0; i < pose.groups.size(); ++i) {
    const std::string f = "groups[" + std::to_string(i) + "].follows";
    std::string at = pose.groups[i].follows;
    for (std::size_t steps = 0; !at.empty(); ++steps) {
      const auto next = std::find_if(pose.groups.begin(), pose.groups.end(),
                                     [&](const PoseGroup& g) { return g.name == at; });
      if (next == pose.groups.end()) r.fail(f, "no group is named \"" + at + "\"");
      if (next->name == pose.groups[i].name || steps > pose.groups.size())
        r.fail(f, "the chain of groups it follows comes back to it");
      at = next->follows;
    }
  }
  if (j.contains("keyframes")) {
    const json& k = j["keyframes"];
    if (!k.is_array()) r.fail("keyframes", "expected an array");
    for (std::size_t i = 0; i < k.size(); ++i) {
      const std::string f = "keyframes[" + std::to_string(i) + "]";
      r.object(k[i], f);
      r.onlyKeys(k[i], f, {"name", "groups"});
      PoseKeyframe frame;
      frame.name =
          k[i].contains("name") ? r.string(k[i]["name"], f + ".name") : "frame" + std::to_string(i);
      if (!k[i].contains("groups")) r.fail(f + ".groups", "required");
      const json& gs = r.object(k[i]["groups"], f + ".groups");
      for (const auto& item : gs.items()) {
        // Named copies, not structured bindings: C++17 lambdas cannot capture those (clang).
        const std::string name = item.key();
        const json& t = item.value();
        const std::string gf = f + ".groups." + name;
        const auto it = std::find_if(pose.groups.begin(), pose.groups.end(),
                                     [&](const PoseGroup& g) { return g.name == name; });
        if (it == pose.groups.end()) r.fail(gf, "no group has this name");
        if (it->fixed) r.fail(gf, "the group is fixed");
        r.object(t, gf);
        r.onlyKeys(t, gf, {"rotation", "translation"});
        frame.transforms.emplace_back(name, r.transform(t, gf, it->transform));
      }
      pose.keyframes.push_back(frame);
    }
  }
  return pose;
}

Pose readPoseFile(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw Error(path + ": cannot open");
  std::stringstream text;
  text << in.rdbuf();
  return parsePose(text.str(), path);
}

std::string poseToJson(const Pose& pose) {
  json j = {{"format", "repose-pose"}, {"version", 1}, {"name", pose.name}};
  if (!pose.description.empty()) j["description"] = pose.description;
  if (pose.jointRings != 0) j["joint_rings"] = pose.jointRings;
  if (!pose.scapulohumeralRhythm || !pose.lumbopelvicRhythm)
    j["rhythms"] = {{"scapulohumeral", pose.scapulohumeralRhythm},
                    {"lumbopelvic", pose.lumbopelvicRhythm}};
  if (!pose.separations.empty()) {
    j["separations"] = json::array();
    for (const PoseSeparation& s : pose.separations) {
      json parts = json::array();
      for (int k = 0; k < 2; ++k)
        parts.push_back(s.partNames[k].empty() ? json(s.parts[k]) : json(s.partNames[k]));
      j["separations"].push_back({{"parts", parts}, {"region", regionJson(s.region)}});
    }
  }
  j["groups"] = json::array();
  for (const PoseGroup& g : pose.groups) {
    json select = json::object();
    if (g.select.rest) select["rest"] = true;
    if (!g.select.cageVertices.empty()) select["cage_vertices"] = g.select.cageVertices;
    if (g.select.region) select["region"] = regionJson(*g.select.region);
    if (!g.select.parts.empty() || !g.select.partNames.empty()) {
      json parts = json::array();
      for (const int p : g.select.parts) parts.push_back(p);
      for (const std::string& p : g.select.partNames) parts.push_back(p);
      select["parts"] = parts;
    }
    json group = {{"name", g.name}, {"select", select}};
    if (!g.follows.empty()) group["follows"] = g.follows;
    if (g.fixed) {
      group["fixed"] = true;
    } else {
      group.update(transformJson(g.transform));
    }
    j["groups"].push_back(group);
  }
  if (!pose.keyframes.empty()) {
    j["keyframes"] = json::array();
    for (const PoseKeyframe& k : pose.keyframes) {
      json groups = json::object();
      for (const auto& [name, t] : k.transforms) groups[name] = transformJson(t);
      j["keyframes"].push_back({{"name", k.name}, {"groups", groups}});
    }
  }
  return j.dump(2) + "\n";
}

void writePoseFile(const Pose& pose, const std::string& path) {
  writeTextFileAtomically(path, poseToJson(pose));
}

std::vector<std::string> jointDistalParts(const Skeleton& skeleton, const std::string& joint) {
  const SkeletonJoint* j = skeleton.find(joint);
  if (!j || j->parts[1].empty()) return {};
  std::vector<std::string> parts{j->parts[1]};
  // Joints below: those whose chain of parents reaches `joint` (the skeleton is a tree).
  for (const SkeletonJoint& other : skeleton.joints) {
    if (other.name == joint || other.parts[1].empty()) continue;
    for (const SkeletonJoint* up = skeleton.find(other.parent); up; up = skeleton.find(up->parent))
      if (up->name == joint) {
        if (std::find(parts.begin(), parts.end(), other.parts[1]) == parts.end())
          parts.push_back(other.parts[1]);
        break;
      }
  }
  return parts;
}

PoseGroup jointGroup(const Skeleton& skeleton, const std::string& joint, const std::string& axis,
                     double angleDeg) {
  const std::string where = "joint group " + joint + "." + axis;
  skeleton.axis(joint + "." + axis, where);  // throws for an unknown joint or axis
  PoseGroup g;
  g.name = joint + "." + axis;
  g.select.partNames = jointDistalParts(skeleton, joint);
  if (g.select.partNames.empty())
    throw Error(skeleton.source + ": joint " + joint +
                " names no distal body part (\"parts\" in skeleton.json): cannot pose by it");
  g.transform.pivotJoint = joint;
  g.transform.axisName = joint + "." + axis;
  g.transform.angleDeg = angleDeg;
  return g;
}

namespace {
// Whether `joint` lies below `ancestor` in the skeleton's tree.
bool jointBelow(const Skeleton& skeleton, const std::string& joint, const std::string& ancestor) {
  const SkeletonJoint* j = skeleton.find(joint);
  std::size_t steps = 0;
  for (const SkeletonJoint* up = j ? skeleton.find(j->parent) : nullptr;
       up && steps <= skeleton.joints.size(); up = skeleton.find(up->parent), ++steps)
    if (up->name == ancestor) return true;
  return false;
}
}  // namespace

std::vector<std::string> jointTurnAxes(const SkeletonJoint& joint) {
  auto rank = [](const std::string& axis) {
    return axis == "rotation" ? 0 : axis == "flexion" ? 2 : 1;  // abduction, lateral, others: 1
  };
  std::vector<std::string> axes;
  for (const auto& [name, v] : joint.axes) axes.push_back(name);
  std::stable_sort(axes.begin(), axes.end(),
                   [&](const std::string& a, const std::string& b) { return rank(a) < rank(b); });
  return axes;
}

std::string setJointGroup(Pose& pose, const Skeleton& skeleton, const std::string& joint,
                          const LabelTable& partLabels) {
  skeleton.centre(joint, "joint group " + joint);  // throws naming the joints there are
  const SkeletonJoint& j = *skeleton.find(joint);
  if (j.axes.empty()) throw Error(skeleton.source + ": joint " + joint + " has no axes");
  if (jointDistalParts(skeleton, joint).empty())
    throw Error(skeleton.source + ": joint " + joint +
                " names no distal body part (\"parts\" in skeleton.json): cannot pose by it");
  // The new group: a turn per axis, by name (the rig resolves them); angles kept from a group
  // of this joint already there (its turns in the same order, or its one named axis).
  const std::vector<std::string> axes = jointTurnAxes(j);
  PoseGroup group;
  group.name = joint;
  group.transform.pivotJoint = joint;
  std::vector<double> angles(axes.size(), 0.0);
  for (const PoseGroup& g : pose.groups) {
    if (g.fixed || jointOfGroup(skeleton, g.name) != joint) continue;
    if (g.name == joint) {
      angles[0] = g.transform.angleDeg;
      for (std::size_t k = 0; k < g.transform.then.size() && k + 1 < angles.size(); ++k)
        angles[k + 1] = g.transform.then[k].angleDeg;
    } else {
      for (std::size_t k = 0; k < axes.size(); ++k)
        if (joint + "." + axes[k] == g.name) angles[k] = g.transform.angleDeg;
    }
  }
  group.transform.axisName = joint + "." + axes[0];
  group.transform.angleDeg = angles[0];
  for (std::size_t k = 1; k < axes.size(); ++k)
    group.transform.then.push_back({Eigen::Vector3d::UnitX(), angles[k], joint + "." + axes[k]});

  // Groups that give way: this joint's own, and any group not of a joint that selects a part
  // the joint moves (by name, or by label through S's table).
  const std::vector<std::string> moved = jointDistalParts(skeleton, joint);
  auto selectsMoved = [&](const PoseGroup& g) {
    for (const std::string& n : g.select.partNames)
      if (std::find(moved.begin(), moved.end(), n) != moved.end()) return true;
    for (const int label : g.select.parts)
      if (const Label* l = partLabels.find(label);
          l && std::find(moved.begin(), moved.end(), l->name) != moved.end())
        return true;
    return false;
  };
  std::set<std::string> removed;
  for (const PoseGroup& g : pose.groups) {
    if (g.select.rest) continue;
    const std::string of = jointOfGroup(skeleton, g.name);
    if (of == joint || (of.empty() && selectsMoved(g))) removed.insert(g.name);
  }
  pose.groups.erase(std::remove_if(pose.groups.begin(), pose.groups.end(),
                                   [&](const PoseGroup& g) { return removed.count(g.name) > 0; }),
                    pose.groups.end());
  for (PoseKeyframe& k : pose.keyframes)
    k.transforms.erase(std::remove_if(k.transforms.begin(), k.transforms.end(),
                                      [&](const auto& e) { return removed.count(e.first) > 0; }),
                       k.transforms.end());
  for (PoseGroup& g : pose.groups)
    if (removed.count(g.follows)) g.follows.clear();
  // Before the rest group, as the pose suite's files order them; a fixed rest if there is none.
  const auto rest = std::find_if(pose.groups.begin(), pose.groups.end(),
                                 [](const PoseGroup& g) { return g.select.rest; });
  pose.groups.insert(rest, group);
  if (std::none_of(pose.groups.begin(), pose.groups.end(),
                   [](const PoseGroup& g) { return g.select.rest; })) {
    PoseGroup still;
    still.name = "rest";
    still.select.rest = true;
    still.fixed = true;
    pose.groups.push_back(still);
  }
  // The chain, for every joint group: its joint's distal parts less those of the joint groups
  // below it, carried by the nearest joint group above it.
  std::vector<std::pair<PoseGroup*, std::string>> joints;
  for (PoseGroup& g : pose.groups)
    if (!g.fixed && !g.select.rest)
      if (const std::string of = jointOfGroup(skeleton, g.name); !of.empty())
        joints.emplace_back(&g, of);
  for (auto& [g, of] : joints) {
    std::vector<std::string> parts = jointDistalParts(skeleton, of);
    std::string above;
    for (const auto& [other, otherJoint] : joints) {
      if (jointBelow(skeleton, otherJoint, of)) {
        for (const std::string& p : jointDistalParts(skeleton, otherJoint))
          parts.erase(std::remove(parts.begin(), parts.end(), p), parts.end());
      } else if (jointBelow(skeleton, of, otherJoint) &&
                 (above.empty() ||
                  jointBelow(skeleton, otherJoint, jointOfGroup(skeleton, above)))) {
        above = other->name;  // the nearest: below every other joint group above
      }
    }
    g->select = PoseSelection{};
    g->select.partNames = parts;
    g->follows = above;
  }
  return group.name;
}

std::pair<double, double> jointRangeDeg(const std::string& joint, const std::string& axis) {
  // Active ranges of motion of a healthy adult (clinical goniometry), rounded out; the sign is
  // the skeleton's (docs/POSES.md: positive flexion flexes, positive abduction moves away from
  // the midline).
  struct Range {
    const char* joint;
    const char* axis;
    double lo, hi;
  };
  static constexpr Range kRanges[] = {
      {"shoulder", "flexion", -60, 180}, {"shoulder", "abduction", -30, 180},
      {"shoulder", "rotation", -90, 90}, {"elbow", "flexion", 0, 150},
      {"elbow", "rotation", -90, 90},    {"wrist", "flexion", -70, 80},
      {"wrist", "rotation", -90, 90},    {"hip", "flexion", -30, 120},
      {"hip", "abduction", -30, 45},     {"hip", "rotation", -45, 45},
      {"knee", "flexion", 0, 150},       {"knee", "rotation", -30, 30},
      {"ankle", "flexion", -50, 20},     {"ankle", "rotation", -30, 30},
      {"neck", "flexion", -60, 50},      {"neck", "lateral", -45, 45},
      {"neck", "rotation", -80, 80}};
  const std::string kind = joint.substr(0, joint.find('_'));
  for (const Range& r : kRanges)
    if (kind == r.joint && axis == r.axis) return {r.lo, r.hi};
  return {-180, 180};
}

std::string jointOfGroup(const Skeleton& skeleton, const std::string& group) {
  const std::size_t dot = group.find('.');
  const SkeletonJoint* j = skeleton.find(group.substr(0, dot));
  if (!j) return "";
  if (dot == std::string::npos) return j->name;
  return j->axis(group.substr(dot + 1)) ? j->name : "";
}

void nameJointGroups(Pose& pose, const Skeleton& skeleton) {
  // A turn's axis by the name of the joint's axis it equals (it was resolved from that name).
  auto axisName = [](const SkeletonJoint& j, const Eigen::Vector3d& axis) -> std::string {
    for (const auto& [name, v] : j.axes)
      if (v.normalized().dot(axis.normalized()) > 1 - 1e-9) return j.name + "." + name;
    return "";
  };
  auto name = [&](PoseTransform& t, const std::string& group) {
    const std::string joint = jointOfGroup(skeleton, group);
    if (joint.empty()) return;
    const SkeletonJoint& j = *skeleton.find(joint);
    t.pivotJoint = joint;
    // "<joint>.<axis>": the axis its name gives; "<joint>": each turn's by its direction.
    if (t.axisName.empty()) t.axisName = group != joint ? group : axisName(j, t.axis);
    for (PoseTurn& u : t.then)
      if (u.axisName.empty()) u.axisName = axisName(j, u.axis);
  };
  for (PoseGroup& g : pose.groups)
    if (!g.fixed) name(g.transform, g.name);
  for (PoseKeyframe& k : pose.keyframes)
    for (auto& [group, t] : k.transforms) name(t, group);
}

}  // namespace repose
