// vtkSlicerReposeLogic: the Repose module's logic. Holds the parameter node and the volume it
// names, loaded through Core and converted to VTK; errors become one-line messages, never crashes.
#pragma once

#include "vtkSlicerReposeModuleLogicExport.h"

#include "vtkMRMLReposeParametersNode.h"
#include "vtkSlicerReposePoseHistory.h"

#include <vtkImageData.h>
#include <vtkLookupTable.h>
#include <vtkMatrix4x4.h>
#include <vtkObject.h>
#include <vtkPolyData.h>
#include <vtkSmartPointer.h>

#include <array>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace repose {
class PoseJob;
struct Pose;
class Volume;
}  // namespace repose
class vtkMRMLReposeCageNode;
class vtkMRMLReposeNode;
class vtkMRMLReposePoseNode;
class vtkMRMLReposeScene;
class vtkMRMLReposeSegmentationNode;
class vtkMRMLReposeTransferMeshNode;
class vtkSlicerReposeJob;

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
  // The names of its label table (the file's), by layer and value. The display names (and the
  // lookup table) also hold what the tissue table or the label convention names of the rest.
  struct LabelName {
    int layer = 0, value = 0;
    std::string name;
  };
  const std::vector<LabelName>& GetVolumeLabelNames() const { return this->VolumeLabelNames; }
  // Distinct non-zero (layer, value) pairs in the voxels; -1 when the volume is not a
  // label map (an intensity image) or there is none.
  int GetVolumeLabelsPresent() const { return this->VolumeLabelsPresent; }
  // The path of the last load attempt (successful or not).
  const std::string& GetVolumePath() const { return this->VolumePath; }
  const std::string& GetLastErrorMessage() const { return this->LastErrorMessage; }

  // Several lines for an info box: dimensions, spacing, orientation codes, scalar type, layers,
  // labels present and named. Empty when no volume is loaded.
  std::string GetVolumeSummary() const;
  // A display lookup table of a label map a node holds (the colours of the label table it
  // carries, layer 0); null for a null image.
  static vtkSmartPointer<vtkLookupTable> GetLabelLookupTable(vtkImageData* labelMap);

  // ---- The pipeline on the nodes of a scene (vtkSlicerReposeLogicPipeline.cxx) ----
  // The logic creates an empty scene; a caller may give its own.
  void SetScene(vtkMRMLReposeScene* scene);
  vtkMRMLReposeScene* GetScene() const;

  // Reads G, S (optional) and an image (optional) on this thread into a new segmentation node.
  // Null on failure, with GetLastErrorMessage() naming the file and the problem.
  vtkMRMLReposeSegmentationNode* AddSegmentation(const std::string& labelsPath,
                                                 const std::string& partsPath = "",
                                                 const std::string& imagePath = "");
  // Whether `seg` holds what these paths hold now: it was read from them (AddSegmentation, or a
  // scene opened from its folder) and none has changed since. The panel then builds on it again
  // instead of reading G, S and the image anew into one more node.
  bool IsSegmentationOf(vtkMRMLReposeSegmentationNode* seg, const std::string& labelsPath,
                        const std::string& partsPath, const std::string& imagePath) const;
  // Reads and validates a pose file into a new pose node (null and a message on failure).
  vtkMRMLReposePoseNode* AddPose(const std::string& path);
  // What a panel shows of a pose node, parsed once per change of the node: the groups a user can
  // turn (not fixed, in the file's order), the number of keyframes, the separations as
  // "part A | part B" (names, else label values). `valid` is false, with `error`, for a pose
  // text that does not parse.
  struct PoseSummary {
    bool valid = false;
    std::string error;
    std::vector<std::string> movableGroups;
    int keyframes = 0;
    std::vector<std::string> separations;
  };
  PoseSummary GetPoseSummary(vtkMRMLReposePoseNode* pose) const;

  // Long steps run one at a time on a worker thread; the nodes they make are added to the scene
  // by WaitForJob/PollJob on the calling thread, and only when the step finished, so a cancelled
  // or failed job leaves the scene and the output folder as they were.
  // `repose rig` as a job: the body-part map S, the skeleton and the tissue table made from the
  // bones of the organ map at `labelsPath` (its label convention told from its names or IDs; the
  // parameter node's image, when set, gives the body's outline), written to `folder` as
  // S.nii.gz, skeleton.json, tissues.csv and rig.json (all four or none). When it finishes, the
  // parameter node's body-part map is folder/S.nii.gz and the tissue table folder/tissues.csv;
  // GetLastRigSummary says what was found.
  bool StartRigFromOrganMap(const std::string& labelsPath, const std::string& folder);
  // Where the panel rigs to: `outputFolder`/rig when an output folder is set, else
  // <G's folder>/<G's name without extension>_rig beside the segmentation ("" without a G).
  static std::string DefaultRigFolder(const std::string& labelsPath,
                                      const std::string& outputFolder);
  const std::string& GetLastRigSummary() const { return this->LastRigSummary; }
  // Cage and transfer mesh of the segmentation's S (separations from the pose, settings from the
  // parameter node when one is set), referenced by the pose node.
  bool StartBuildRig(vtkMRMLReposeSegmentationNode* segmentation, vtkMRMLReposePoseNode* pose);
  // The pose node's current frame at full resolution: a new segmentation node (posed G, S, image)
  // referring to its source and pose; with an output folder also posed_G.nii.gz, posed_S.nii.gz
  // (posed_image.nii.gz), transform.nrrd and report.json written there.
  bool StartApplyPose(vtkMRMLReposePoseNode* pose, const std::string& outputFolder = "");
  // The live pose's transfer mesh refined for its current frame (seed §4.2: smaller tets where the
  // Green deformation distorts most), with the rig's whole pieces and separations: a new
  // transfer-mesh node the pose then refers to (the old one stays in the scene). Start live
  // posing again afterwards to use it.
  // `iterations`: rounds of mesh, measure, shrink (each finer where the error is above the mean).
  bool StartRefineMesh(vtkMRMLReposePoseNode* pose, int iterations = 3);
  // One line on the last refinement: rounds, vertices before and after, maximum error (e^G).
  const std::string& GetLastRefinementSummary() const { return this->LastRefinementSummary; }
  // Per round of the last refinement: its mesh's vertices and maximum error e^G.
  const std::vector<int>& GetLastRefinementVertices() const { return this->RefinementVertices; }
  const std::vector<double>& GetLastRefinementMaxErrors() const { return this->RefinementErrors; }
  bool IsJobRunning() const;
  double GetJobProgress() const;
  std::string GetJobStage() const;
  void CancelJob();
  enum JobStatus { JobIdle, JobRunning, JobSucceeded, JobCancelled, JobFailed };
  int WaitForJob();
  int PollJob();
  // Tissue table (CSV, docs/FORMATS.md) for the reports of pose jobs; empty: the phantom's table
  // when G's labels are the phantom's, else none (no masses, no bone check).
  void SetTissueTablePath(const std::string& path);
  // The segmentation node the last ApplyPose job made (null before).
  vtkMRMLReposeSegmentationNode* GetLastPosedSegmentation() const;
  // What the panel shows of the last ApplyPose job (vtkSlicerReposeLogicQuality.cxx): its
  // report.json's quality checks (docs/QUALITY.md's targets) as rows of what was measured, the
  // target and whether it was met; each label's volume change (name, %, largest first) for the
  // plot; the job's warnings (separations not made, a tissue table that does not fit). Empty
  // before an export.
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
  const std::vector<std::string>& GetLastPoseWarnings() const { return this->LastPoseWarnings; }

  // Pose edits, undoable: the group's transform (rotation about `axis` through `pivot` by
  // `angleDeg`, then `translation`) in the pose's current keyframe, or in the pose itself when it
  // has none; a group's further turns (a joint group's other axes) are kept. False with a message
  // for an unknown group or a fixed one.
  bool SetPoseGroupTransform(vtkMRMLReposePoseNode* pose, const std::string& group,
                             const std::array<double, 3>& axis, double angleDeg,
                             const std::array<double, 3>& pivot,
                             const std::array<double, 3>& translation);
  // The group's transform in the pose's current keyframe (its base transform where the keyframe
  // does not name it). Empty for an unknown or fixed group.
  struct GroupTransform {
    std::array<double, 3> axis{0, 0, 1};
    double angleDeg = 0;
    std::array<double, 3> pivot{0, 0, 0}, translation{0, 0, 0};
  };
  std::optional<GroupTransform> GetPoseGroupTransform(vtkMRMLReposePoseNode* pose,
                                                      const std::string& group) const;
  // The group's motion as a 4x4 matrix (rest RAS mm -> posed RAS mm; for a group that follows
  // another, carried along its chain), and setting it from one (the 3D view's transform widget):
  // the group keeps its pivot and its axis direction, and a follower's own transform is what is
  // left after the groups it follows. False with a message when the matrix is not a rigid
  // motion, or for a group turning about several axes (a joint's: its sliders move it).
  bool GetPoseGroupMatrix(vtkMRMLReposePoseNode* pose, const std::string& group,
                          vtkMatrix4x4* matrix) const;
  bool SetPoseGroupMatrix(vtkMRMLReposePoseNode* pose, const std::string& group,
                          vtkMatrix4x4* matrix);
  // A group's turns in the current keyframe: its rotation, then each further turn (a joint
  // group: one per axis of its joint, repose::jointTurnAxes' order), each with its axis (a
  // joint's axis by name until the rig resolves it, e.g. "elbow_left.flexion", else the vector)
  // and angle. Empty for an unknown or fixed group. Setting a turn's angle is an undoable edit
  // (a drag between Begin/EndPoseInteraction is one step) that re-solves a live pose. False with
  // a message (unknown group, no such turn).
  struct GroupTurn {
    std::string axisName;
    std::array<double, 3> axis{1, 0, 0};
    double angleDeg = 0;
  };
  std::vector<GroupTurn> GetPoseGroupTurns(vtkMRMLReposePoseNode* pose,
                                           const std::string& group) const;
  bool SetPoseGroupTurnAngle(vtkMRMLReposePoseNode* pose, const std::string& group, int turn,
                             double angleDeg);
  // A new pose node with the one fixed group "rest" (every cage vertex): a pose built up from
  // selections in the 3D view.
  vtkMRMLReposePoseNode* NewPose(const std::string& name);
  // A new handle group of the live pose, undoable: the given cage vertices, or with bodyPart > 0
  // that part of S (its cage vertices and its tissue). It takes its vertices from "the rest" and
  // from groups of listed vertices; overlapping a group that selects by region or part is refused.
  // Returns the new group's name ("group N"), or "" with a message. The live pose re-prepares
  // itself for the new groups (a job).
  std::string AddPoseGroup(vtkMRMLReposePoseNode* pose, const std::vector<int>& cageVertices,
                           int bodyPart = 0);
  // Posing by joint. The joints of the skeleton beside a body-part map (skeleton.json, as
  // `repose rig` and `repose phantom` write it): each with its axes, its anatomical range per
  // axis (repose::jointRangeDeg) and the body parts distal to it. Empty when there is none.
  struct JointInfo {
    std::string name;
    std::vector<std::string> axes;  // in the order of its group's turns (repose::jointTurnAxes)
    std::vector<std::array<double, 3>> axisVectors;    // per axis, unit, RAS
    std::vector<std::pair<double, double>> rangesDeg;  // per axis
    std::vector<std::string> distalParts;
  };
  static std::vector<JointInfo> GetJointsBeside(const std::string& partsPath);
  // The pose's group that turns `joint` about every one of its axes (repose::setJointGroup:
  // named after the joint, a turn per axis by name, its angles kept if the joint had a group),
  // undoable. Joint groups of the same limb form a chain: the shoulder's keeps the upper arm and
  // carries the elbow's, which follows it; other groups selecting the joint's parts (by name or
  // label) give way, with their keyframe entries; a fixed "rest" group keeps the others. Live
  // posing of this pose stops: the rig must be built again for it (StartBuildRig resolves the
  // names and cuts the joint's contacts). Returns the group's name, or "" with a message.
  std::string SetPoseJoint(vtkMRMLReposePoseNode* pose, const std::string& partsPath,
                           const std::string& joint);
  // The pose as a pose file, its joint groups in the named form ("axis": "elbow_left.flexion",
  // "pivot": "elbow_left") so it poses any rigged body; written atomically. False with a message.
  bool WritePoseFile(vtkMRMLReposePoseNode* pose, const std::string& partsPath,
                     const std::string& path);
  // A limb separation added to the pose, undoable: parts by name or label of S, the region as
  // "box:x0,y0,z0,x1,y1,z1" or "sphere:x,y,z,r" (RAS mm). The rig built next makes it (an inset
  // cage between the parts, the transfer mesh cut along their border). False with a message.
  bool AddPoseSeparation(vtkMRMLReposePoseNode* pose, const std::string& partA,
                         const std::string& partB, const std::string& region);
  // A drag: the edits between Begin and End are one undo step (each still re-solves live).
  void BeginPoseInteraction();
  void EndPoseInteraction();
  bool Undo();
  bool Redo();
  bool CanUndo() const;
  bool CanRedo() const;

  // A scene folder: scene.json and the data files its nodes name (G, S and image as .nii.gz,
  // cage .vtk, transfer mesh .vtu, poses .pose.json). Saving writes every file atomically and
  // scene.json last; loading replaces the scene only if every file read.
  bool SaveScene(const std::string& folder);
  bool LoadScene(const std::string& folder);
  // What a module or application does when a user opens a folder: LoadScene, then the parameter
  // node follows the scene (its first segmentation's S and image paths, its first pose as the
  // active one with its file and first movable group, the cage's and transfer mesh's settings),
  // G is the current volume, and a rigged pose goes live (a job). False with a message.
  bool OpenScene(const std::string& folder);

  // ---- Live posing while a pose is edited (vtkSlicerReposeLogicLive.cxx) ----
  // Prepares a pose node whose rig is built for interactive frames: G converted, the transfer
  // mesh embedded in the cage, the groups resolved, both systems factorized, on the worker like
  // every long step (WaitForJob/PollJob commits it). Afterwards every change of that pose node
  // (SetPoseGroupTransform, Undo, Redo, its current frame) re-solves the frame at preview
  // precision on the calling thread and fires ModifiedEvent.
  bool StartLivePose(vtkMRMLReposePoseNode* pose);
  void StopLivePose();
  vtkMRMLReposePoseNode* GetLivePose() const;
  // Re-solves the live frame from the pose node now. False with a message on failure.
  bool UpdateLiveFrame();
  // Wall time of the last live frame solve (ms).
  double GetLiveFrameMilliseconds() const;
  // Wall time of the last ComputeLiveSlice (ms; 0 before the first).
  double GetLiveSliceMilliseconds() const { return this->LiveSliceMilliseconds; }
  // The posed cage and the posed body surface (the transfer mesh's outer faces), RAS mm; null
  // without a live pose.
  vtkPolyData* GetLiveCage() const;
  vtkPolyData* GetLiveBodySurface() const;
  // RAS box (xmin, xmax, ymin, ymax, zmin, zmax) of the rest and posed body together, where the
  // views place their slices.
  std::array<double, 6> GetLiveBounds() const;
  // The live rig's cage at rest (RAS mm, one entry per cage vertex), the cage vertices a group
  // of the live pose moves, the cage vertices of a body part of S (as a group selecting that part
  // would move), and S's parts (label, name).
  std::vector<std::array<double, 3>> GetLiveRestCage() const;
  std::vector<int> GetLiveGroupVertices(const std::string& group) const;
  std::vector<int> GetLiveCageVerticesOfPart(int label) const;
  std::vector<std::pair<int, std::string>> GetLiveBodyParts() const;
  // The centre of the rest body's box (where the views' slices start).
  std::array<double, 3> GetLiveRestCenter() const;
  // What the live frame predicts of the export's volumes (repose::predictVolumeChange on its
  // transfer mesh, computed once per frame when asked, a few ms at the seed's scale): the body's
  // change in %, and the body part that changes most with the part that drags it (names of S;
  // empty when nothing changes), as `repose pose` warns of tissue dragged along a contact.
  // The frame is restored first as the export restores it (repose::PoseRig::
  // restoreFrameVolumes), so `met` says whether the export will meet the mesh's targets (body
  // within 0.5 %, each part within 1 %) and `missed` names what it will miss.
  struct LivePrediction {
    bool valid = false;
    double bodyChangePercent = 0;
    std::string worstPart, draggedBy;
    double worstPartChangePercent = 0;
    bool met = true;
    std::string missed;  // one line, "" when met
  };
  LivePrediction GetLivePrediction();
  // A drag is in progress (between BeginPoseInteraction and EndPoseInteraction): the panel then
  // leaves the prediction (about 20 ms at the seed's 41K vertices, ReposeLiveBench's
  // "prediction") to the drag's end.
  bool IsPoseInteractionActive() const { return this->History.IsInteracting(); }
  // The data probe's input side: the live segmentation's G (at rest, as read) at a RAS point, the
  // nearest voxel's label; -1 outside its grid or without a live pose. And a label's display name
  // (the file's, else the tissue table's or the label convention's, else its number).
  int GetLiveRestLabelAt(double r, double a, double s) const;
  std::string GetLiveLabelName(int value) const;
  // A body part's name (S's label table; else its number).
  std::string GetLivePartName(int value) const;
  // The skeleton's joints where the live frame puts them: each centre anchored once in the rest
  // transfer mesh (repose::anchorPoints) and moved with it, its axes turned by the deformation
  // of the tissue there. Empty without a live pose or a skeleton (the segmentation's).
  struct LiveJoint {
    std::string name;
    std::array<double, 3> centre{};                                   // RAS mm, posed
    std::vector<std::pair<std::string, std::array<double, 3>>> axes;  // unit, posed
  };
  std::vector<LiveJoint> GetLiveJoints() const;
  // The live frame's labels of G on the slice plane through `positionMm` (orientation 0 axial,
  // 1 coronal, 2 sagittal), square pixels, `pixels` across the box's larger in-plane side and as
  // many as the box needs across the other: a one-voxel-thick label image on RAS axes (what the
  // slice views show while a handle is dragged). Null without a live pose. Its time:
  // GetLiveSliceMilliseconds.
  vtkSmartPointer<vtkImageData> ComputeLiveSlice(int orientation, double positionMm, int pixels);
  // The body-part map S (or G's body mask) on the same plane and grid, posed the same way: what
  // the slice views outline when asked (the parameter node's ShowBodyParts). The first call
  // converts S from the segmentation node (a copy of it, held while the pose is live).
  vtkSmartPointer<vtkImageData> ComputeLivePartsSlice(int orientation, double positionMm,
                                                      int pixels);
  // The segmentation's image (CT, MR) on the same plane and grid as ComputeLiveSlice, posed the
  // same way (trilinear at the rest position; the image's minimum where no tissue is). Null when
  // the segmentation has no image or there is no live pose.
  vtkSmartPointer<vtkImageData> ComputeLiveImageSlice(int orientation, double positionMm,
                                                      int pixels);
  // A grey window for that image: a soft-tissue CT window (W 400, L 40) for a CT in Hounsfield
  // units, else the 1st..99th percentile of the image's voxels. Empty without a live image.
  struct ImageWindow {
    double window = 0, level = 0;
  };
  std::optional<ImageWindow> GetLiveImageWindow() const;

 protected:
  vtkSlicerReposeLogic();
  ~vtkSlicerReposeLogic() override;
  void OnParameterNodeModified();
  void OnLivePoseModified();
  // The live frame of this pose (the live pose node's, parsed once per change).
  bool SolveLiveFrame(const repose::Pose& pose);
  void ReleaseLivePose();  // StopLivePose without the ModifiedEvent
  // The pose job of a segmentation (Core's policy, as `repose pose` and Python use it): its
  // tissue table, skeleton and joints, separations, the rig's settings from the parameter node.
  // G and S must outlive it.
  std::shared_ptr<const repose::PoseJob> PoseJobFor(vtkMRMLReposeSegmentationNode* seg,
                                                    const repose::Pose& pose,
                                                    const repose::Volume& G,
                                                    const repose::Volume& S) const;
  // S's file as the parameter node names it ("" without one): where a tissue table from
  // `repose rig` is looked for.
  std::string PartsPath() const;
  vtkMRMLReposePoseNode* AddPoseNode(const std::string& name, const std::string& json);
  // LoadVolume, or with `held` (a node's label map, read already) that image instead of the
  // file at `path`, which then only names it.
  bool ShowVolume(const std::string& path, vtkImageData* held);
  // Pushes an undo step (or extends the current drag's) and sets the pose node's JSON.
  void RecordPoseEdit(vtkMRMLReposePoseNode* node, const std::string& after);
  // Runs `body` for a call that can fail: LastErrorMessage is cleared, and an exception becomes
  // its one line and the `failed` result (vtkSlicerReposeLogicGuarded.h). The one try/catch of
  // the Logic's calls.
  template <class Result, class Body>
  Result Guarded(Result failed, Body&& body);

 private:
  vtkSlicerReposeLogic(const vtkSlicerReposeLogic&) = delete;
  void operator=(const vtkSlicerReposeLogic&) = delete;

  vtkSmartPointer<vtkMRMLReposeParametersNode> ParameterNode;
  unsigned long ParameterNodeObserverTag = 0;
  vtkSmartPointer<vtkImageData> VolumeImageData;
  vtkSmartPointer<vtkMatrix4x4> VolumeIJKToRASMatrix;
  vtkSmartPointer<vtkLookupTable> VolumeLookupTable;
  std::vector<LabelName> VolumeLabelNames;
  int VolumeLabelsPresent = -1;
  std::string VolumePath;
  std::string LastErrorMessage;

  vtkSmartPointer<vtkMRMLReposeScene> Scene;
  std::string TissueTablePath;
  std::string LastRigSummary;
  std::string VolumeLabelNote;  // where the labels' names came from, when not from the file
  std::vector<std::string> VolumeReadNotes;  // what the reader decided (ReadOptions::note)
  // FilesStamp of VolumePath and the tissue table when VolumeImageData is a label map read from
  // that file ("" otherwise): AddSegmentation of the same, unchanged file shares the image
  // instead of reading it again.
  std::string VolumeStamp;
  std::string LastRefinementSummary;
  std::vector<int> RefinementVertices;
  std::vector<double> RefinementErrors;
  std::unique_ptr<vtkSlicerReposeJob> Job;
  vtkSmartPointer<vtkMRMLReposeSegmentationNode> LastPosedSegmentation;
  std::string LastPoseReport;  // report.json of the last ApplyPose job
  std::vector<std::string> LastPoseWarnings;
  vtkSlicerReposePoseHistory History;  // undo and redo of pose edits
  struct LiveSession;
  std::shared_ptr<LiveSession> Live;  // shared_ptr: its type is complete only in the Live file
  // GetPoseSummary's last answer, for the node and modification time it was parsed at.
  mutable const vtkMRMLReposePoseNode* SummarizedPose = nullptr;
  mutable vtkMTimeType SummarizedTime = 0;
  mutable PoseSummary Summary;
  double LiveSliceMilliseconds = 0;
};
