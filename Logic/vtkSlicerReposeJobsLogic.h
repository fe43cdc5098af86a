// vtkSlicerReposeJobsLogic: the long steps, a part of the module's logic (vtkSlicerReposeLogic::
// GetJobs). Each runs on the one worker (progress, cancel); the nodes it makes are added to the
// scene by WaitForJob/PollJob on the calling thread, and only when the step finished, so a
// cancelled or failed job leaves the scene and the output folder as they were. What a job leaves
// for the panel lives in nodes, so a saved scene keeps it: the rig's summary and tissue table in
// the parameter node, an export's report and warnings on the segmentation node it made (named by
// the parameter node), a refinement's rounds on the transfer-mesh node it made.
#pragma once

#include "vtkSlicerReposeModuleLogicExport.h"

#include <vtkObject.h>

#include <memory>
#include <string>
#include <vector>

class vtkMRMLReposePoseNode;
class vtkMRMLReposeSegmentationNode;
class vtkMRMLReposeTransferMeshNode;
struct vtkSlicerReposeLogicContext;

class VTK_SLICER_REPOSE_MODULE_LOGIC_EXPORT vtkSlicerReposeJobsLogic : public vtkObject {
 public:
  static vtkSlicerReposeJobsLogic* New();
  vtkTypeMacro(vtkSlicerReposeJobsLogic, vtkObject);

  // `repose rig` as a job: S, the skeleton and the tissue table made from the bones of the organ
  // map at `labelsPath` (the parameter node's image, when set, gives the body's outline), written
  // to `folder` as S.nii.gz, skeleton.json, tissues.csv and rig.json (all four or none). When it
  // finishes, the parameter node's body-part map is folder/S.nii.gz, its tissue table
  // folder/tissues.csv and its rig summary what was found (GetLastRigSummary).
  bool StartRigFromOrganMap(const std::string& labelsPath, const std::string& folder);
  // Where the panel rigs to: `outputFolder`/rig when an output folder is set, else
  // <G's folder>/<G's name without extension>_rig beside the segmentation ("" without a G).
  static std::string DefaultRigFolder(const std::string& labelsPath,
                                      const std::string& outputFolder);
  std::string GetLastRigSummary() const;
  // Cage and transfer mesh of the segmentation's S (separations from the pose, settings from the
  // parameter node), referenced by the pose node.
  bool StartBuildRig(vtkMRMLReposeSegmentationNode* segmentation, vtkMRMLReposePoseNode* pose);
  // The pose node's current frame at full resolution (Core's repose::runPoseFrame): a new
  // segmentation node (posed G, S, image; the report and warnings) referring to its source and
  // pose; with an output folder also the files `repose pose` writes there. Without one, a frame
  // whose posed volumes exceed Output > Memory budget is refused before the work; with one it
  // is made slab by slab into the folder (the same files), and the node holds G and S read back
  // from them as a coarser preview ("(preview 1:F)" in its name, a warning saying where the
  // full-resolution files are; no image).
  bool StartApplyPose(vtkMRMLReposePoseNode* pose, const std::string& outputFolder = "");
  // The live pose's transfer mesh refined for its current frame (seed §4.2), `iterations` rounds:
  // a new transfer-mesh node the pose then refers to. Start live posing again to use it.
  bool StartRefineMesh(vtkMRMLReposePoseNode* pose, int iterations = 3);
  // The last refinement (the newest refined transfer-mesh node of the scene): one line (rounds,
  // vertices before and after, maximum error e^G), and per round its vertices and error.
  std::string GetLastRefinementSummary() const;
  std::vector<int> GetLastRefinementVertices() const;
  std::vector<double> GetLastRefinementMaxErrors() const;

  bool IsJobRunning() const;
  double GetJobProgress() const;
  std::string GetJobStage() const;
  void CancelJob();
  enum JobStatus { JobIdle, JobRunning, JobSucceeded, JobCancelled, JobFailed };
  int WaitForJob();
  int PollJob();

  // The segmentation node the last export made (the parameter node's output; null before).
  vtkMRMLReposeSegmentationNode* GetLastPosedSegmentation() const;
  // What the panel shows of that export: its report.json's quality checks as rows (measured,
  // target, met), each label's volume change (name, %, largest first), the job's warnings.
  struct QualityCheck {
    std::string name, measured, target;
    bool met = false;
  };
  std::vector<QualityCheck> GetLastPoseQuality() const;
  struct LabelChange {
    int value = 0;
    std::string name;
    double changePercent = 0;
  };
  std::vector<LabelChange> GetLastPoseLabelChanges() const;
  std::vector<std::string> GetLastPoseWarnings() const;
  const std::string& GetLastErrorMessage() const;

 protected:
  vtkSlicerReposeJobsLogic();
  ~vtkSlicerReposeJobsLogic() override;
  friend class vtkSlicerReposeLogic;
  void SetContext(std::shared_ptr<vtkSlicerReposeLogicContext> context) {
    this->Context = std::move(context);
  }
  vtkMRMLReposeTransferMeshNode* LastRefinedMesh() const;

 private:
  vtkSlicerReposeJobsLogic(const vtkSlicerReposeJobsLogic&) = delete;
  void operator=(const vtkSlicerReposeJobsLogic&) = delete;

  std::shared_ptr<vtkSlicerReposeLogicContext> Context;
};
