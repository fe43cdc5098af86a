// qSlicerReposeCageInteraction: picking in display space, the rubber band, the selection's
// points and the box widget that moves the active group.
#include "qSlicerReposeCageInteraction.h"

#include "vtkMRMLReposeParametersNode.h"
#include "vtkMRMLReposePoseNode.h"
#include "vtkSlicerReposeLogic.h"

#include <vtkActor.h>
#include <vtkActor2D.h>
#include <vtkBoxRepresentation.h>
#include <vtkBoxWidget2.h>
#include <vtkCallbackCommand.h>
#include <vtkCellArray.h>
#include <vtkCommand.h>
#include <vtkMatrix4x4.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkPolyDataMapper.h>
#include <vtkPolyDataMapper2D.h>
#include <vtkProperty.h>
#include <vtkProperty2D.h>
#include <vtkRenderWindow.h>
#include <vtkRenderWindowInteractor.h>
#include <vtkRenderer.h>
#include <vtkSmartPointer.h>
#include <vtkTransform.h>
#include <vtkWeakPointer.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <set>

namespace {
constexpr double kPickPixels = 8;   // how near the pointer a vertex must be drawn to be picked
constexpr double kBoxMarginMm = 8;  // the transform widget's box around the group's vertices
constexpr int kClickPixels = 4;     // a Shift-drag shorter than this is a click
}  // namespace

class qSlicerReposeCageInteractionPrivate {
 public:
  vtkSmartPointer<vtkSlicerReposeLogic> Logic;
  vtkRenderer* Renderer = nullptr;
  // Weak: the interactor belongs to the 3D view's render window, which may go first.
  vtkWeakPointer<vtkRenderWindowInteractor> Interactor;
  vtkSmartPointer<vtkCallbackCommand> Callback;
  // Selected vertices, drawn over the cage's.
  vtkSmartPointer<vtkPolyData> Selected;
  vtkSmartPointer<vtkActor> SelectedActor;
  // The rubber band of a Shift-drag, in display coordinates.
  vtkSmartPointer<vtkPolyData> Band;
  vtkSmartPointer<vtkActor2D> BandActor;
  bool Banding = false;
  int BandStart[2] = {0, 0};
  // The active group's translate/rotate widget and the drag in progress.
  vtkSmartPointer<vtkBoxWidget2> Box;
  vtkSmartPointer<vtkBoxRepresentation> BoxRep;
  bool Dragging = false;
  std::string DragGroup;
  vtkSmartPointer<vtkMatrix4x4> DragStart;

  vtkMRMLReposeParametersNode* parameters() const {
    return this->Logic ? this->Logic->GetParameterNode() : nullptr;
  }
  vtkPolyData* cage() const {
    return this->Logic ? this->Logic->GetLive()->GetLiveCage() : nullptr;
  }
  void setSelection(std::vector<int> vertices, int part) {
    vtkMRMLReposeParametersNode* p = this->parameters();
    if (!p) return;
    const int state = p->StartModify();
    p->SetSelectedCageVertices(vertices);
    p->SetSelectedBodyPart(part);
    p->EndModify(state);
  }
  // Display position and depth of every live cage vertex.
  std::vector<std::array<double, 3>> projected() const {
    std::vector<std::array<double, 3>> out;
    vtkPolyData* c = this->cage();
    if (!c) return out;
    out.resize(std::size_t(c->GetNumberOfPoints()));
    for (vtkIdType v = 0; v < c->GetNumberOfPoints(); ++v) {
      double p[3];
      c->GetPoint(v, p);
      this->Renderer->SetWorldPoint(p[0], p[1], p[2], 1.0);
      this->Renderer->WorldToDisplay();
      this->Renderer->GetDisplayPoint(out[std::size_t(v)].data());
    }
    return out;
  }
  void render() const {
    if (this->Renderer->GetRenderWindow()) this->Renderer->GetRenderWindow()->Render();
  }
};

