// vtkMRMLReposeTransferMeshNode: the labelled tetrahedral transfer mesh (an unstructured grid of
// tets in RAS mm, cell array "label" = body part of S) with the size it was built with.
#pragma once

#include "vtkMRMLReposeNode.h"

#include <vtkSmartPointer.h>
#include <vtkUnstructuredGrid.h>

#include <vector>

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
  // A mesh refined for a pose's frame (the Logic's StartRefineMesh): the vertices of the mesh it
  // was refined from, and per round its vertices and maximum error e^G. Empty for a mesh built
  // whole. Saved with the scene.
  struct Refinement {
    int fromVertices = 0;
    std::vector<int> vertices;
    std::vector<double> maxErrors;
    bool operator==(const Refinement& o) const {
      return fromVertices == o.fromVertices && vertices == o.vertices && maxErrors == o.maxErrors;
    }
  };
  const Refinement& GetRefinement() const { return this->RefinementRecord; }
  void SetRefinement(const Refinement& r) { this->SetField(this->RefinementRecord, r); }

 protected:
  vtkMRMLReposeTransferMeshNode() = default;
  void WriteFields(nlohmann::ordered_json& json) const override;
  bool ReadFields(const nlohmann::json& json, bool apply, std::string& error) override;
  void CopyContent(vtkMRMLReposeNode* other) override;

 private:
  vtkSmartPointer<vtkUnstructuredGrid> Mesh;
  std::string FileName, CoordinatesFile;
  double SizeMm = 0;
  Refinement RefinementRecord;
};
