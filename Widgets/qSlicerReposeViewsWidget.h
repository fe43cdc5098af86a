// qSlicerReposeViewsWidget: the module's four-up view layout, as Slicer's: Red (axial) and the 3D
// view on top, Yellow (sagittal) and Green (coronal) below. The 3D view draws the posed cage as a
// wireframe with its vertices and the posed body surface; the slice views draw the live frame's
// labels, recomputed from the Logic on every change of the live pose (a handle moved, undo, a
// keyframe), so they follow a drag. Under the views, a data probe line (as Slicer's Data Probe)
// says what is under the pointer in a slice view: the RAS position, the posed label and the input
// label there, each by name and value.
#pragma once

#include "qSlicerReposeModuleWidgetsExport.h"

#include <QColor>
#include <QScopedPointer>
#include <QStringList>
#include <QWidget>

class qSlicerReposeCageInteraction;
class qSlicerReposeSliceView;
class qSlicerReposeViewsWidgetPrivate;
class vtkRenderer;
class vtkSlicerReposeLogic;

class QSLICER_REPOSE_MODULE_WIDGETS_EXPORT qSlicerReposeViewsWidget : public QWidget {
  Q_OBJECT
 public:
  explicit qSlicerReposeViewsWidget(QWidget* parent = nullptr);
  ~qSlicerReposeViewsWidget() override;

  void setLogic(vtkSlicerReposeLogic* logic);
  vtkSlicerReposeLogic* logic() const;

  // orientation 0 axial (Red), 1 coronal (Green), 2 sagittal (Yellow).
  qSlicerReposeSliceView* sliceView(int orientation) const;
  // A slice's position along its normal (RAS mm); until set, the centre of the live body.
  void setSlicePosition(int orientation, double positionMm);
  // Pixels across a live slice (the larger in-plane side of the body's box).
  void setSliceResolution(int pixels);
  vtkRenderer* renderer3D() const;
  // Selection of cage vertices and the active group's transform widget in the 3D view.
  qSlicerReposeCageInteraction* cageInteraction() const;

  // Recomputes the slices and redraws every view from the Logic's live pose (called on every
  // Logic change). The slices' rasterization time of the last refresh, all three, in ms.
  void refresh();
  double lastSliceMilliseconds() const;

  // The probe line: what it shows now ("" with the pointer off the slices), and what it shows
  // with the pointer at a RAS point of a view's plane (the same text; also shown).
  QString probeText() const;
  QString probe(int orientation, double r, double a, double s);

  // The skeleton's joints drawn in the 3D view (the parameter node's ShowJoints, a live pose and a
  // skeleton): their names, where a joint's sphere is drawn (RAS mm; false when not shown), and
  // how many axis lines are drawn.
  QStringList jointsShown() const;
  bool jointShownAt(const QString& name, double ras[3]) const;
  int jointAxesShown() const;
  // The colour a body part is outlined in (ShowBodyParts), invalid for an unknown part.
  QColor partColor(int part) const;

  // The four views as one picture (the 3D view read back from its framebuffer).
  QImage renderViews();

 private:
  void updateJoints(bool show);  // from the Logic's live joints, or hidden
  QScopedPointer<qSlicerReposeViewsWidgetPrivate> d_ptr;
  Q_DECLARE_PRIVATE(qSlicerReposeViewsWidget)
  Q_DISABLE_COPY(qSlicerReposeViewsWidget)
};
