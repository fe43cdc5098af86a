// skeleton.json reading and writing, the joint axes' conventions, and where a skeleton and a
// tissue table are found beside S.
#include "repose/skeleton/Skeleton.h"

#include "repose/io/AtomicOutput.h"
#include "repose/util/Error.h"
#include "repose/util/JsonFields.h"

#include <nlohmann/json.hpp>

#include <Eigen/Geometry>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

namespace repose {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

using Reader = JsonFields;

json vec(const Eigen::Vector3d& v) {
  return json::array({v.x(), v.y(), v.z()});
}

std::string jointList(const Skeleton& s) {
  std::string out;
  for (const SkeletonJoint& j : s.joints) out += (out.empty() ? "" : ", ") + j.name;
  return out.empty() ? "none" : out;
}

std::string skeletonName(const Skeleton& s) {
  return s.source.empty() ? std::string("the skeleton") : s.source;
}

// The sibling of `partsPath` named <prefix><name> when S is <prefix>S.<ext>, else <name>.
std::string beside(const std::string& partsPath, const std::string& name) {
  if (partsPath.empty()) return "";
  const fs::path parts(partsPath);
  const fs::path dir = parts.has_parent_path() ? parts.parent_path() : fs::path(".");
  const std::string file = parts.filename().string();
  std::vector<fs::path> candidates;
  for (const char* ext : {".nii.gz", ".seg.nrrd", ".nii", ".nrrd", ".nhdr"}) {
    const std::string suffix = std::string("S") + ext;
    if (file.size() > suffix.size() &&
        file.compare(file.size() - suffix.size(), suffix.size(), suffix) == 0)
      candidates.push_back(dir / (file.substr(0, file.size() - suffix.size()) + name));
  }
  candidates.push_back(dir / name);
  std::error_code ec;
  for (const fs::path& c : candidates)
    if (fs::is_regular_file(c, ec)) return c.string();
  return "";
}

}  // namespace

const Eigen::Vector3d* SkeletonJoint::axis(const std::string& axisName) const {
  for (const auto& [name, v] : axes)
    if (name == axisName) return &v;
  return nullptr;
}

const SkeletonJoint* Skeleton::find(const std::string& name) const {
  for (const SkeletonJoint& j : joints)
    if (j.name == name) return &j;
  return nullptr;
}

Eigen::Vector3d Skeleton::centre(const std::string& joint, const std::string& where) const {
  const SkeletonJoint* j = find(joint);
  if (!j)
    throw Error(where + ": " + skeletonName(*this) + " has no joint \"" + joint +
                "\" (its joints: " + jointList(*this) + ")");
  return j->centre;
}

Eigen::Vector3d Skeleton::axis(const std::string& jointDotAxis, const std::string& where) const {
  const auto dot = jointDotAxis.rfind('.');
  if (dot == std::string::npos || dot == 0 || dot + 1 == jointDotAxis.size())
    throw Error(where + ": \"" + jointDotAxis +
                "\" is not a joint axis (expected <joint>.<axis>, e.g. elbow_left.flexion)");
  const std::string joint = jointDotAxis.substr(0, dot), name = jointDotAxis.substr(dot + 1);
  centre(joint, where);  // names the missing joint
  const SkeletonJoint& j = *find(joint);
  if (const Eigen::Vector3d* a = j.axis(name)) return *a;
  std::string have;
  for (const auto& [n, v] : j.axes) have += (have.empty() ? "" : ", ") + n;
  throw Error(where + ": joint \"" + joint + "\" of " + skeletonName(*this) + " has no axis \"" +
              name + "\" (its axes: " + (have.empty() ? "none" : have) + ")");
}

Skeleton parseSkeleton(const std::string& text, const std::string& source) {
  const Reader r{source};
  json doc;
  try {
    doc = json::parse(text);
  } catch (const json::exception& e) {
    throw Error(source + ": not valid JSON (" + std::string(e.what()) + ")");
  }
  if (!doc.is_object()) r.fail("(top level)", "expected an object");
  if (doc.contains("space") && doc["space"] != "RAS")
    r.fail("space", "expected \"RAS\" (joints are in RAS millimetres)");
  if (doc.contains("units") && doc["units"] != "mm") r.fail("units", "expected \"mm\"");
  if (!doc.contains("joints") || !doc["joints"].is_array())
    r.fail("joints", "expected an array of joints");
  Skeleton s;
  s.source = source;
  std::set<std::string> names;
  for (std::size_t i = 0; i < doc["joints"].size(); ++i) {
    const std::string f = "joints[" + std::to_string(i) + "]";
    const json& j = doc["joints"][i];
    if (!j.is_object()) r.fail(f, "expected an object");
    SkeletonJoint joint;
    if (!j.contains("name")) r.fail(f + ".name", "required");
    joint.name = r.string(j["name"], f + ".name");
    if (joint.name.empty() || joint.name.find('.') != std::string::npos ||
        !names.insert(joint.name).second)
      r.fail(f + ".name", "empty, holding a '.', or used by another joint");
    if (j.contains("parent")) joint.parent = r.string(j["parent"], f + ".parent");
    if (!j.contains("ras")) r.fail(f + ".ras", "required");
    joint.centre = r.vector3(j["ras"], f + ".ras");
    if (j.contains("axes")) {
      if (!j["axes"].is_object()) r.fail(f + ".axes", "expected an object of unit vectors");
      for (const auto& item : j["axes"].items()) {
        const std::string af = f + ".axes." + item.key();
        const Eigen::Vector3d v = r.vector3(item.value(), af);
        if (v.norm() < 1e-9) r.fail(af, "zero vector");
        joint.axes.emplace_back(item.key(), v.normalized());
      }
    }
    if (j.contains("parts")) {
      const json& p = j["parts"];
      if (!p.is_array() || p.size() != 2) r.fail(f + ".parts", "expected [proximal, distal]");
      for (int k = 0; k < 2; ++k)
        joint.parts[std::size_t(k)] = r.string(p[k], f + ".parts[" + std::to_string(k) + "]");
    }
    if (j.contains("radius_mm")) {
      joint.radiusMm = r.number(j["radius_mm"], f + ".radius_mm");
      if (joint.radiusMm < 0) r.fail(f + ".radius_mm", "negative");
    }
    if (j.contains("method")) joint.method = r.string(j["method"], f + ".method");
    if (j.contains("fit_rms_mm")) joint.fitRmsMm = r.number(j["fit_rms_mm"], f + ".fit_rms_mm");
    s.joints.push_back(joint);
  }
  for (std::size_t i = 0; i < s.joints.size(); ++i)
    if (!s.joints[i].parent.empty() && !names.count(s.joints[i].parent))
      r.fail("joints[" + std::to_string(i) + "].parent",
             "no joint named \"" + s.joints[i].parent + "\"");
  return s;
}

