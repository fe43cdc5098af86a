// vtkSlicerReposeLogic: the Repose module's logic, thin as a Slicer module's logic is. It holds the
// parameter node (the module's state: inputs, settings, the last results' nodes) and the scene,
// shows the input volume the parameter node names, reads segmentations and poses into nodes, and
// saves and opens scene folders (with the parameter node, so a reopened scene restores the panel).
// Its three parts, one class each, own the rest: the long steps (GetJobs), live posing (GetLive)
// and pose editing (GetPoseEdits). All share one scene, one worker and one error message; each
// part's ModifiedEvent is also this logic's. Errors become one-line messages, never crashes.
#pragma once

#include "vtkSlicerReposeModuleLogicExport.h"

#include "vtkMRMLReposeParametersNode.h"
#include "vtkSlicerReposeJobsLogic.h"
#include "vtkSlicerReposeLiveLogic.h"
#include "vtkSlicerReposePoseEditLogic.h"

#include <vtkImageData.h>
#include <vtkLookupTable.h>
#include <vtkMatrix4x4.h>
#include <vtkObject.h>
#include <vtkSmartPointer.h>

#include <memory>
#include <string>
#include <vector>

class vtkMRMLReposePoseNode;
class vtkMRMLReposeScene;
class vtkMRMLReposeSegmentationNode;
struct vtkSlicerReposeLogicContext;

class VTK_SLICER_REPOSE_MODULE_LOGIC_EXPORT vtkSlicerReposeLogic : public vtkObject {
 public:
  static vtkSlicerReposeLogic* New();
  vtkTypeMacro(vtkSlicerReposeLogic, vtkObject);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  // The parts.
  vtkSlicerReposeJobsLogic* GetJobs() const { return this->Jobs; }
  vtkSlicerReposeLiveLogic* GetLive() const { return this->Live; }
  vtkSlicerReposePoseEditLogic* GetPoseEdits() const { return this->PoseEdits; }

  // The logic follows its parameter node: when the node's input segmentation path changes, the
  // volume is (re)loaded, or cleared when the path becomes empty. Fires ModifiedEvent after. The
  // logic starts with a node of its own; null gives it a new one (the state lives in it).
  void SetParameterNode(vtkMRMLReposeParametersNode* node);
  vtkMRMLReposeParametersNode* GetParameterNode() const;

  // Reads `path` (any format repose::readVolume knows) and makes it the current volume; also
  // writes the path to the parameter node. On failure the current volume is cleared, false is
  // returned and GetLastErrorMessage() holds one line naming the file and the problem.
  bool LoadVolume(const std::string& path);
  void ClearVolume();
  // The current volume: voxels in RAS mm geometry, its IJK->RAS matrix, a display lookup table
  // of layer 0, the names of its label table by layer and value (the file's, then what the
  // tissue table or the label convention names), the distinct non-zero labels present (-1 for an
  // intensity image or none), the path of the last load attempt.
  vtkImageData* GetVolumeImageData() const { return this->VolumeImageData; }
  vtkMatrix4x4* GetVolumeIJKToRASMatrix() const { return this->VolumeIJKToRASMatrix; }
  vtkLookupTable* GetVolumeLookupTable() const { return this->VolumeLookupTable; }
  struct LabelName {
    int layer = 0, value = 0;
    std::string name;
  };
  const std::vector<LabelName>& GetVolumeLabelNames() const { return this->VolumeLabelNames; }
  int GetVolumeLabelsPresent() const { return this->VolumeLabelsPresent; }
  const std::string& GetVolumePath() const { return this->VolumePath; }
  const std::string& GetLastErrorMessage() const;
  // Several lines for an info box: dimensions, spacing, orientation codes, scalar type, layers,
  // labels present and named. Empty when no volume is loaded.
  std::string GetVolumeSummary() const;
  // A display lookup table of a label map a node holds (its label table's colours, layer 0).
  static vtkSmartPointer<vtkLookupTable> GetLabelLookupTable(vtkImageData* labelMap);

  // The scene of nodes the parts work on. The logic creates an empty one; a caller may give its
  // own.
  void SetScene(vtkMRMLReposeScene* scene);
  vtkMRMLReposeScene* GetScene() const;
  // Reads G, S (optional) and an image (optional) into a new segmentation node. Null on failure,
  // with GetLastErrorMessage() naming the file and the problem.
  vtkMRMLReposeSegmentationNode* AddSegmentation(const std::string& labelsPath,
                                                 const std::string& partsPath = "",
                                                 const std::string& imagePath = "");
  // Whether `seg` holds what these paths hold now (read from them, none changed since): the panel
  // then builds on it again instead of reading G, S and the image anew.
  bool IsSegmentationOf(vtkMRMLReposeSegmentationNode* seg, const std::string& labelsPath,
                        const std::string& partsPath, const std::string& imagePath) const;
  // Reads and validates a pose file into a new pose node (null and a message on failure).
  vtkMRMLReposePoseNode* AddPose(const std::string& path);
  // A scene folder: scene.json (the nodes and the parameter node) and the data files its nodes
  // name; saving writes every file atomically and scene.json last; loading replaces the scene
  // only if every file read. OpenScene is what a user's open does: LoadScene, then the parameter
  // node as saved, its paths and active pose following the folder's nodes, G shown, a rigged
  // pose live (a job). False with a message.
  bool SaveScene(const std::string& folder);
  bool LoadScene(const std::string& folder);
  bool OpenScene(const std::string& folder);

 protected:
  vtkSlicerReposeLogic();
  ~vtkSlicerReposeLogic() override;
  void OnParameterNodeModified();
  // LoadVolume, or with `held` (a node's label map, read already) that image instead of the
  // file at `path`, which then only names it.
  bool ShowVolume(const std::string& path, vtkImageData* held);
  void ResetVolume();  // no volume shown
  // LoadScene, and the saved parameter node's JSON ("" for none) when asked.
  bool LoadSceneFolder(const std::string& folder, std::string* parameters);

 private:
  vtkSlicerReposeLogic(const vtkSlicerReposeLogic&) = delete;
  void operator=(const vtkSlicerReposeLogic&) = delete;

  std::shared_ptr<vtkSlicerReposeLogicContext> Context;
  vtkSmartPointer<vtkSlicerReposeJobsLogic> Jobs;
  vtkSmartPointer<vtkSlicerReposeLiveLogic> Live;
  vtkSmartPointer<vtkSlicerReposePoseEditLogic> PoseEdits;
  unsigned long ParameterNodeObserverTag = 0;
  // The input box's volume: a view of the file the parameter node names (read again from it).
  vtkSmartPointer<vtkImageData> VolumeImageData;
  vtkSmartPointer<vtkMatrix4x4> VolumeIJKToRASMatrix;
  vtkSmartPointer<vtkLookupTable> VolumeLookupTable;
  std::vector<LabelName> VolumeLabelNames;
  int VolumeLabelsPresent = -1;
  std::string VolumePath;
  std::string VolumeLabelNote;               // where the labels' names came from, if not the file
  std::vector<std::string> VolumeReadNotes;  // what the reader decided (ReadOptions::note)
  // FilesStamp of VolumePath and the tissue table when VolumeImageData is a label map read from
  // that file ("" otherwise): AddSegmentation of the same, unchanged file shares the image
  // instead of reading it again.
  std::string VolumeStamp;
};
