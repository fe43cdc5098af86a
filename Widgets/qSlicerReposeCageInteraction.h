// qSlicerReposeCageInteraction: editing the live cage in the 3D view. Shift+click selects the
// cage vertex drawn nearest the pointer, Shift+drag the vertices inside a rubber band (Ctrl adds
// to the selection); a body part of S selects its vertices. The selection lives in the parameter
// node (SelectedCageVertices, SelectedBodyPart), the module panel makes a handle group of it.
// The active handle group carries a translate/rotate widget (a box around its posed vertices:
// drag the centre to move it, a face to turn it); each step of a drag sets the group's motion
// through the Logic, which re-solves the live frame (ARAP + Green coordinates + rigidity), and
// the whole drag is one undo step.
#pragma once

#include "qSlicerReposeModuleWidgetsExport.h"

#include <QObject>
#include <QPoint>
#include <QScopedPointer>

class qSlicerReposeCageInteractionPrivate;
class vtkBoxWidget2;
class vtkObject;
class vtkRenderer;
class vtkRenderWindowInteractor;
class vtkSlicerReposeLogic;

class QSLICER_REPOSE_MODULE_WIDGETS_EXPORT qSlicerReposeCageInteraction : public QObject {
  Q_OBJECT
 public:
  qSlicerReposeCageInteraction(vtkRenderer* renderer, vtkRenderWindowInteractor* interactor,
                               QObject* parent = nullptr);
  ~qSlicerReposeCageInteraction() override;

  void setLogic(vtkSlicerReposeLogic* logic);

  // A live cage vertex in display coordinates (VTK's: pixels, origin bottom left); (-1, -1) when
  // there is no such vertex.
  QPoint vertexDisplayPosition(int vertex) const;
  // What Shift+click does at a display point: the nearest drawn vertex within a few pixels (the
  // front one where several are) becomes the selection, or with `toggle` joins or leaves it.
  // False (selection unchanged) when no vertex is that close.
  bool pickVertexAt(int x, int y, bool toggle);
  // What Shift+drag does: the vertices drawn inside the display rectangle become the selection
  // (or are added to it). Returns how many were inside.
  int selectInRectangle(int x0, int y0, int x1, int y1, bool add);
  // The cage vertices of a body part of S. Returns how many.
  int selectBodyPart(int label);
  void clearSelection();

  // The translate/rotate widget of the active group (enabled only while a movable group of the
  // live pose is active, and not for a joint's group of several axes: its sliders turn it).
  vtkBoxWidget2* transformWidget() const;
  bool isDragging() const;

  // Redraws the selection and places the transform widget on the active group; called by the
  // views on every change of the Logic or the parameter node (not during a drag).
  void update();

 private:
  static void onInteractorEvent(vtkObject* caller, unsigned long event, void* self, void*);
  void onWidgetStart();
  void onWidgetInteraction();
  void onWidgetEnd();

  QScopedPointer<qSlicerReposeCageInteractionPrivate> d_ptr;
  Q_DECLARE_PRIVATE(qSlicerReposeCageInteraction)
  Q_DISABLE_COPY(qSlicerReposeCageInteraction)
};
