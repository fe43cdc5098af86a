// Scene folders: the module's scene.json format (version 2) for a single segmentation, rig and
// pose, written and read without the MRML layer.
#include "repose/pose/SceneFolder.h"

#include "repose/io/AtomicOutput.h"
#include "repose/io/MeshIO.h"
#include "repose/schema/SceneSchema.h"
#include "repose/util/Error.h"

#include <nlohmann/json.hpp>
#include <zlib.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <vector>

namespace repose {

namespace fs = std::filesystem;
namespace sc = scene_schema;
using nlohmann::json;

namespace {

// "SIZE:CRC32" of a file's bytes (sc::kFileStamps), "" when it cannot be read.
std::string fileStamp(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) return "";
  uLong crc = crc32(0L, Z_NULL, 0);
  std::uintmax_t size = 0;
  std::vector<char> buffer(1 << 20);
  while (in) {
    in.read(buffer.data(), std::streamsize(buffer.size()));
    const std::streamsize n = in.gcount();
    if (n <= 0) break;
    crc = crc32(crc, reinterpret_cast<const Bytef*>(buffer.data()), uInt(n));
    size += std::uintmax_t(n);
  }
  if (in.bad()) return "";
  char hex[16];
  std::snprintf(hex, sizeof hex, "%08lx", static_cast<unsigned long>(crc));
  return std::to_string(size) + ":" + hex;
}

// The first rig file of the scene that is missing or differs from its stamp in scene.json, as
// "FILE: what"; "" when all match or the scene records none.
std::string editedRigFile(const fs::path& scene, const json& doc) {
  const auto stamps = doc.find(sc::kFileStamps);
  if (stamps == doc.end() || !stamps->is_object()) return "";
  for (const auto& [name, stamp] : stamps->items()) {
    if (!stamp.is_string()) continue;
    const fs::path file = fs::path(name).is_absolute() ? fs::path(name) : scene / name;
    std::error_code ec;
    if (!fs::exists(file, ec)) return file.string() + ": missing";
    if (fileStamp(file) != stamp.get<std::string>())
      return file.string() +
             ": changed since the scene was saved (not the file scene.json records)";
  }
  return "";
}

}  // namespace

std::string sceneRigKey(const std::string& partsPath, const std::vector<LimbSeparation>& cuts,
                        const RigSettings& settings) {
  json separations = json::array();
  for (const LimbSeparation& s : cuts)
    separations.push_back(
        {{"labels", {s.labelA, s.labelB}}, {"region", json::parse(regionToJson(s.region))}});
  const json key = {
      {"parts", fs::absolute(partsPath).string()},
      {"parts_bytes", fs::file_size(partsPath)},
      {"parts_mtime", fs::last_write_time(partsPath).time_since_epoch().count()},
      {"cage_vertices", settings.cageVertices},
      {"dilate_mm", settings.dilateMm},
      {"mesh_size_mm", settings.meshMm},
      {"rigid_labels", settings.rigidLabels},
      {"bone_pieces",
       [&] {
         json pairs = json::array();
         for (const auto& [label, piece] : settings.bonePieces) pairs.push_back({label, piece});
         return pairs;
       }()},
      {"whole_organs", settings.wholeOrgans},
      {"refine_joints",
       [&] {
         json balls = json::array();
         for (const JointRefinement& r : settings.refineJoints)
           balls.push_back({r.centre.x(), r.centre.y(), r.centre.z(), r.radiusMm, r.sizeMm});
         return balls;
       }()},
      {"separations", separations}};
  return key.dump();
}

