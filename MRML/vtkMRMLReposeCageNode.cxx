#include "vtkMRMLReposeCageNode.h"

#include <vtkObjectFactory.h>
#include "repose/schema/SceneSchema.h"

namespace sc = repose::scene_schema;

vtkStandardNewMacro(vtkMRMLReposeCageNode);

void vtkMRMLReposeCageNode::SetMesh(vtkPolyData* mesh) {
  this->Mesh = mesh;
  this->Modified();
}

void vtkMRMLReposeCageNode::WriteFields(nlohmann::ordered_json& json) const {
  json[sc::cage::kFile] = this->FileName;
  json[sc::cage::kTargetVertexCount] = this->TargetVertexCount;
  json[sc::cage::kDilationMm] = this->DilationMm;
  if (!this->CageChoice.empty())
    json[sc::cage::kChoice] = nlohmann::ordered_json::parse(this->CageChoice, nullptr, false);
  nlohmann::ordered_json groups = nlohmann::ordered_json::array();
  for (const HandleGroup& g : this->HandleGroups)
    groups.push_back({{sc::cage::kGroupName, g.name}, {sc::cage::kGroupVertices, g.vertices}});
  json[sc::cage::kHandleGroups] = groups;
}

bool vtkMRMLReposeCageNode::ReadFields(const nlohmann::json& json, bool apply, std::string& error) {
  if (!apply) {
    if (!CheckString(json, sc::cage::kFile, error) ||
        !CheckInteger(json, sc::cage::kTargetVertexCount, error) ||
        !CheckNumber(json, sc::cage::kDilationMm, error))
      return false;
    if (json.contains(sc::cage::kChoice) && !json[sc::cage::kChoice].is_object())
      return error = std::string(sc::cage::kChoice) + ": expected an object", false;
    if (json.contains(sc::cage::kHandleGroups)) {
      const auto& groups = json[sc::cage::kHandleGroups];
      if (!groups.is_array()) return error = "HandleGroups: expected an array", false;
      for (std::size_t i = 0; i < groups.size(); ++i) {
        const std::string f = "HandleGroups[" + std::to_string(i) + "]";
        const auto& g = groups[i];
        if (!g.is_object() || !g.contains(sc::cage::kGroupName) ||
            !g[sc::cage::kGroupName].is_string() || !g.contains(sc::cage::kGroupVertices) ||
            !g[sc::cage::kGroupVertices].is_array())
          return error = f + ": expected {\"name\": text, \"vertices\": [indices]}", false;
        for (const auto& v : g[sc::cage::kGroupVertices])
          if (!v.is_number_integer() || v.get<long long>() < 0)
            return error = f + ".vertices: expected non-negative integers", false;
      }
    }
    return true;
  }
  if (json.contains(sc::cage::kFile)) this->SetFileName(json[sc::cage::kFile]);
  if (json.contains(sc::cage::kTargetVertexCount))
    this->SetTargetVertexCount(json[sc::cage::kTargetVertexCount]);
  if (json.contains(sc::cage::kDilationMm)) this->SetDilationMm(json[sc::cage::kDilationMm]);
  this->SetCageChoice(json.contains(sc::cage::kChoice) ? json[sc::cage::kChoice].dump() : "");
  if (json.contains(sc::cage::kHandleGroups)) {
    std::vector<HandleGroup> groups;
    for (const auto& g : json[sc::cage::kHandleGroups])
      groups.push_back({g[sc::cage::kGroupName].get<std::string>(),
                        g[sc::cage::kGroupVertices].get<std::vector<int>>()});
    this->SetHandleGroups(groups);
  }
  return true;
}

void vtkMRMLReposeCageNode::CopyContent(vtkMRMLReposeNode* other) {
  auto* o = static_cast<vtkMRMLReposeCageNode*>(other);
  this->SetFileName(o->FileName);
  this->SetTargetVertexCount(o->TargetVertexCount);
  this->SetDilationMm(o->DilationMm);
  this->SetCageChoice(o->CageChoice);
  this->SetHandleGroups(o->HandleGroups);
  vtkSmartPointer<vtkPolyData> mesh;
  if (o->Mesh) {
    mesh = vtkSmartPointer<vtkPolyData>::New();
    mesh->DeepCopy(o->Mesh);
  }
  this->SetMesh(mesh);
}
