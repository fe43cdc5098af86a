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
  // Where this mesh's Green coordinates are saved (a scene's tm.green, beside FileName), set when
  // a scene is loaded or saved; "" when none. Not part of scene.json: the file is found beside
  // the mesh's, and it is used only if written for this mesh and its cage (CageDeformation).
  const std::string& GetCoordinatesFile() const { return this->CoordinatesFile; }
  void SetCoordinatesFile(const std::string& path) { this->CoordinatesFile = path; }
  double GetSizeMm() const { return this->SizeMm; }  // 0: the automatic size
  void SetSizeMm(double mm) { this->SetField(this->SizeMm, mm); }

 protected:
  vtkMRMLReposeTransferMeshNode() = default;
  void WriteFields(nlohmann::ordered_json& json) const override;
  bool ReadFields(const nlohmann::json& json, bool apply, std::string& error) override;
  void CopyContent(vtkMRMLReposeNode* other) override;

 private:
  vtkSmartPointer<vtkUnstructuredGrid> Mesh;
  std::string FileName, CoordinatesFile;
  double SizeMm = 0;
};