void writeSceneFolder(const std::string& folder, const PoseRig& rig, const std::string& key,
                      const SceneInputs& inputs, const RigSettings& settings) {
  const fs::path scene = folder;
  if (!fs::exists(fs::absolute(scene).parent_path()))
    throw Error(folder + ": its parent folder does not exist");
  fs::create_directories(scene);
  writeTriangleMesh(rig.cage(), (scene / "cage.vtk").string());
  writeTransferMesh(rig.mesh(), (scene / "tm.vtu").string());
  // The coordinates, so that a later run reads them instead of computing them (most of its time).
  rig.deformation().saveCoordinates(greenCoordinatesFileFor((scene / "tm.vtu").string()));
  // The pose as its user wrote it: the rhythms' groups come after its own and are made again
  // whenever it is rigged.
  const Pose& pose = rig.userPose();
  const std::string poseFile = (pose.name.empty() ? "pose" : pose.name) + ".pose.json";
  writePoseFile(pose, (scene / poseFile).string());
  json groups = json::array();
  for (std::size_t g = 0; g < rig.handles().size() && g < pose.groups.size(); ++g)
    groups.push_back({{sc::cage::kGroupName, pose.groups[g].name},
                      {sc::cage::kGroupVertices, rig.handles()[g].cageVertices}});
  const std::string seg = std::string(sc::segmentation::kClassName) + "1",
                    cage = std::string(sc::cage::kClassName) + "1",
                    mesh = std::string(sc::transfer_mesh::kClassName) + "1";
  auto absolute = [](const std::string& p) { return p.empty() ? p : fs::absolute(p).string(); };
  const json nodes = json::array(
      {{{sc::kClass, sc::segmentation::kClassName},
        {sc::kId, seg},
        {sc::kName, fs::path(inputs.organs).filename().string()},
        {sc::kReferences, json::object()},
        {sc::segmentation::kLabelMapFile, absolute(inputs.organs)},
        {sc::segmentation::kBodyPartMapFile, absolute(inputs.parts)},
        {sc::segmentation::kImageFile, absolute(inputs.image)}},
       {{sc::kClass, sc::cage::kClassName},
        {sc::kId, cage},
        {sc::kName, "cage"},
        {sc::kReferences, {{sc::kSegmentationRole, seg}}},
        {sc::cage::kFile, "cage.vtk"},
        {sc::cage::kTargetVertexCount, settings.cageVertices},
        {sc::cage::kDilationMm, settings.dilateMm},
        {sc::cage::kChoice, json::parse(rig.cageChoice().json())},
        {sc::cage::kHandleGroups, groups}},
       {{sc::kClass, sc::transfer_mesh::kClassName},
        {sc::kId, mesh},
        {sc::kName, "transfer mesh"},
        {sc::kReferences, {{sc::kCageRole, cage}, {sc::kSegmentationRole, seg}}},
        {sc::transfer_mesh::kFile, "tm.vtu"},
        {sc::transfer_mesh::kSizeMm, settings.meshMm}},
       {{sc::kClass, sc::pose::kClassName},
        {sc::kId, std::string(sc::pose::kClassName) + "1"},
        {sc::kName, pose.name},
        {sc::kReferences,
         {{sc::kCageRole, cage}, {sc::kSegmentationRole, seg}, {sc::kTransferMeshRole, mesh}}},
        {sc::pose::kFile, poseFile},
        {sc::pose::kCurrentFrame, 0}}});
  json stamps = json::object();
  for (const char* name : {"cage.vtk", "tm.vtu"}) stamps[name] = fileStamp(scene / name);
  const json doc = {{sc::kFormatKey, sc::kFormat},
                    {sc::kVersionKey, sc::kVersion},
                    {sc::kNodes, nodes},
                    {sc::kBuiltFor, key.empty() ? json() : json::parse(key)},
                    {sc::kFileStamps, stamps}};
  writeTextFileAtomically((scene / sc::kDocument).string(), doc.dump(2) + "\n");
}

namespace {

// A string member, or "" when the node is not an object or the member is absent or not a string
// (json::value would throw its own exception type on those: found by Testing/Fuzz/FuzzScene).
std::string stringOf(const json& node, const char* key) {
  if (!node.is_object()) return "";
  const auto it = node.find(key);
  return it != node.end() && it->is_string() ? it->get<std::string>() : "";
}

json nodesOf(const json& doc) {
  const auto it = doc.find(sc::kNodes);
  return it != doc.end() && it->is_array() ? *it : json::array();
}

json readSceneJson(const fs::path& scene) {
  const fs::path file = scene / sc::kDocument;
  std::ifstream in(file);
  if (!in)
    throw Error(scene.string() + ": not a scene folder (no " + std::string(sc::kDocument) + ")");
  const json doc = json::parse(in, nullptr, false);
  if (doc.is_discarded() || !doc.is_object()) throw Error(file.string() + ": not valid JSON");
  if (stringOf(doc, sc::kFormatKey) != sc::kFormat)
    throw Error(file.string() + ": not a Repose scene (" + sc::kFormatKey + " is not \"" +
                sc::kFormat + "\")");
  return doc;
}

// A node's file, relative to the scene folder unless absolute.
std::string fileOf(const fs::path& scene, const json& node, const char* key) {
  const std::string name = stringOf(node, key);
  if (name.empty()) return name;
  return fs::path(name).is_absolute() ? name : (scene / name).string();
}

// The cage node's setting: the choice Core recorded, else (an older scene, or the workbench's)
// the node's target vertex count and dilation, asked and used alike.
CageChoice cageChoiceOf(const json& node) {
  const auto it = node.find(sc::cage::kChoice);
  if (it != node.end() && it->is_object()) {
    try {
      return CageChoice::fromJson(it->dump());
    } catch (const Error&) {
      // a hand-edited choice: the node's setting below
    }
  }
  CageSetting setting;
  const auto v = node.find(sc::cage::kTargetVertexCount);
  const auto d = node.find(sc::cage::kDilationMm);
  if (v != node.end() && v->is_number_integer()) setting.vertices = v->get<int>();
  if (d != node.end() && d->is_number()) setting.dilateMm = d->get<double>();
  return CageChoice::given(setting);
}

}  // namespace

