// vtkMRMLReposeParametersNode: the Repose module's state (inputs, cage and mesh settings, output),
// Slicer-shaped (New, PrintSelf, Copy) with a flat JSON form in place of MRML scene XML.
#pragma once

#include "vtkSlicerReposeModuleMRMLExport.h"

#include <vtkObject.h>

#include <string>
#include <vector>

class VTK_SLICER_REPOSE_MODULE_MRML_EXPORT vtkMRMLReposeParametersNode : public vtkObject {
 public:
  static vtkMRMLReposeParametersNode* New();
  vtkTypeMacro(vtkMRMLReposeParametersNode, vtkObject);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  // Copies every field; observers see at most one ModifiedEvent, and none if nothing changed.
  void Copy(vtkMRMLReposeParametersNode* other);

  // One JSON object, one key per field (the names below without Get/Set).
  std::string WriteJSON() const;
  // Sets the fields present in `json` (others keep their value) through the setters, so ranges
  // are enforced. On a parse or type error returns false, fills `error` and changes nothing.
  bool ReadJSON(const std::string& json, std::string* error = nullptr);

  // Slicer-style batching: between StartModify and EndModify, ModifiedEvent is held back and
  // fired once at the end if anything changed. Nests.
  int StartModify();
  void EndModify(int previousDisableState);
  void Modified() override;

  // Input segmentation, by node ID (when a scene holds it) and by file.
  vtkSetMacro(InputSegmentationNodeID, std::string);
  const std::string& GetInputSegmentationNodeID() const { return this->InputSegmentationNodeID; }
  vtkSetMacro(InputSegmentationPath, std::string);
  const std::string& GetInputSegmentationPath() const { return this->InputSegmentationPath; }
  // Body-part (limb) map S; empty means the binary mask of the input.
  vtkSetMacro(BodyPartMapPath, std::string);
  const std::string& GetBodyPartMapPath() const { return this->BodyPartMapPath; }
  // Optional intensity image I deformed along with the labels.
  vtkSetMacro(ImagePath, std::string);
  const std::string& GetImagePath() const { return this->ImagePath; }

  // Target number of cage vertices, clamped to [50, 2000].
  void SetCageVertexCount(int count);
  int GetCageVertexCount() const { return this->CageVertexCount; }
  static constexpr int CageVertexCountMin = 50;
  static constexpr int CageVertexCountMax = 2000;
  // Dilation of the body mask before the cage surface is extracted, in mm, clamped to [0, 1000].
  void SetCageDilationMm(double mm);
  double GetCageDilationMm() const { return this->CageDilationMm; }
  // Uniform initial tetrahedron size of the transfer mesh in mm, clamped to [0, 1000];
  // 0 means automatic (5% of the grid diagonal, as in the seed paper).
  void SetTransferMeshSizeMm(double mm);
  double GetTransferMeshSizeMm() const { return this->TransferMeshSizeMm; }
  // Peak memory allowed when writing the full-resolution output, in MiB, clamped to
  // [64, 1048576]; larger volumes are streamed out of core.
  void SetOutputMemoryBudgetMB(int mib);
  int GetOutputMemoryBudgetMB() const { return this->OutputMemoryBudgetMB; }

  vtkSetMacro(OutputFolder, std::string);
  const std::string& GetOutputFolder() const { return this->OutputFolder; }

  // The pose being edited: its file, its node in the Logic's scene, and the handle group the
  // panel's rotation controls act on.
  vtkSetMacro(PosePath, std::string);
  const std::string& GetPosePath() const { return this->PosePath; }
  vtkSetMacro(ActivePoseNodeID, std::string);
  const std::string& GetActivePoseNodeID() const { return this->ActivePoseNodeID; }
  vtkSetMacro(ActiveGroup, std::string);
  const std::string& GetActiveGroup() const { return this->ActiveGroup; }
  // The cage vertices selected in the 3D view (indices, sorted, no repeats; negatives dropped):
  // what "New group from selection" makes a handle group of.
  void SetSelectedCageVertices(const std::vector<int>& vertices);
  const std::vector<int>& GetSelectedCageVertices() const { return this->SelectedCageVertices; }
  // The body part (label of S) the selection was made from, 0 when it was picked vertex by
  // vertex: a group made from it selects the part, and so carries the part's tissue too.
  void SetSelectedBodyPart(int label);
  int GetSelectedBodyPart() const { return this->SelectedBodyPart; }
  // Opacity of the labels over the image in the slice views, clamped to [0, 1].
  void SetLabelOpacity(double opacity);
  double GetLabelOpacity() const { return this->LabelOpacity; }
  // What the views draw besides the labels: the body-part map S as outlines in the slice views
  // (each part in its own colour), and the skeleton's joints in the 3D view (spheres with their
  // names and axes, where the live frame puts them).
  void SetShowBodyParts(bool show);
  bool GetShowBodyParts() const { return this->ShowBodyParts; }
  void SetShowJoints(bool show);
  bool GetShowJoints() const { return this->ShowJoints; }

  // Tissue table (CSV, docs/FORMATS.md) for the reports of pose jobs; empty: the phantom's table
  // when G's labels are the phantom's, else none (no masses, no bone check). Rigging from the
  // organ map sets it to the rig folder's tissues.csv.
  vtkSetMacro(TissueTablePath, std::string);
  const std::string& GetTissueTablePath() const { return this->TissueTablePath; }
  // What the last rig from the organ map found (convention, joints, what it could not make).
  vtkSetMacro(RigSummary, std::string);
  const std::string& GetRigSummary() const { return this->RigSummary; }
  // The segmentation node the last export of a pose made (its report and warnings are on it).
  vtkSetMacro(OutputSegmentationNodeID, std::string);
  const std::string& GetOutputSegmentationNodeID() const { return this->OutputSegmentationNodeID; }

 protected:
  vtkMRMLReposeParametersNode() = default;
  ~vtkMRMLReposeParametersNode() override = default;

  // The single list of fields: print, write, read and copy all walk it, so they list the same
  // fields in the same order. `f(name, member pointer, setter pointer)`.
  template <class F>
  static void ForEachField(F&& f);

  std::string InputSegmentationNodeID;
  std::string InputSegmentationPath;
  std::string BodyPartMapPath;
  std::string ImagePath;
  int CageVertexCount = 300;
  double CageDilationMm = 10.0;  // as `repose pose --dilate-mm`
  double TransferMeshSizeMm = 0.0;
  int OutputMemoryBudgetMB = 0;  // 0: half the physical memory (repose pose --memory's default)
  std::string OutputFolder;
  std::string PosePath;
  std::string ActivePoseNodeID;
  std::string ActiveGroup;
  std::vector<int> SelectedCageVertices;
  int SelectedBodyPart = 0;
  double LabelOpacity = 0.8;
  bool ShowBodyParts = false;
  bool ShowJoints = true;
  std::string TissueTablePath;
  std::string RigSummary;
  std::string OutputSegmentationNodeID;

 private:
  vtkMRMLReposeParametersNode(const vtkMRMLReposeParametersNode&) = delete;
  void operator=(const vtkMRMLReposeParametersNode&) = delete;

  int DisableModified = 0;
  bool ModifiedWhileDisabled = false;
};