qSlicerReposeCageInteraction::qSlicerReposeCageInteraction(vtkRenderer* renderer,
                                                           vtkRenderWindowInteractor* interactor,
                                                           QObject* parent)
    : QObject(parent), d_ptr(new qSlicerReposeCageInteractionPrivate) {
  Q_D(qSlicerReposeCageInteraction);
  d->Renderer = renderer;
  d->Interactor = interactor;

  d->Selected = vtkSmartPointer<vtkPolyData>::New();
  d->Selected->SetPoints(vtkSmartPointer<vtkPoints>::New());
  d->Selected->SetVerts(vtkSmartPointer<vtkCellArray>::New());
  auto selectedMapper = vtkSmartPointer<vtkPolyDataMapper>::New();
  selectedMapper->SetInputData(d->Selected);
  d->SelectedActor = vtkSmartPointer<vtkActor>::New();
  d->SelectedActor->SetMapper(selectedMapper);
  d->SelectedActor->GetProperty()->SetColor(0.9, 0.1, 0.1);
  d->SelectedActor->GetProperty()->SetPointSize(10);
  d->SelectedActor->GetProperty()->RenderPointsAsSpheresOn();
  d->SelectedActor->PickableOff();
  renderer->AddActor(d->SelectedActor);

  d->Band = vtkSmartPointer<vtkPolyData>::New();
  d->Band->SetPoints(vtkSmartPointer<vtkPoints>::New());
  d->Band->GetPoints()->SetNumberOfPoints(4);
  auto loop = vtkSmartPointer<vtkCellArray>::New();
  const vtkIdType ids[5] = {0, 1, 2, 3, 0};
  loop->InsertNextCell(5, ids);
  d->Band->SetLines(loop);
  auto bandMapper = vtkSmartPointer<vtkPolyDataMapper2D>::New();
  bandMapper->SetInputData(d->Band);
  d->BandActor = vtkSmartPointer<vtkActor2D>::New();
  d->BandActor->SetMapper(bandMapper);
  d->BandActor->GetProperty()->SetColor(1, 1, 1);
  d->BandActor->VisibilityOff();
  renderer->AddActor2D(d->BandActor);

  // Move (centre handle, middle button) and turn (a face): no scaling, a handle is rigid.
  d->BoxRep = vtkSmartPointer<vtkBoxRepresentation>::New();
  d->BoxRep->SetPlaceFactor(1.0);
  d->BoxRep->GetOutlineProperty()->SetColor(0.2, 0.9, 0.3);
  d->Box = vtkSmartPointer<vtkBoxWidget2>::New();
  d->Box->SetInteractor(interactor);
  d->Box->SetRepresentation(d->BoxRep);
  d->Box->SetCurrentRenderer(renderer);
  d->Box->ScalingEnabledOff();
  d->Box->MoveFacesEnabledOff();
  d->Box->AddObserver(vtkCommand::StartInteractionEvent, this,
                      &qSlicerReposeCageInteraction::onWidgetStart);
  d->Box->AddObserver(vtkCommand::InteractionEvent, this,
                      &qSlicerReposeCageInteraction::onWidgetInteraction);
  d->Box->AddObserver(vtkCommand::EndInteractionEvent, this,
                      &qSlicerReposeCageInteraction::onWidgetEnd);

  // Shift+mouse before the camera style and the widget (higher priority), which it then stops.
  d->Callback = vtkSmartPointer<vtkCallbackCommand>::New();
  d->Callback->SetClientData(this);
  d->Callback->SetCallback(&qSlicerReposeCageInteraction::onInteractorEvent);
  for (unsigned long e : {vtkCommand::LeftButtonPressEvent, vtkCommand::MouseMoveEvent,
                          vtkCommand::LeftButtonReleaseEvent})
    interactor->AddObserver(e, d->Callback, 2.0);
}

qSlicerReposeCageInteraction::~qSlicerReposeCageInteraction() {
  Q_D(qSlicerReposeCageInteraction);
  // Without its interactor the box widget has already let go of it (it observes the
  // interactor's deletion) and there is no observer left to remove.
  if (!d->Interactor) return;
  d->Box->SetEnabled(0);
  d->Interactor->RemoveObserver(d->Callback);
}

void qSlicerReposeCageInteraction::setLogic(vtkSlicerReposeLogic* logic) {
  Q_D(qSlicerReposeCageInteraction);
  d->Logic = logic;
  this->update();
}

vtkBoxWidget2* qSlicerReposeCageInteraction::transformWidget() const {
  Q_D(const qSlicerReposeCageInteraction);
  return d->Box;
}

bool qSlicerReposeCageInteraction::isDragging() const {
  Q_D(const qSlicerReposeCageInteraction);
  return d->Dragging;
}

