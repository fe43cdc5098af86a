#include "vtkMRMLReposeTransferMeshNode.h"

#include <vtkObjectFactory.h>
#include "repose/schema/SceneSchema.h"

namespace sc = repose::scene_schema;

vtkStandardNewMacro(vtkMRMLReposeTransferMeshNode);

void vtkMRMLReposeTransferMeshNode::SetMesh(vtkUnstructuredGrid* mesh) {
  this->Mesh = mesh;
  this->Modified();
}

void vtkMRMLReposeTransferMeshNode::WriteFields(nlohmann::ordered_json& json) const {
  json[sc::transfer_mesh::kFile] = this->FileName;
  json[sc::transfer_mesh::kSizeMm] = this->SizeMm;
}

bool vtkMRMLReposeTransferMeshNode::ReadFields(const nlohmann::json& json, bool apply,
                                               std::string& error) {
  if (!apply)
    return CheckString(json, sc::transfer_mesh::kFile, error) &&
           CheckNumber(json, sc::transfer_mesh::kSizeMm, error);
  if (json.contains(sc::transfer_mesh::kFile)) this->SetFileName(json[sc::transfer_mesh::kFile]);
  if (json.contains(sc::transfer_mesh::kSizeMm)) this->SetSizeMm(json[sc::transfer_mesh::kSizeMm]);
  return true;
}

void vtkMRMLReposeTransferMeshNode::CopyContent(vtkMRMLReposeNode* other) {
  auto* o = static_cast<vtkMRMLReposeTransferMeshNode*>(other);
  this->SetFileName(o->FileName);
  this->SetSizeMm(o->SizeMm);
  this->CoordinatesFile = o->CoordinatesFile;
  vtkSmartPointer<vtkUnstructuredGrid> mesh;
  if (o->Mesh) {
    mesh = vtkSmartPointer<vtkUnstructuredGrid>::New();
    mesh->DeepCopy(o->Mesh);
  }
  this->SetMesh(mesh);
}