SceneContents readSceneFolder(const std::string& folder) {
  const fs::path scene = folder;
  const json doc = readSceneJson(scene);
  SceneContents out;
  std::string cageFile, meshFile, poseFile;
  for (const json& node : nodesOf(doc)) {
    const std::string cls = stringOf(node, sc::kClass);
    if (cls == sc::segmentation::kClassName && out.inputs.organs.empty()) {
      out.inputs.organs = fileOf(scene, node, sc::segmentation::kLabelMapFile);
      out.inputs.parts = fileOf(scene, node, sc::segmentation::kBodyPartMapFile);
      out.inputs.image = fileOf(scene, node, sc::segmentation::kImageFile);
    } else if (cls == sc::cage::kClassName && cageFile.empty()) {
      cageFile = fileOf(scene, node, sc::cage::kFile);
      out.geometry.cageChoice = cageChoiceOf(node);
    } else if (cls == sc::transfer_mesh::kClassName && meshFile.empty()) {
      meshFile = fileOf(scene, node, sc::transfer_mesh::kFile);
    } else if (cls == sc::pose::kClassName && poseFile.empty()) {
      poseFile = fileOf(scene, node, sc::pose::kFile);
    }
  }
  const std::string json = (scene / sc::kDocument).string();
  if (out.inputs.organs.empty()) throw Error(json + ": no segmentation node with a label map");
  if (cageFile.empty() || meshFile.empty())
    throw Error(json + ": no cage and transfer mesh (the rig was never built)");
  if (poseFile.empty()) throw Error(json + ": no pose node");
  const std::string edited = editedRigFile(scene, doc);
  if (!edited.empty())
    throw Error(edited + "; build the rig again (repose pose --scene " + folder + ")");
  out.geometry.cage = readTriangleMesh(cageFile);
  out.geometry.mesh = readTransferMesh(meshFile);
  out.geometry.coordinatesFile = greenCoordinatesFileFor(meshFile);
  out.pose = readPoseFile(poseFile);
  if (doc.contains(sc::kBuiltFor) && !doc[sc::kBuiltFor].is_null())
    out.key = doc[sc::kBuiltFor].dump(-1, ' ', false, json::error_handler_t::replace);
  return out;
}

std::optional<RigGeometry> readSceneRig(const std::string& folder, const std::string& key,
                                        std::string* why) {
  const fs::path scene = folder;
  if (!fs::exists(scene / sc::kDocument)) return std::nullopt;
  auto notReused = [&](const std::string& reason) -> std::optional<RigGeometry> {
    if (why) *why = reason;
    return std::nullopt;  // built again (and written over)
  };
  json doc;
  try {
    doc = readSceneJson(scene);
  } catch (const Error& e) {
    return notReused(e.what());
  }
  const auto builtFor = doc.find(sc::kBuiltFor);
  if (builtFor == doc.end() || *builtFor != json::parse(key, nullptr, false))
    return notReused((scene / sc::kDocument).string() +
                     ": built for another body-part map or other settings");
  std::string cageFile, meshFile;
  CageChoice choice;
  for (const json& node : nodesOf(doc)) {
    if (stringOf(node, sc::kClass) == sc::cage::kClassName) {
      cageFile = fileOf(scene, node, sc::cage::kFile);
      choice = cageChoiceOf(node);
    }
    if (stringOf(node, sc::kClass) == sc::transfer_mesh::kClassName)
      meshFile = fileOf(scene, node, sc::transfer_mesh::kFile);
  }
  if (cageFile.empty() || meshFile.empty())
    return notReused((scene / sc::kDocument).string() + ": no cage and transfer mesh");
  for (const std::string& file : {cageFile, meshFile})
    if (!fs::exists(file)) return notReused(file + ": missing");
  const std::string edited = editedRigFile(scene, doc);
  if (!edited.empty()) return notReused(edited);
  return RigGeometry{readTriangleMesh(cageFile), readTransferMesh(meshFile),
                     greenCoordinatesFileFor(meshFile), choice};
}

}  // namespace repose