QPoint qSlicerReposeCageInteraction::vertexDisplayPosition(int vertex) const {
  Q_D(const qSlicerReposeCageInteraction);
  vtkPolyData* c = d->cage();
  if (!c || vertex < 0 || vertex >= c->GetNumberOfPoints()) return {-1, -1};
  double p[3], q[3];
  c->GetPoint(vertex, p);
  d->Renderer->SetWorldPoint(p[0], p[1], p[2], 1.0);
  d->Renderer->WorldToDisplay();
  d->Renderer->GetDisplayPoint(q);
  return {int(std::lround(q[0])), int(std::lround(q[1]))};
}

bool qSlicerReposeCageInteraction::pickVertexAt(int x, int y, bool toggle) {
  Q_D(qSlicerReposeCageInteraction);
  vtkMRMLReposeParametersNode* p = d->parameters();
  if (!p) return false;
  const auto points = d->projected();
  int best = -1;
  double bestDepth = std::numeric_limits<double>::infinity();
  for (std::size_t v = 0; v < points.size(); ++v) {
    const double dx = points[v][0] - x, dy = points[v][1] - y;
    if (dx * dx + dy * dy > kPickPixels * kPickPixels) continue;
    if (points[v][2] < bestDepth) {  // the vertex in front
      bestDepth = points[v][2];
      best = int(v);
    }
  }
  if (best < 0) return false;
  std::vector<int> selection;
  if (toggle) {
    selection = p->GetSelectedCageVertices();
    const auto it = std::find(selection.begin(), selection.end(), best);
    if (it != selection.end())
      selection.erase(it);
    else
      selection.push_back(best);
  } else {
    selection = {best};
  }
  d->setSelection(selection, 0);
  return true;
}

int qSlicerReposeCageInteraction::selectInRectangle(int x0, int y0, int x1, int y1, bool add) {
  Q_D(qSlicerReposeCageInteraction);
  vtkMRMLReposeParametersNode* p = d->parameters();
  if (!p) return 0;
  const auto points = d->projected();
  std::vector<int> selection = add ? p->GetSelectedCageVertices() : std::vector<int>{};
  int inside = 0;
  for (std::size_t v = 0; v < points.size(); ++v)
    if (points[v][0] >= std::min(x0, x1) && points[v][0] <= std::max(x0, x1) &&
        points[v][1] >= std::min(y0, y1) && points[v][1] <= std::max(y0, y1)) {
      selection.push_back(int(v));
      ++inside;
    }
  d->setSelection(selection, 0);
  return inside;
}

int qSlicerReposeCageInteraction::selectBodyPart(int label) {
  Q_D(qSlicerReposeCageInteraction);
  if (!d->Logic) return 0;
  const std::vector<int> vertices = d->Logic->GetLive()->GetLiveCageVerticesOfPart(label);
  d->setSelection(vertices, vertices.empty() ? 0 : label);
  return int(vertices.size());
}

void qSlicerReposeCageInteraction::clearSelection() {
  Q_D(qSlicerReposeCageInteraction);
  d->setSelection({}, 0);
}

void qSlicerReposeCageInteraction::update() {
  Q_D(qSlicerReposeCageInteraction);
  vtkPolyData* cage = d->cage();
  vtkMRMLReposeParametersNode* p = d->parameters();
  // The selection's points at their posed positions.
  vtkPoints* points = d->Selected->GetPoints();
  points->Reset();
  auto verts = vtkSmartPointer<vtkCellArray>::New();
  if (cage && p)
    for (int v : p->GetSelectedCageVertices())
      if (v < cage->GetNumberOfPoints()) {
        const vtkIdType id = points->InsertNextPoint(cage->GetPoint(v));
        verts->InsertNextCell(1, &id);
      }
  points->Modified();
  d->Selected->SetVerts(verts);
  d->Selected->Modified();
  d->SelectedActor->SetVisibility(points->GetNumberOfPoints() > 0);
  if (d->Dragging) return;  // the box is where the user holds it

  // The transform widget around the active group's posed vertices.
  vtkMRMLReposePoseNode* pose = d->Logic ? d->Logic->GetLive()->GetLivePose() : nullptr;
  vtkNew<vtkMatrix4x4> unused;
  const std::string group = p ? p->GetActiveGroup() : std::string();
  // Only a group one matrix can move: a joint's group turning about several axes has its
  // sliders (SetPoseGroupMatrix refuses it).
  const std::vector<int> vertices =
      pose && d->Logic->GetPoseEdits()->GetPoseGroupMatrix(pose, group, unused) &&
              d->Logic->GetPoseEdits()->GetPoseGroupTurns(pose, group).size() == 1
          ? d->Logic->GetLive()->GetLiveGroupVertices(group)
          : std::vector<int>{};
  if (vertices.empty() || !cage) {
    d->Box->SetEnabled(0);
    return;
  }
  double bounds[6] = {std::numeric_limits<double>::max(), std::numeric_limits<double>::lowest(),
                      std::numeric_limits<double>::max(), std::numeric_limits<double>::lowest(),
                      std::numeric_limits<double>::max(), std::numeric_limits<double>::lowest()};
  for (int v : vertices) {
    if (v >= cage->GetNumberOfPoints()) continue;
    const double* x = cage->GetPoint(v);
    for (int k = 0; k < 3; ++k) {
      bounds[2 * k] = std::min(bounds[2 * k], x[k] - kBoxMarginMm);
      bounds[2 * k + 1] = std::max(bounds[2 * k + 1], x[k] + kBoxMarginMm);
    }
  }
  d->BoxRep->PlaceWidget(bounds);
  d->Box->SetEnabled(1);
}

