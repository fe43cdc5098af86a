#include "vtkMRMLReposeTransferMeshNode.h"

#include <vtkObjectFactory.h>
#include "repose/schema/SceneSchema.h"

#include <algorithm>

namespace sc = repose::scene_schema;

vtkStandardNewMacro(vtkMRMLReposeTransferMeshNode);

void vtkMRMLReposeTransferMeshNode::SetMesh(vtkUnstructuredGrid* mesh) {
  this->Mesh = mesh;
  this->Modified();
}

void vtkMRMLReposeTransferMeshNode::WriteFields(nlohmann::ordered_json& json) const {
  json[sc::transfer_mesh::kFile] = this->FileName;
  json[sc::transfer_mesh::kSizeMm] = this->SizeMm;
  if (!this->RefinementRecord.vertices.empty()) {
    json[sc::transfer_mesh::kRefinedFromVertices] = this->RefinementRecord.fromVertices;
    json[sc::transfer_mesh::kRefinementVertices] = this->RefinementRecord.vertices;
    json[sc::transfer_mesh::kRefinementMaxErrors] = this->RefinementRecord.maxErrors;
  }
}

bool vtkMRMLReposeTransferMeshNode::ReadFields(const nlohmann::json& json, bool apply,
                                               std::string& error) {
  if (!apply) {
    if (!CheckString(json, sc::transfer_mesh::kFile, error) ||
        !CheckNumber(json, sc::transfer_mesh::kSizeMm, error) ||
        !CheckInteger(json, sc::transfer_mesh::kRefinedFromVertices, error))
      return false;
    for (const char* key :
         {sc::transfer_mesh::kRefinementVertices, sc::transfer_mesh::kRefinementMaxErrors})
      if (json.contains(key) &&
          (!json[key].is_array() ||
           !std::all_of(json[key].begin(), json[key].end(), [](auto& x) { return x.is_number(); })))
        return error = std::string(key) + ": expected an array of numbers", false;
    return true;
  }
  if (json.contains(sc::transfer_mesh::kFile)) this->SetFileName(json[sc::transfer_mesh::kFile]);
  if (json.contains(sc::transfer_mesh::kSizeMm)) this->SetSizeMm(json[sc::transfer_mesh::kSizeMm]);
  if (json.contains(sc::transfer_mesh::kRefinementVertices)) {
    Refinement r;
    r.fromVertices = json.value(sc::transfer_mesh::kRefinedFromVertices, 0);
    r.vertices = json[sc::transfer_mesh::kRefinementVertices].get<std::vector<int>>();
    if (json.contains(sc::transfer_mesh::kRefinementMaxErrors))
      r.maxErrors = json[sc::transfer_mesh::kRefinementMaxErrors].get<std::vector<double>>();
    this->SetRefinement(r);
  }
  return true;
}

void vtkMRMLReposeTransferMeshNode::CopyContent(vtkMRMLReposeNode* other) {
  auto* o = static_cast<vtkMRMLReposeTransferMeshNode*>(other);
  this->SetFileName(o->FileName);
  this->SetSizeMm(o->SizeMm);
  this->SetRefinement(o->RefinementRecord);
  this->CoordinatesFile = o->CoordinatesFile;
  vtkSmartPointer<vtkUnstructuredGrid> mesh;
  if (o->Mesh) {
    mesh = vtkSmartPointer<vtkUnstructuredGrid>::New();
    mesh->DeepCopy(o->Mesh);
  }
  this->SetMesh(mesh);
}
