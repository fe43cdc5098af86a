// vtkMRMLReposeCageNode: the control cage (a closed triangle mesh, RAS mm) with the settings it
// was built with and its named handle groups (cage vertex indices), which the GUI selects and
// moves and pose files name.
#pragma once

#include "vtkMRMLReposeNode.h"

#include <vtkPolyData.h>
#include <vtkSmartPointer.h>

#include <vector>

class VTK_SLICER_REPOSE_MODULE_MRML_EXPORT vtkMRMLReposeCageNode : public vtkMRMLReposeNode {
 public:
  static vtkMRMLReposeCageNode* New();
  vtkTypeMacro(vtkMRMLReposeCageNode, vtkMRMLReposeNode);
  const char* GetNodeClassName() const override { return "vtkMRMLReposeCageNode"; }

  vtkPolyData* GetMesh() const { return this->Mesh; }
  void SetMesh(vtkPolyData* mesh);

  const std::string& GetFileName() const { return this->FileName; }
  void SetFileName(const std::string& name) { this->SetField(this->FileName, name); }
  int GetTargetVertexCount() const { return this->TargetVertexCount; }
  void SetTargetVertexCount(int n) { this->SetField(this->TargetVertexCount, n); }
  double GetDilationMm() const { return this->DilationMm; }
  void SetDilationMm(double mm) { this->SetField(this->DilationMm, mm); }

  // The setting the cage was built with, asked and tried (Core's CageChoice::json as text; ""
  // when unknown: a cage read from a file).
  const std::string& GetCageChoice() const { return this->CageChoice; }
  void SetCageChoice(const std::string& json) { this->SetField(this->CageChoice, json); }

  struct HandleGroup {
    std::string name;
    std::vector<int> vertices;
    bool operator==(const HandleGroup& o) const { return name == o.name && vertices == o.vertices; }
  };
  const std::vector<HandleGroup>& GetHandleGroups() const { return this->HandleGroups; }
  void SetHandleGroups(const std::vector<HandleGroup>& groups) {
    this->SetField(this->HandleGroups, groups);
  }

 protected:
  vtkMRMLReposeCageNode() = default;
  void WriteFields(nlohmann::ordered_json& json) const override;
  bool ReadFields(const nlohmann::json& json, bool apply, std::string& error) override;
  void CopyContent(vtkMRMLReposeNode* other) override;

 private:
  vtkSmartPointer<vtkPolyData> Mesh;
  std::string FileName;
  int TargetVertexCount = 300;
  double DilationMm = 10;
  std::string CageChoice;
  std::vector<HandleGroup> HandleGroups;
};
