// vtkSlicerReposeLiveLogic: live posing, a part of the module's logic (vtkSlicerReposeLogic::
// GetLive). A pose node whose rig is built is prepared once for interaction (Core's
// repose::LiveSession, on the worker); afterwards every change of that node's pose (an edit,
// undo, redo, its keyframe) is one frame on the calling thread, and the views ask for their
// slices in one call. The node's pose is parsed already: a drag parses no text.
#pragma once

#include "vtkSlicerReposeModuleLogicExport.h"

#include <vtkImageData.h>
#include <vtkObject.h>
#include <vtkPolyData.h>
#include <vtkSmartPointer.h>

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace repose {
class LiveSession;
class LivePredictionWorker;
}  // namespace repose
class vtkMRMLReposePoseNode;
struct vtkSlicerReposeLogicContext;

class VTK_SLICER_REPOSE_MODULE_LOGIC_EXPORT vtkSlicerReposeLiveLogic : public vtkObject {
 public:
  static vtkSlicerReposeLiveLogic* New();
  vtkTypeMacro(vtkSlicerReposeLiveLogic, vtkObject);

  // Prepares a pose node whose rig is built (G converted, the transfer mesh embedded in the
  // cage, the groups resolved, both systems factorized) on the worker like every long step
  // (the jobs' WaitForJob/PollJob commits it). Afterwards every change of that pose node re-solves
  // the frame at preview precision on the calling thread and fires ModifiedEvent.
  bool StartLivePose(vtkMRMLReposePoseNode* pose);
  void StopLivePose();
  vtkMRMLReposePoseNode* GetLivePose() const;
  // Re-solves the live frame from the pose node now. False with a message on failure.
  bool UpdateLiveFrame();
  // Wall time of the last live frame solve, and of the labels of the last slice (ms).
  double GetLiveFrameMilliseconds() const;
  double GetLiveSliceMilliseconds() const { return this->SliceMilliseconds; }
  // The posed cage and the posed body surface (the transfer mesh's outer faces), RAS mm; null
  // without a live pose.
  vtkPolyData* GetLiveCage() const { return this->Cage; }
  vtkPolyData* GetLiveBodySurface() const { return this->Body; }
  // RAS box (xmin, xmax, ymin, ymax, zmin, zmax) of the rest and posed body together, where the
  // views place their slices; and the rest body's centre, where they start.
  std::array<double, 6> GetLiveBounds() const;
  std::array<double, 3> GetLiveRestCenter() const;
  // The live rig's cage at rest (RAS mm, one entry per cage vertex), the cage vertices a group
  // of the live pose moves, those of a body part of S (as a group selecting that part would
  // move), and S's parts (label, name).
  std::vector<std::array<double, 3>> GetLiveRestCage() const;
  std::vector<int> GetLiveGroupVertices(const std::string& group) const;
  std::vector<int> GetLiveCageVerticesOfPart(int label) const;
  std::vector<std::pair<int, std::string>> GetLiveBodyParts() const;
  // What the live frame predicts of the export's volumes (repose::LivePrediction: the frame
  // restored as the export restores it, then the volume change per part), once per frame.
  // The panel asks for it when a drag ends (RequestLivePrediction: on a worker thread, a new
  // frame cancels it) and shows it when PeekLivePrediction has it, so its event loop never waits
  // on it; GetLivePrediction waits (scripts, tests).
  struct LivePrediction {
    bool valid = false;
    bool pending = false;  // PeekLivePrediction: being computed for the frame at hand
    double bodyChangePercent = 0;
    std::string worstPart, draggedBy;
    double worstPartChangePercent = 0;
    bool met = true;
    std::string missed;  // one line, "" when met
  };
  LivePrediction GetLivePrediction();
  void RequestLivePrediction();
  LivePrediction PeekLivePrediction();
  // The data probe's input side: G at rest at a RAS point (the nearest voxel's label; -1 outside
  // its grid or without a live pose), a label's display name, a body part's name.
  int GetLiveRestLabelAt(double r, double a, double s) const;
  std::string GetLiveLabelName(int value) const;
  std::string GetLivePartName(int value) const;
  // The skeleton's joints where the live frame puts them. Empty without a skeleton.
  struct LiveJoint {
    std::string name;
    std::array<double, 3> centre{};                                   // RAS mm, posed
    std::vector<std::pair<std::string, std::array<double, 3>>> axes;  // unit, posed
  };
  std::vector<LiveJoint> GetLiveJoints() const;
  // The live frame's labels of G on the slice plane through `positionMm` (orientation 0 axial,
  // 1 coronal, 2 sagittal), square pixels, `pixels` across the box's larger in-plane side: a
  // one-voxel-thick label image on RAS axes. Null without a live pose.
  vtkSmartPointer<vtkImageData> ComputeLiveSlice(int orientation, double positionMm, int pixels);
  // What the three slice views show, in one call: per orientation (axial, coronal, sagittal, at
  // positionsMm[o]) the labels, the segmentation's image on the same grid (null without one) and,
  // with `parts`, S (or G's body mask) for the outlines; each label slice's time.
  struct LiveSlices {
    std::array<vtkSmartPointer<vtkImageData>, 3> labels, images, parts;
    std::array<double, 3> labelMilliseconds{};
  };
  LiveSlices ComputeLiveSlices(const std::array<double, 3>& positionsMm, int pixels, bool parts);
  // A grey window for the image (soft-tissue CT window for Hounsfield units, else the 1st..99th
  // percentile). Empty without a live image.
  struct ImageWindow {
    double window = 0, level = 0;
  };
  std::optional<ImageWindow> GetLiveImageWindow() const;
  const std::string& GetLastErrorMessage() const;

 protected:
  vtkSlicerReposeLiveLogic();
  ~vtkSlicerReposeLiveLogic() override;
  friend class vtkSlicerReposeLogic;
  void SetContext(std::shared_ptr<vtkSlicerReposeLogicContext> context) {
    this->Context = std::move(context);
  }
  // StopLivePose without the ModifiedEvent.
  void ReleaseLivePose();
  void OnLivePoseModified();
  bool SolveLiveFrame();

 private:
  vtkSlicerReposeLiveLogic(const vtkSlicerReposeLiveLogic&) = delete;
  void operator=(const vtkSlicerReposeLiveLogic&) = delete;

  std::shared_ptr<vtkSlicerReposeLogicContext> Context;
  std::shared_ptr<repose::LiveSession> Session;
  std::unique_ptr<repose::LivePredictionWorker> Predictions;
  std::uint64_t FrameSerial = 0;  // one per solved frame: which frame a prediction is of
  vtkSmartPointer<vtkMRMLReposePoseNode> Pose;
  unsigned long PoseObserverTag = 0;
  vtkSmartPointer<vtkPolyData> Cage, Body;
  double SliceMilliseconds = 0;
};
