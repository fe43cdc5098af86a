// qSlicerReposeModuleWidget: the Repose module panel (Input, Pose, Cage, Transfer mesh, Output).
// Rebuilds itself from the parameter node and the logic on every Modified (updateWidgetFromMRML)
// and writes every user edit to the node or through the logic: no state lives only here. Long
// steps (rig, live preparation, export) run as the logic's jobs, polled by a timer, with a
// progress bar and Cancel.
#pragma once

#include "qSlicerReposeModuleWidgetsExport.h"

#include <QScopedPointer>
#include <QWidget>

#include <string>

class qSlicerReposeModuleWidgetPrivate;
class vtkMRMLReposeParametersNode;
class vtkMRMLReposePoseNode;
class vtkSlicerReposeLogic;

class QSLICER_REPOSE_MODULE_WIDGETS_EXPORT qSlicerReposeModuleWidget : public QWidget {
  Q_OBJECT
 public:
  explicit qSlicerReposeModuleWidget(QWidget* parent = nullptr);
  ~qSlicerReposeModuleWidget() override;

  // The logic loads what the node names; the widget hands it its parameter node.
  void setLogic(vtkSlicerReposeLogic* logic);
  vtkSlicerReposeLogic* logic() const;
  // The widget shows and edits this node; without one the panel is disabled.
  void setParameterNode(vtkMRMLReposeParametersNode* node);
  vtkMRMLReposeParametersNode* parameterNode() const;

  // What a user does by typing a path and pressing Enter: the node gets the path, the logic
  // loads it. True if the volume loaded.
  bool setInputPath(const QString& path);
  // The info box text: the loaded volume's summary, an error line, or a hint.
  QString inputInfoText() const;
  // The pose file: loaded into a pose node of the logic's scene, which becomes the active pose.
  bool setPosePath(const QString& path);
  vtkMRMLReposePoseNode* activePose() const;

  // The buttons, as a user presses them (and tests do). Each starts a job and returns at once;
  // false with the reason in jobStatusText() when it cannot start.
  bool buildRig();  // cage and mesh, then live posing
  // "Rig from organ map": S, joints and tissue table from G's bones (a job), written to
  // rigFolder() and then the body-part map.
  bool rigFromOrganMap();
  // Where the rig goes: the output folder's rig/ when an output folder is set, else
  // <G's folder>/<G's name>_rig beside the segmentation (never into an input file).
  QString rigFolder() const;
  bool exportPose();
  void cancelJob();
  // Runs the job timer's step until no job is left (tests and scripts; the GUI never blocks).
  void waitForJobs();
  QString jobStatusText() const;

  // Posing by joint (the Pose section's Joint row): the joint's group (its distal parts, a turn
  // about each of its axes through it; chained to the groups of the limb's other joints) made
  // the active group of the active pose (a new pose when there is none), and the cage and mesh
  // built for it; then a slider per axis (flexion, abduction, rotation...) in the joint's
  // anatomical ranges turns it live. False with the reason in jobStatusText().
  bool poseByJoint(const QString& joint);
  // The active joint group's sliders: the angle about one of its axes (by name), set as a drag
  // of its slider would (one undo step); false when the active group is no joint's or has no
  // such axis. The axes shown ("" list when none).
  bool setJointAngle(const QString& axis, double angleDeg);
  double jointAngle(const QString& axis) const;
  QStringList jointAxesShown() const;
  // The joints offered (of the skeleton beside the body-part map).
  QStringList joints() const;
  // The active pose as a pose file, joint groups named (it poses any rigged body).
  bool savePose(const QString& path);

  // The rotation controls: the active group turned to `angleDeg` about its own axis and pivot.
  bool setActiveGroupAngle(double angleDeg);
  double activeGroupAngle() const;

  // A new pose (one fixed "rest" group) made active, posed live at once when the rig is built.
  bool newPose();
  // The selection of cage vertices (in the parameter node; the 3D view adds Shift+click and
  // Shift+drag): a body part's vertices, or none. selectBodyPart returns how many.
  int selectBodyPart(int label);
  void clearSelection();
  // The selection made a handle group of the active pose, which becomes the active group (its
  // name; empty with the reason in jobStatusText() when refused). The live pose re-prepares.
  QString newGroupFromSelection();

  // The Cage section's separation row (parts by name or label, the region text) added to the
  // active pose; Build applies it. False with the reason in jobStatusText().
  bool addSeparation(const QString& partA, const QString& partB, const QString& region);
  // The Transfer mesh section's Refine: a job, then live posing on the refined mesh.
  bool refineMesh();

  // File dialog filters for the input (also used by the module's File > Open).
  static QStringList inputFileFilters();

  void updateWidgetFromMRML();

 private:
  void onInputPathEditingFinished();
  void onBrowseClicked();
  void onPosePathEditingFinished();
  void onPoseBrowseClicked();
  void onJobTimer();
  void onPredictionTimer();
  void onAngleSliderPressed();
  void onAngleSliderReleased();
  void onAngleChanged(int angle);
  void updateJointSliders(const std::string& group);  // the active group's, or hidden

  QScopedPointer<qSlicerReposeModuleWidgetPrivate> d_ptr;
  Q_DECLARE_PRIVATE(qSlicerReposeModuleWidget)
  Q_DISABLE_COPY(qSlicerReposeModuleWidget)
};