void qSlicerReposeCageInteraction::onWidgetStart() {
  Q_D(qSlicerReposeCageInteraction);
  vtkMRMLReposePoseNode* pose = d->Logic ? d->Logic->GetLive()->GetLivePose() : nullptr;
  vtkMRMLReposeParametersNode* p = d->parameters();
  if (!pose || !p) return;
  d->DragStart = vtkSmartPointer<vtkMatrix4x4>::New();
  d->DragGroup = p->GetActiveGroup();
  if (!d->Logic->GetPoseEdits()->GetPoseGroupMatrix(pose, d->DragGroup, d->DragStart)) return;
  d->Dragging = true;
  d->Logic->GetPoseEdits()->BeginPoseInteraction();
}

void qSlicerReposeCageInteraction::onWidgetInteraction() {
  Q_D(qSlicerReposeCageInteraction);
  vtkMRMLReposePoseNode* pose = d->Logic ? d->Logic->GetLive()->GetLivePose() : nullptr;
  if (!d->Dragging || !pose) return;
  // The box's motion since the drag began, after the group's motion at that moment.
  vtkNew<vtkTransform> box;
  d->BoxRep->GetTransform(box);
  vtkNew<vtkMatrix4x4> motion;
  vtkMatrix4x4::Multiply4x4(box->GetMatrix(), d->DragStart, motion);
  d->Logic->GetPoseEdits()->SetPoseGroupMatrix(pose, d->DragGroup, motion);
}

void qSlicerReposeCageInteraction::onWidgetEnd() {
  Q_D(qSlicerReposeCageInteraction);
  if (!d->Dragging) return;
  d->Dragging = false;
  d->Logic->GetPoseEdits()->EndPoseInteraction();
  this->update();
  d->render();
}

void qSlicerReposeCageInteraction::onInteractorEvent(vtkObject*, unsigned long event, void* self,
                                                     void*) {
  auto* q = static_cast<qSlicerReposeCageInteraction*>(self);
  qSlicerReposeCageInteractionPrivate* d = q->d_func();
  vtkRenderWindowInteractor* i = d->Interactor;
  const int* at = i->GetEventPosition();
  if (event == vtkCommand::LeftButtonPressEvent) {
    if (!i->GetShiftKey() || !d->cage()) return;
    d->Banding = true;
    d->BandStart[0] = at[0];
    d->BandStart[1] = at[1];
  } else if (!d->Banding) {
    return;
  }
  d->Callback->SetAbortFlag(1);  // neither the camera nor the box sees a selection gesture
  vtkPoints* band = d->Band->GetPoints();
  band->SetPoint(0, d->BandStart[0], d->BandStart[1], 0);
  band->SetPoint(1, at[0], d->BandStart[1], 0);
  band->SetPoint(2, at[0], at[1], 0);
  band->SetPoint(3, d->BandStart[0], at[1], 0);
  band->Modified();
  if (event == vtkCommand::LeftButtonReleaseEvent) {
    d->Banding = false;
    d->BandActor->VisibilityOff();
    const bool click = std::abs(at[0] - d->BandStart[0]) < kClickPixels &&
                       std::abs(at[1] - d->BandStart[1]) < kClickPixels;
    if (click)
      q->pickVertexAt(at[0], at[1], i->GetControlKey() != 0);
    else
      q->selectInRectangle(d->BandStart[0], d->BandStart[1], at[0], at[1], i->GetControlKey() != 0);
  } else {
    d->BandActor->SetVisibility(event == vtkCommand::MouseMoveEvent);
  }
  d->render();
}