Skeleton readSkeleton(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw Error(path + ": cannot open");
  std::stringstream text;
  text << in.rdbuf();
  return parseSkeleton(text.str(), path);
}

std::string skeletonToJson(const Skeleton& skeleton, const std::string& extra) {
  json joints = json::array();
  for (const SkeletonJoint& j : skeleton.joints) {
    json o = {{"name", j.name}, {"parent", j.parent}, {"ras", vec(j.centre)}};
    if (!j.axes.empty()) {
      json axes = json::object();
      for (const auto& [name, v] : j.axes) axes[name] = vec(v);
      o["axes"] = axes;
    }
    if (!j.parts[0].empty() || !j.parts[1].empty()) o["parts"] = {j.parts[0], j.parts[1]};
    if (j.radiusMm > 0) o["radius_mm"] = j.radiusMm;
    if (!j.method.empty()) o["method"] = j.method;
    if (j.fitRmsMm >= 0) o["fit_rms_mm"] = j.fitRmsMm;
    joints.push_back(o);
  }
  json doc = {{"units", "mm"}, {"space", "RAS"}};
  if (!extra.empty()) doc.update(json::parse(extra));
  doc["joints"] = joints;
  return doc.dump(2) + "\n";
}

void writeSkeleton(const Skeleton& skeleton, const std::string& path, const std::string& extra) {
  writeTextFileAtomically(path, skeletonToJson(skeleton, extra));
}

std::string findSkeletonBeside(const std::string& partsPath) {
  return beside(partsPath, "skeleton.json");
}

std::string findTissuesBeside(const std::string& partsPath) {
  return beside(partsPath, "tissues.csv");
}

std::vector<std::pair<std::string, Eigen::Vector3d>> jointAxes(
    JointKind kind, const Eigen::Vector3d& distal, const Eigen::Vector3d& anterior,
    const Eigen::Vector3d& superior, int side, const Eigen::Vector3d& palmar) {
  const Eigen::Vector3d d = distal.normalized();
  const Eigen::Vector3d right = anterior.cross(superior).normalized();
  const Eigen::Vector3d lateral = double(side) * right;
  // The unit axis a with a x d towards `towards`: a positive turn about a moves d that way.
  auto turning = [&](const Eigen::Vector3d& towards) {
    Eigen::Vector3d a = d.cross(towards);
    if (a.norm() < 1e-6) a = d.unitOrthogonal();
    return Eigen::Vector3d(a.normalized());
  };
  std::vector<std::pair<std::string, Eigen::Vector3d>> axes;
  switch (kind) {
    case JointKind::Shoulder:
    case JointKind::Hip:
      axes.emplace_back("flexion", turning(anterior));
      axes.emplace_back("abduction", turning(lateral));
      break;
    case JointKind::Elbow:
      axes.emplace_back("flexion", turning(anterior));
      break;
    case JointKind::Knee:
      axes.emplace_back("flexion", turning(-anterior));
      break;
    case JointKind::Wrist:
      axes.emplace_back("flexion", turning(palmar.norm() > 0 ? palmar : anterior));
      break;
    case JointKind::Ankle:
      axes.emplace_back("flexion", turning(superior));  // dorsiflexion: the toes go up
      break;
    case JointKind::Neck:
      axes.emplace_back("flexion", turning(anterior));
      axes.emplace_back("lateral", turning(-right));
      break;
    case JointKind::Sternoclavicular:
      axes.emplace_back("elevation", turning(superior));
      axes.emplace_back("protraction", turning(anterior));
      break;
    case JointKind::Lumbosacral:
      // The pelvis tilts back (its lower end forwards), as a hip's flexion turns the thigh.
      axes.emplace_back("flexion", turning(anterior));
      axes.emplace_back("lateral", turning(-right));
      break;
  }
  axes.emplace_back("rotation", d);
  return axes;
}

}  // namespace repose
