#include "vtkMRMLReposeCageNode.h"

#include <vtkObjectFactory.h>

vtkStandardNewMacro(vtkMRMLReposeCageNode);

void vtkMRMLReposeCageNode::SetMesh(vtkPolyData* mesh) {
  this->Mesh = mesh;
  this->Modified();
}

void vtkMRMLReposeCageNode::WriteFields(nlohmann::ordered_json& json) const {
  json["FileName"] = this->FileName;
  json["TargetVertexCount"] = this->TargetVertexCount;
  json["DilationMm"] = this->DilationMm;
  nlohmann::ordered_json groups = nlohmann::ordered_json::array();
  for (const HandleGroup& g : this->HandleGroups)
    groups.push_back({{"name", g.name}, {"vertices", g.vertices}});
  json["HandleGroups"] = groups;
}

bool vtkMRMLReposeCageNode::ReadFields(const nlohmann::json& json, bool apply, std::string& error) {
  if (!apply) {
    if (!CheckString(json, "FileName", error) || !CheckInteger(json, "TargetVertexCount", error) ||
        !CheckNumber(json, "DilationMm", error))
      return false;
    if (json.contains("HandleGroups")) {
      const auto& groups = json["HandleGroups"];
      if (!groups.is_array()) return error = "HandleGroups: expected an array", false;
      for (std::size_t i = 0; i < groups.size(); ++i) {
        const std::string f = "HandleGroups[" + std::to_string(i) + "]";
        const auto& g = groups[i];
        if (!g.is_object() || !g.contains("name") || !g["name"].is_string() ||
            !g.contains("vertices") || !g["vertices"].is_array())
          return error = f + ": expected {\"name\": text, \"vertices\": [indices]}", false;
        for (const auto& v : g["vertices"])
          if (!v.is_number_integer() || v.get<long long>() < 0)
            return error = f + ".vertices: expected non-negative integers", false;
      }
    }
    return true;
  }
  if (json.contains("FileName")) this->SetFileName(json["FileName"]);
  if (json.contains("TargetVertexCount")) this->SetTargetVertexCount(json["TargetVertexCount"]);
  if (json.contains("DilationMm")) this->SetDilationMm(json["DilationMm"]);
  if (json.contains("HandleGroups")) {
    std::vector<HandleGroup> groups;
    for (const auto& g : json["HandleGroups"])
      groups.push_back({g["name"].get<std::string>(), g["vertices"].get<std::vector<int>>()});
    this->SetHandleGroups(groups);
  }
  return true;
}

void vtkMRMLReposeCageNode::CopyContent(vtkMRMLReposeNode* other) {
  auto* o = static_cast<vtkMRMLReposeCageNode*>(other);
  this->SetFileName(o->FileName);
  this->SetTargetVertexCount(o->TargetVertexCount);
  this->SetDilationMm(o->DilationMm);
  this->SetHandleGroups(o->HandleGroups);
  vtkSmartPointer<vtkPolyData> mesh;
  if (o->Mesh) {
    mesh = vtkSmartPointer<vtkPolyData>::New();
    mesh->DeepCopy(o->Mesh);
  }
  this->SetMesh(mesh);
}
