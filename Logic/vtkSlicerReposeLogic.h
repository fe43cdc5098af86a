// vtkSlicerReposeLogic: the Repose module's logic. Holds the parameter node and the volume it
// names, loaded through Core and converted to VTK; errors become one-line messages, never crashes.
#pragma once

#include "vtkSlicerReposeModuleLogicExport.h"

#include <repose/volume/LabelTable.h>

#include "vtkMRMLReposeParametersNode.h"

#include <vtkImageData.h>
#include <vtkLookupTable.h>
#include <vtkMatrix4x4.h>
#include <vtkObject.h>
#include <vtkSmartPointer.h>

#include <string>

class VTK_SLICER_REPOSE_MODULE_LOGIC_EXPORT vtkSlicerReposeLogic : public vtkObject {
 public:
  static vtkSlicerReposeLogic* New();
  vtkTypeMacro(vtkSlicerReposeLogic, vtkObject);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  // The logic follows its parameter node: when the node's input segmentation path changes, the
  // volume is (re)loaded, or cleared when the path becomes empty. Fires ModifiedEvent after.
  void SetParameterNode(vtkMRMLReposeParametersNode* node);
  vtkMRMLReposeParametersNode* GetParameterNode() const { return this->ParameterNode; }

  // Reads `path` (any format repose::readVolume knows) and makes it the current volume; also
  // writes the path to the parameter node. On failure the current volume is cleared, false is
  // returned and GetLastErrorMessage() holds one line naming the file and the problem.
  bool LoadVolume(const std::string& path);
  void ClearVolume();

  // The current volume: voxels in RAS mm geometry (origin/spacing/direction), its IJK->RAS
  // matrix, its label table and a display lookup table of layer 0. Null/empty when none.
  vtkImageData* GetVolumeImageData() const { return this->VolumeImageData; }
  vtkMatrix4x4* GetVolumeIJKToRASMatrix() const { return this->VolumeIJKToRASMatrix; }
  vtkLookupTable* GetVolumeLookupTable() const { return this->VolumeLookupTable; }
  const repose::LabelTable& GetVolumeLabelTable() const { return this->VolumeLabelTable; }
  // Distinct non-zero (layer, value) pairs in the voxels; -1 when the volume is not a
  // label map (an intensity image) or there is none.
  int GetVolumeLabelsPresent() const { return this->VolumeLabelsPresent; }
  // The path of the last load attempt (successful or not).
  const std::string& GetVolumePath() const { return this->VolumePath; }
  const std::string& GetLastErrorMessage() const { return this->LastErrorMessage; }

  // Several lines for an info box: dimensions, spacing, orientation codes, scalar type, layers,
  // labels present and named. Empty when no volume is loaded.
  std::string GetVolumeSummary() const;

 protected:
  vtkSlicerReposeLogic();
  ~vtkSlicerReposeLogic() override;
  void OnParameterNodeModified();

 private:
  vtkSlicerReposeLogic(const vtkSlicerReposeLogic&) = delete;
  void operator=(const vtkSlicerReposeLogic&) = delete;

  vtkSmartPointer<vtkMRMLReposeParametersNode> ParameterNode;
  unsigned long ParameterNodeObserverTag = 0;
  vtkSmartPointer<vtkImageData> VolumeImageData;
  vtkSmartPointer<vtkMatrix4x4> VolumeIJKToRASMatrix;
  vtkSmartPointer<vtkLookupTable> VolumeLookupTable;
  repose::LabelTable VolumeLabelTable;
  int VolumeLabelsPresent = -1;
  std::string VolumePath;
  std::string LastErrorMessage;
};
