// Scene folders: the module's scene.json format (version 2) for a single segmentation, rig and
// pose, written and read without the MRML layer.
#include "repose/pose/SceneFolder.h"

#include "repose/io/AtomicOutput.h"
#include "repose/io/MeshIO.h"
#include "repose/util/Error.h"

#include <nlohmann/json.hpp>

#include <filesystem>
#include <fstream>

namespace repose {

namespace fs = std::filesystem;
using nlohmann::json;

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
  const std::string poseFile = (rig.pose().name.empty() ? "pose" : rig.pose().name) + ".pose.json";
  writePoseFile(rig.pose(), (scene / poseFile).string());
  json groups = json::array();
  for (std::size_t g = 0; g < rig.handles().size(); ++g)
    groups.push_back(
        {{"name", rig.pose().groups[g].name}, {"vertices", rig.handles()[g].cageVertices}});
  const std::string seg = "vtkMRMLReposeSegmentationNode1", cage = "vtkMRMLReposeCageNode1",
                    mesh = "vtkMRMLReposeTransferMeshNode1";
  auto absolute = [](const std::string& p) { return p.empty() ? p : fs::absolute(p).string(); };
  const json nodes = json::array(
      {{{"class", "vtkMRMLReposeSegmentationNode"},
        {"id", seg},
        {"name", fs::path(inputs.organs).filename().string()},
        {"references", json::object()},
        {"LabelMapFileName", absolute(inputs.organs)},
        {"BodyPartMapFileName", absolute(inputs.parts)},
        {"ImageFileName", absolute(inputs.image)}},
       {{"class", "vtkMRMLReposeCageNode"},
        {"id", cage},
        {"name", "cage"},
        {"references", {{"segmentation", seg}}},
        {"FileName", "cage.vtk"},
        {"TargetVertexCount", settings.cageVertices},
        {"DilationMm", settings.dilateMm},
        {"HandleGroups", groups}},
       {{"class", "vtkMRMLReposeTransferMeshNode"},
        {"id", mesh},
        {"name", "transfer mesh"},
        {"references", {{"cage", cage}, {"segmentation", seg}}},
        {"FileName", "tm.vtu"},
        {"SizeMm", settings.meshMm}},
       {{"class", "vtkMRMLReposePoseNode"},
        {"id", "vtkMRMLReposePoseNode1"},
        {"name", rig.pose().name},
        {"references", {{"cage", cage}, {"segmentation", seg}, {"transfer_mesh", mesh}}},
        {"FileName", poseFile},
        {"CurrentFrame", 0}}});
  const json doc = {{"format", "repose-scene"},
                    {"version", 2},
                    {"nodes", nodes},
                    {"built_for", key.empty() ? json() : json::parse(key)}};
  writeTextFileAtomically((scene / "scene.json").string(), doc.dump(2) + "\n");
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
  const auto it = doc.find("nodes");
  return it != doc.end() && it->is_array() ? *it : json::array();
}

json readSceneJson(const fs::path& scene) {
  const fs::path file = scene / "scene.json";
  std::ifstream in(file);
  if (!in) throw Error(scene.string() + ": not a scene folder (no scene.json)");
  const json doc = json::parse(in, nullptr, false);
  if (doc.is_discarded() || !doc.is_object()) throw Error(file.string() + ": not valid JSON");
  if (stringOf(doc, "format") != "repose-scene")
    throw Error(file.string() + ": not a Repose scene (format is not \"repose-scene\")");
  return doc;
}

// A node's file, relative to the scene folder unless absolute.
std::string fileOf(const fs::path& scene, const json& node, const char* key) {
  const std::string name = stringOf(node, key);
  if (name.empty()) return name;
  return fs::path(name).is_absolute() ? name : (scene / name).string();
}

}  // namespace

SceneContents readSceneFolder(const std::string& folder) {
  const fs::path scene = folder;
  const json doc = readSceneJson(scene);
  SceneContents out;
  std::string cageFile, meshFile, poseFile;
  for (const json& node : nodesOf(doc)) {
    const std::string cls = stringOf(node, "class");
    if (cls == "vtkMRMLReposeSegmentationNode" && out.inputs.organs.empty()) {
      out.inputs.organs = fileOf(scene, node, "LabelMapFileName");
      out.inputs.parts = fileOf(scene, node, "BodyPartMapFileName");
      out.inputs.image = fileOf(scene, node, "ImageFileName");
    } else if (cls == "vtkMRMLReposeCageNode" && cageFile.empty()) {
      cageFile = fileOf(scene, node, "FileName");
    } else if (cls == "vtkMRMLReposeTransferMeshNode" && meshFile.empty()) {
      meshFile = fileOf(scene, node, "FileName");
    } else if (cls == "vtkMRMLReposePoseNode" && poseFile.empty()) {
      poseFile = fileOf(scene, node, "FileName");
    }
  }
  const std::string json = (scene / "scene.json").string();
  if (out.inputs.organs.empty()) throw Error(json + ": no segmentation node with a label map");
  if (cageFile.empty() || meshFile.empty())
    throw Error(json + ": no cage and transfer mesh (the rig was never built)");
  if (poseFile.empty()) throw Error(json + ": no pose node");
  out.geometry.cage = readTriangleMesh(cageFile);
  out.geometry.mesh = readTransferMesh(meshFile);
  out.geometry.coordinatesFile = greenCoordinatesFileFor(meshFile);
  out.pose = readPoseFile(poseFile);
  if (doc.contains("built_for") && !doc["built_for"].is_null())
    out.key = doc["built_for"].dump(-1, ' ', false, json::error_handler_t::replace);
  return out;
}

std::optional<RigGeometry> readSceneRig(const std::string& folder, const std::string& key) {
  const fs::path scene = folder;
  if (!fs::exists(scene / "scene.json")) return std::nullopt;
  json doc;
  try {
    doc = readSceneJson(scene);
  } catch (const Error&) {
    return std::nullopt;  // not ours: built again (and written over)
  }
  const auto builtFor = doc.find("built_for");
  if (builtFor == doc.end() || *builtFor != json::parse(key, nullptr, false)) return std::nullopt;
  std::string cageFile, meshFile;
  for (const json& node : nodesOf(doc)) {
    if (stringOf(node, "class") == "vtkMRMLReposeCageNode")
      cageFile = fileOf(scene, node, "FileName");
    if (stringOf(node, "class") == "vtkMRMLReposeTransferMeshNode")
      meshFile = fileOf(scene, node, "FileName");
  }
  if (cageFile.empty() || meshFile.empty()) return std::nullopt;
  return RigGeometry{readTriangleMesh(cageFile), readTransferMesh(meshFile),
                     greenCoordinatesFileFor(meshFile)};
}

}  // namespace repose
