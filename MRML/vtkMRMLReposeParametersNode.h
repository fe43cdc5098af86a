// vtkMRMLReposeParametersNode: the Repose module's state (inputs, cage and mesh settings, output),
// Slicer-shaped (New, PrintSelf, Copy) with a flat JSON form in place of MRML scene XML.
#pragma once

#include "vtkSlicerReposeModuleMRMLExport.h"

#include <vtkObject.h>

#include <string>

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
  double CageDilationMm = 5.0;
  double TransferMeshSizeMm = 0.0;
  int OutputMemoryBudgetMB = 4096;
  std::string OutputFolder;

 private:
  vtkMRMLReposeParametersNode(const vtkMRMLReposeParametersNode&) = delete;
  void operator=(const vtkMRMLReposeParametersNode&) = delete;

  int DisableModified = 0;
  bool ModifiedWhileDisabled = false;
};
