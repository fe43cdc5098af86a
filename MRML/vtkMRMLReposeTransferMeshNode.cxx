#include "vtkMRMLReposeTransferMeshNode.h"

#include <vtkObjectFactory.h>

vtkStandardNewMacro(vtkMRMLReposeTransferMeshNode);

void vtkMRMLReposeTransferMeshNode::SetMesh(vtkUnstructuredGrid* mesh) {
  this->Mesh = mesh;
  this->Modified();
}

void vtkMRMLReposeTransferMeshNode::WriteFields(nlohmann::ordered_json& json) const {
  json["FileName"] = this->FileName;
  json["SizeMm"] = this->SizeMm;
}

bool vtkMRMLReposeTransferMeshNode::ReadFields(const nlohmann::json& json, bool apply,
                                               std::string& error) {
  if (!apply) return CheckString(json, "FileName", error) && CheckNumber(json, "SizeMm", error);
  if (json.contains("FileName")) this->SetFileName(json["FileName"]);
  if (json.contains("SizeMm")) this->SetSizeMm(json["SizeMm"]);
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
