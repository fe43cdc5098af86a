// vtkMRMLReposeTransferMeshNode: the labelled tetrahedral transfer mesh (an unstructured grid of
// tets in RAS mm, cell array "label" = body part of S) with the size it was built with.
#pragma once

#include "vtkMRMLReposeNode.h"

#include <vtkSmartPointer.h>
#include <vtkUnstructuredGrid.h>

class VTK_SLICER_REPOSE_MODULE_MRML_EXPORT vtkMRMLReposeTransferMeshNode
    : public vtkMRMLReposeNode {
 public:
  static vtkMRMLReposeTransferMeshNode* New();
  vtkTypeMacro(vtkMRMLReposeTransferMeshNode, vtkMRMLReposeNode);
  const char* GetNodeClassName() const override { return "vtkMRMLReposeTransferMeshNode"; }

  vtkUnstructuredGrid* GetMesh() const { return this->Mesh; }
  void SetMesh(vtkUnstructuredGrid* mesh);

  const std::string& GetFileName() const { return this->FileName; }
  void SetFileName(const std::string& name) { this->SetField(this->FileName, name); }
  double GetSizeMm() const { return this->SizeMm; }  // 0: the automatic size
  void SetSizeMm(double mm) { this->SetField(this->SizeMm, mm); }

 protected:
  vtkMRMLReposeTransferMeshNode() = default;
  void WriteFields(nlohmann::ordered_json& json) const override;
  bool ReadFields(const nlohmann::json& json, bool apply, std::string& error) override;
  void CopyContent(vtkMRMLReposeNode* other) override;

 private:
  vtkSmartPointer<vtkUnstructuredGrid> Mesh;
  std::string FileName;
  double SizeMm = 0;
};
