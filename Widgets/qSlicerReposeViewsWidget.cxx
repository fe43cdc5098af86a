// qSlicerReposeViewsWidget: layout, the 3D view's actors, and the refresh from the Logic.
#include "qSlicerReposeViewsWidget.h"

#include "qSlicerReposeCageInteraction.h"
#include "qSlicerReposeSliceView.h"
#include "vtkMRMLReposeParametersNode.h"
#include "vtkMRMLReposePoseNode.h"
#include "vtkMRMLReposeScene.h"
#include "vtkMRMLReposeSegmentationNode.h"
#include "vtkSlicerReposeLogic.h"

#include <QVTKOpenGLNativeWidget.h>
#include <vtkActor.h>
#include <vtkActor2D.h>
#include <vtkCellArray.h>
#include <vtkCellData.h>
#include <vtkGlyph3D.h>
#include <vtkLabeledDataMapper.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkSphereSource.h>
#include <vtkStringArray.h>
#include <vtkUnsignedCharArray.h>
#include <vtkCamera.h>
#include <vtkCommand.h>
#include <vtkGenericOpenGLRenderWindow.h>
#include <vtkInteractorStyleTrackballCamera.h>
#include <vtkRenderWindowInteractor.h>
#include <vtkLookupTable.h>
#include <vtkPolyDataMapper.h>
#include <vtkProperty.h>
#include <vtkRenderer.h>
#include <vtkSmartPointer.h>
#include <vtkTextActor.h>
#include <vtkTextProperty.h>

#include <QGridLayout>
#include <QLabel>
#include <QPainter>

#include <array>

#include <algorithm>
#include <cmath>
#include <limits>

class qSlicerReposeViewsWidgetPrivate {
 public:
  vtkSmartPointer<vtkSlicerReposeLogic> Logic;
  unsigned long LogicObserverTag = 0;
  vtkSmartPointer<vtkMRMLReposeParametersNode> Parameters;  // the logic's, for the opacity
  unsigned long ParametersObserverTag = 0;
  QVTKOpenGLNativeWidget* View3D = nullptr;
  vtkSmartPointer<vtkGenericOpenGLRenderWindow> RenderWindow;
  vtkSmartPointer<vtkRenderer> Renderer;
  vtkSmartPointer<vtkActor> BodyActor, CageActor, CageVertexActor;
  vtkSmartPointer<vtkPolyDataMapper> BodyMapper, CageMapper, CageVertexMapper;
  // The skeleton's joints: spheres at the posed centres (glyphs of JointPoints), their axes as
  // coloured lines (JointAxes), their names as labels at the centres. The labels go by side
  // (JointLabels: the patient's right, left, the midline): seen from the front, a right joint's
  // name ends at its centre and a left one's starts there, so a pair's names never overlap.
  vtkSmartPointer<vtkPolyData> JointPoints, JointAxes;
  vtkSmartPointer<vtkSphereSource> JointSphere;
  vtkSmartPointer<vtkActor> JointActor, JointAxisActor;
  vtkSmartPointer<vtkPolyData> JointLabels[3];
  vtkSmartPointer<vtkActor2D> JointLabelActors[3];
  QHash<int, QColor> PartColors;  // the body-part overlay's colours, per live pose
  vtkMRMLReposePoseNode* PartColorsFor = nullptr;
  qSlicerReposeSliceView* Slices[3] = {nullptr, nullptr, nullptr};
  double Positions[3] = {std::numeric_limits<double>::quiet_NaN(),
                         std::numeric_limits<double>::quiet_NaN(),
                         std::numeric_limits<double>::quiet_NaN()};
  int Pixels = 256;
  double SliceMilliseconds = 0;
  vtkMRMLReposePoseNode* CameraResetFor = nullptr;
  qSlicerReposeCageInteraction* CageInteraction = nullptr;
  vtkSmartPointer<vtkTextActor> Timing;  // "frame … ms, slices … ms" in the 3D view's corner
  vtkSmartPointer<vtkLookupTable> Lookup;
  vtkMRMLReposePoseNode* LookupFor = nullptr;
  QLabel* Probe = nullptr;  // the data probe line under the views
  int ProbeView = -1;       // the view the pointer is over (-1: none)
  double ProbeRas[3] = {0, 0, 0};
};

qSlicerReposeViewsWidget::qSlicerReposeViewsWidget(QWidget* parent)
    : QWidget(parent), d_ptr(new qSlicerReposeViewsWidgetPrivate) {
  Q_D(qSlicerReposeViewsWidget);
  this->setObjectName("ReposeViews");
  auto* grid = new QGridLayout(this);
  grid->setContentsMargins(0, 0, 0, 0);
  grid->setSpacing(2);
  d->View3D = new QVTKOpenGLNativeWidget(this);
  d->View3D->setObjectName("ThreeDView");
  d->RenderWindow = vtkSmartPointer<vtkGenericOpenGLRenderWindow>::New();
  d->View3D->setRenderWindow(d->RenderWindow);
  d->Renderer = vtkSmartPointer<vtkRenderer>::New();
  d->Renderer->SetBackground(0.76, 0.76, 0.87);  // Slicer's 3D view blue-grey
  d->Renderer->SetBackground2(0.29, 0.29, 0.43);
  d->Renderer->GradientBackgroundOn();
  d->RenderWindow->AddRenderer(d->Renderer);
  auto actor = [&](vtkSmartPointer<vtkActor>& a, vtkSmartPointer<vtkPolyDataMapper>& m) {
    m = vtkSmartPointer<vtkPolyDataMapper>::New();
    a = vtkSmartPointer<vtkActor>::New();
    a->SetMapper(m);
    a->VisibilityOff();
    d->Renderer->AddActor(a);
  };
  actor(d->BodyActor, d->BodyMapper);
  d->BodyActor->GetProperty()->SetColor(0.89, 0.72, 0.62);  // skin
  d->BodyActor->GetProperty()->SetOpacity(0.6);
  actor(d->CageActor, d->CageMapper);
  d->CageActor->GetProperty()->SetRepresentationToWireframe();
  d->CageActor->GetProperty()->SetColor(1.0, 0.55, 0.1);
  d->CageActor->GetProperty()->LightingOff();
  actor(d->CageVertexActor, d->CageVertexMapper);
  d->CageVertexActor->GetProperty()->SetRepresentationToPoints();
  d->CageVertexActor->GetProperty()->SetPointSize(5);
  d->CageVertexActor->GetProperty()->SetColor(1.0, 0.9, 0.2);
  d->CageVertexActor->GetProperty()->LightingOff();
  {
    // Joints as Slicer draws markups: spheres with their names beside, always in front of the
    // semi-transparent body; axes in the colours of the anatomical planes' conventions.
    d->JointPoints = vtkSmartPointer<vtkPolyData>::New();
    d->JointSphere = vtkSmartPointer<vtkSphereSource>::New();
    d->JointSphere->SetThetaResolution(16);
    d->JointSphere->SetPhiResolution(12);
    vtkNew<vtkGlyph3D> glyphs;
    glyphs->SetInputData(d->JointPoints);
    glyphs->SetSourceConnection(d->JointSphere->GetOutputPort());
    glyphs->ScalingOff();
    vtkNew<vtkPolyDataMapper> sphereMapper;
    sphereMapper->SetInputConnection(glyphs->GetOutputPort());
    d->JointActor = vtkSmartPointer<vtkActor>::New();
    d->JointActor->SetMapper(sphereMapper);
    d->JointActor->GetProperty()->SetColor(0.4, 1.0, 1.0);  // Slicer's unselected markup colour
    d->JointActor->VisibilityOff();
    d->Renderer->AddActor(d->JointActor);
    d->JointAxes = vtkSmartPointer<vtkPolyData>::New();
    vtkNew<vtkPolyDataMapper> axisMapper;
    axisMapper->SetInputData(d->JointAxes);
    axisMapper->SetScalarModeToUseCellData();
    d->JointAxisActor = vtkSmartPointer<vtkActor>::New();
    d->JointAxisActor->SetMapper(axisMapper);
    d->JointAxisActor->GetProperty()->SetLineWidth(3);
    d->JointAxisActor->GetProperty()->LightingOff();
    d->JointAxisActor->VisibilityOff();
    d->Renderer->AddActor(d->JointAxisActor);
    for (int side = 0; side < 3; ++side) {
      d->JointLabels[side] = vtkSmartPointer<vtkPolyData>::New();
      vtkNew<vtkLabeledDataMapper> labelMapper;
      labelMapper->SetInputData(d->JointLabels[side]);
      labelMapper->SetLabelModeToLabelFieldData();
      labelMapper->SetFieldDataName("name");
      vtkTextProperty* text = labelMapper->GetLabelTextProperty();
      text->SetFontSize(12);
      text->SetColor(1, 1, 1);
      text->ShadowOn();
      text->BoldOn();
      text->SetVerticalJustificationToCentered();
      // 0: the patient's right (the viewer's left from the front), 1: left, 2: the midline.
      if (side == 0) text->SetJustificationToRight();
      if (side == 1) text->SetJustificationToLeft();
      if (side == 2) text->SetJustificationToCentered();
      d->JointLabelActors[side] = vtkSmartPointer<vtkActor2D>::New();
      d->JointLabelActors[side]->SetMapper(labelMapper);
      d->JointLabelActors[side]->VisibilityOff();
      d->Renderer->AddActor2D(d->JointLabelActors[side]);
    }
  }
  d->Timing = vtkSmartPointer<vtkTextActor>::New();
  d->Timing->GetTextProperty()->SetFontSize(13);
  d->Timing->GetTextProperty()->SetColor(0.1, 0.1, 0.2);  // on the light lower part
  d->Timing->SetPosition(6, 6);
  d->Timing->VisibilityOff();
  d->Renderer->AddActor2D(d->Timing);
  // Slicer's 3D view camera: trackball; Shift+mouse selects cage vertices (CageInteraction).
  d->RenderWindow->GetInteractor()->SetInteractorStyle(
      vtkSmartPointer<vtkInteractorStyleTrackballCamera>::New());
  d->CageInteraction =
      new qSlicerReposeCageInteraction(d->Renderer, d->RenderWindow->GetInteractor(), this);
  for (int o = 0; o < 3; ++o) {
    d->Slices[o] = new qSlicerReposeSliceView(o, this);
    // The wheel steps the slice by one of its pixels, within the live body's box.
    connect(d->Slices[o], &qSlicerReposeSliceView::scrolled, this, [this, d, o](int steps) {
      if (!d->Logic || !d->Logic->GetLive()->GetLivePose() || std::isnan(d->Positions[o])) return;
      const std::array<double, 6> box = d->Logic->GetLive()->GetLiveBounds();
      const int axis = o == 0 ? 2 : o == 1 ? 1 : 0;
      const double lo = box[std::size_t(2 * axis)], hi = box[std::size_t(2 * axis + 1)];
      const double larger = std::max({box[1] - box[0], box[3] - box[2], box[5] - box[4]});
      const double step = std::max(larger / d->Pixels, 0.1);
      this->setSlicePosition(o, std::clamp(d->Positions[o] + steps * step, lo, hi));
    });
  }
  // Slicer's Four-Up: Red | 3D over Yellow | Green; the probe line below.
  grid->addWidget(d->Slices[0], 0, 0);
  grid->addWidget(d->View3D, 0, 1);
  grid->addWidget(d->Slices[2], 1, 0);
  grid->addWidget(d->Slices[1], 1, 1);
  d->Probe = new QLabel(this);
  d->Probe->setObjectName("DataProbe");
  d->Probe->setTextFormat(Qt::PlainText);
  d->Probe->setTextInteractionFlags(Qt::TextSelectableByMouse);
  d->Probe->setMinimumHeight(d->Probe->fontMetrics().height() + 6);
  grid->addWidget(d->Probe, 2, 0, 1, 2);
  grid->setRowStretch(0, 1);
  grid->setRowStretch(1, 1);
  for (int o = 0; o < 3; ++o) {
    connect(d->Slices[o], &qSlicerReposeSliceView::probed, this,
            [this, o](double r, double a, double s) { this->probe(o, r, a, s); });
    connect(d->Slices[o], &qSlicerReposeSliceView::probeLeft, this, [d] {
      d->ProbeView = -1;
      d->Probe->clear();
    });
  }
}

qSlicerReposeViewsWidget::~qSlicerReposeViewsWidget() {
  this->setLogic(nullptr);
  // Before the child widgets go (~QWidget, after this body): the 3D view and with it the
  // interactor the cage interaction observes.
  Q_D(qSlicerReposeViewsWidget);
  delete d->CageInteraction;
  d->CageInteraction = nullptr;
}

void qSlicerReposeViewsWidget::setLogic(vtkSlicerReposeLogic* logic) {
  Q_D(qSlicerReposeViewsWidget);
  if (d->Logic == logic) return;
  if (d->Logic) d->Logic->RemoveObserver(d->LogicObserverTag);
  if (d->Parameters) d->Parameters->RemoveObserver(d->ParametersObserverTag);
  d->Logic = logic;
  d->Parameters = logic ? logic->GetParameterNode() : nullptr;
  d->CageInteraction->setLogic(logic);
  if (logic)
    d->LogicObserverTag =
        logic->AddObserver(vtkCommand::ModifiedEvent, this, &qSlicerReposeViewsWidget::refresh);
  if (d->Parameters)
    d->ParametersObserverTag = d->Parameters->AddObserver(vtkCommand::ModifiedEvent, this,
                                                          &qSlicerReposeViewsWidget::refresh);
  this->refresh();
}

vtkSlicerReposeLogic* qSlicerReposeViewsWidget::logic() const {
  Q_D(const qSlicerReposeViewsWidget);
  return d->Logic;
}

qSlicerReposeSliceView* qSlicerReposeViewsWidget::sliceView(int orientation) const {
  Q_D(const qSlicerReposeViewsWidget);
  return orientation >= 0 && orientation < 3 ? d->Slices[orientation] : nullptr;
}

void qSlicerReposeViewsWidget::setSlicePosition(int orientation, double positionMm) {
  Q_D(qSlicerReposeViewsWidget);
  if (orientation < 0 || orientation > 2) return;
  d->Positions[orientation] = positionMm;
  this->refresh();
}

void qSlicerReposeViewsWidget::setSliceResolution(int pixels) {
  Q_D(qSlicerReposeViewsWidget);
  d->Pixels = std::max(16, pixels);
  this->refresh();
}

qSlicerReposeCageInteraction* qSlicerReposeViewsWidget::cageInteraction() const {
  Q_D(const qSlicerReposeViewsWidget);
  return d->CageInteraction;
}

vtkRenderer* qSlicerReposeViewsWidget::renderer3D() const {
  Q_D(const qSlicerReposeViewsWidget);
  return d->Renderer;
}

double qSlicerReposeViewsWidget::lastSliceMilliseconds() const {
  Q_D(const qSlicerReposeViewsWidget);
  return d->SliceMilliseconds;
}

void qSlicerReposeViewsWidget::refresh() {
  Q_D(qSlicerReposeViewsWidget);
  vtkMRMLReposePoseNode* pose = d->Logic ? d->Logic->GetLive()->GetLivePose() : nullptr;
  d->BodyActor->SetVisibility(pose != nullptr);
  d->CageActor->SetVisibility(pose != nullptr);
  d->CageVertexActor->SetVisibility(pose != nullptr);
  vtkMRMLReposeParametersNode* parameters = d->Logic ? d->Logic->GetParameterNode() : nullptr;
  const bool showParts = pose && parameters && parameters->GetShowBodyParts();
  this->updateJoints(pose && parameters && parameters->GetShowJoints());
  d->SliceMilliseconds = 0;
  if (!pose) {
    d->Timing->VisibilityOff();
    d->ProbeView = -1;
    d->Probe->clear();
    for (qSlicerReposeSliceView* view : d->Slices) view->setSlice(nullptr, nullptr);
    d->CameraResetFor = nullptr;
    if (d->CageInteraction) d->CageInteraction->update();
    d->RenderWindow->Render();
    return;
  }
  d->BodyMapper->SetInputData(d->Logic->GetLive()->GetLiveBodySurface());
  d->CageMapper->SetInputData(d->Logic->GetLive()->GetLiveCage());
  d->CageVertexMapper->SetInputData(d->Logic->GetLive()->GetLiveCage());
  // Label colours of G, once per live pose.
  if (d->LookupFor != pose) {
    d->LookupFor = pose;
    d->Lookup = nullptr;
    auto* seg = vtkMRMLReposeSegmentationNode::SafeDownCast(
        d->Logic->GetScene()->GetReferencedNode(pose, "segmentation"));
    if (seg && seg->GetLabelMap())
      d->Lookup = vtkSlicerReposeLogic::GetLabelLookupTable(seg->GetLabelMap());
  }
  // Body-part colours: well-spread hues in S's label order, once per live pose.
  if (d->PartColorsFor != pose) {
    d->PartColorsFor = pose;
    d->PartColors.clear();
    int i = 0;
    for (const auto& [label, name] : d->Logic->GetLive()->GetLiveBodyParts())
      d->PartColors.insert(label, QColor::fromHsvF(std::fmod(0.13 + 0.618034 * i++, 1.0), 0.85, 1));
  }
  const std::array<double, 3> centre = d->Logic->GetLive()->GetLiveRestCenter();
  for (int o = 0; o < 3; ++o) {
    const int axis = o == 0 ? 2 : o == 1 ? 1 : 0;  // axial: S, coronal: A, sagittal: R
    if (std::isnan(d->Positions[o])) d->Positions[o] = centre[std::size_t(axis)];
  }
  // Every slice the three views show, in one call: labels, the image, S's outlines when asked.
  const vtkSlicerReposeLiveLogic::LiveSlices slices = d->Logic->GetLive()->ComputeLiveSlices(
      {d->Positions[0], d->Positions[1], d->Positions[2]}, d->Pixels, showParts);
  const auto window = d->Logic->GetLive()->GetLiveImageWindow();
  const std::array<double, 3>& sliceMs = slices.labelMilliseconds;
  for (int o = 0; o < 3; ++o) {
    d->SliceMilliseconds += sliceMs[std::size_t(o)];
    d->Slices[o]->setWindowLevel(window ? window->window : 0, window ? window->level : 0);
    d->Slices[o]->setPositionMm(d->Positions[o]);
    if (vtkMRMLReposeParametersNode* p = d->Logic->GetParameterNode())
      d->Slices[o]->setLabelOpacity(p->GetLabelOpacity());
    d->Slices[o]->setPartsOverlay(slices.parts[std::size_t(o)], d->PartColors);
    d->Slices[o]->setSlice(slices.labels[std::size_t(o)], d->Lookup, slices.images[std::size_t(o)]);
  }
  // What a drag costs, by the stages ReposeLiveBench reports (docs/PERFORMANCE.md): the frame's
  // solve (posed cage, Green coordinates, rigidity) and each slice's labels; short enough for
  // the 3D view of a 1280 x 800 window.
  d->Timing->SetInput(QString("frame %1 ms + slices %2 ms (ax %3, cor %4, sag %5)")
                          .arg(d->Logic->GetLive()->GetLiveFrameMilliseconds(), 0, 'f', 1)
                          .arg(d->SliceMilliseconds, 0, 'f', 1)
                          .arg(sliceMs[0], 0, 'f', 1)
                          .arg(sliceMs[1], 0, 'f', 1)
                          .arg(sliceMs[2], 0, 'f', 1)
                          .toUtf8()
                          .constData());
  d->Timing->VisibilityOn();
  // A still pointer over a slice: what is under it changes with the frame and with the slice's
  // position (the wheel).
  if (const int o = d->ProbeView; o >= 0) {
    d->ProbeRas[o == 0 ? 2 : o == 1 ? 1 : 0] = d->Positions[o];
    this->probe(o, d->ProbeRas[0], d->ProbeRas[1], d->ProbeRas[2]);
  }
  if (d->CameraResetFor != pose) {
    d->CameraResetFor = pose;
    vtkCamera* camera = d->Renderer->GetActiveCamera();
    camera->SetFocalPoint(0, 0, 0);
    camera->SetPosition(0, 1, 0);  // looking at the patient's face: anterior view
    camera->SetViewUp(0, 0, 1);
    d->Renderer->ResetCamera();
  }
  if (d->CageInteraction) d->CageInteraction->update();
  d->RenderWindow->Render();
  d->View3D->update();
}

void qSlicerReposeViewsWidget::updateJoints(bool show) {
  Q_D(qSlicerReposeViewsWidget);
  const std::vector<vtkSlicerReposeLiveLogic::LiveJoint> joints =
      show && d->Logic ? d->Logic->GetLive()->GetLiveJoints()
                       : std::vector<vtkSlicerReposeLiveLogic::LiveJoint>{};
  const bool visible = !joints.empty();
  d->JointActor->SetVisibility(visible);
  d->JointAxisActor->SetVisibility(visible);
  for (const auto& actor : d->JointLabelActors) actor->SetVisibility(visible);
  vtkNew<vtkPoints> centres;
  vtkNew<vtkStringArray> names;
  names->SetName("name");
  vtkNew<vtkPoints> sideCentres[3];
  vtkNew<vtkStringArray> sideNames[3];
  for (auto& n : sideNames) n->SetName("name");
  vtkNew<vtkPoints> axisPoints;
  vtkNew<vtkCellArray> axisLines;
  vtkNew<vtkUnsignedCharArray> axisColors;
  axisColors->SetNumberOfComponents(3);
  axisColors->SetName("axis");
  // Sized to the body: a sphere about 1.5 % of its largest side, an axis four times as long.
  const std::array<double, 6> box =
      d->Logic ? d->Logic->GetLive()->GetLiveBounds() : std::array<double, 6>{};
  const double larger = std::max({box[1] - box[0], box[3] - box[2], box[5] - box[4]});
  const double radius = std::max(2.0, 0.015 * larger), length = 4 * radius;
  d->JointSphere->SetRadius(radius);
  for (const auto& joint : joints) {
    centres->InsertNextPoint(joint.centre.data());
    names->InsertNextValue(joint.name);
    auto endsWith = [&](const std::string& suffix) {
      return joint.name.size() > suffix.size() &&
             joint.name.compare(joint.name.size() - suffix.size(), suffix.size(), suffix) == 0;
    };
    const int side = endsWith("_right") ? 0 : endsWith("_left") ? 1 : 2;
    sideCentres[side]->InsertNextPoint(joint.centre.data());
    // A space on the joint's side of the name keeps it clear of the sphere.
    sideNames[side]->InsertNextValue(side == 0   ? joint.name + "  "
                                     : side == 1 ? "  " + joint.name
                                                 : joint.name);
    for (const auto& [axisName, axis] : joint.axes) {
      // flexion red, abduction green, rotation blue, the neck's lateral bend yellow
      const unsigned char rgb[4][3] = {
          {230, 50, 50}, {60, 200, 60}, {70, 110, 255}, {240, 220, 60}};
      const int k = axisName == "flexion"     ? 0
                    : axisName == "abduction" ? 1
                    : axisName == "rotation"  ? 2
                                              : 3;
      const vtkIdType a = axisPoints->InsertNextPoint(joint.centre[0] - length * axis[0] / 2,
                                                      joint.centre[1] - length * axis[1] / 2,
                                                      joint.centre[2] - length * axis[2] / 2);
      const vtkIdType b = axisPoints->InsertNextPoint(joint.centre[0] + length * axis[0] / 2,
                                                      joint.centre[1] + length * axis[1] / 2,
                                                      joint.centre[2] + length * axis[2] / 2);
      const vtkIdType ids[2] = {a, b};
      axisLines->InsertNextCell(2, ids);
      axisColors->InsertNextTypedTuple(rgb[k]);
    }
  }
  d->JointPoints->Initialize();
  d->JointPoints->SetPoints(centres);
  d->JointPoints->GetPointData()->AddArray(names);
  d->JointPoints->Modified();
  for (int side = 0; side < 3; ++side) {
    d->JointLabels[side]->Initialize();
    d->JointLabels[side]->SetPoints(sideCentres[side]);
    d->JointLabels[side]->GetPointData()->AddArray(sideNames[side]);
    d->JointLabels[side]->Modified();
  }
  d->JointAxes->Initialize();
  d->JointAxes->SetPoints(axisPoints);
  d->JointAxes->SetLines(axisLines);
  d->JointAxes->GetCellData()->SetScalars(axisColors);
  d->JointAxes->Modified();
}

QStringList qSlicerReposeViewsWidget::jointsShown() const {
  Q_D(const qSlicerReposeViewsWidget);
  QStringList out;
  if (!d->JointActor->GetVisibility()) return out;
  auto* names =
      vtkStringArray::SafeDownCast(d->JointPoints->GetPointData()->GetAbstractArray("name"));
  for (vtkIdType i = 0; names && i < names->GetNumberOfValues(); ++i)
    out << QString::fromStdString(names->GetValue(i));
  return out;
}

bool qSlicerReposeViewsWidget::jointShownAt(const QString& name, double ras[3]) const {
  Q_D(const qSlicerReposeViewsWidget);
  const int i = this->jointsShown().indexOf(name);
  if (i < 0) return false;
  d->JointPoints->GetPoint(i, ras);
  return true;
}

int qSlicerReposeViewsWidget::jointAxesShown() const {
  Q_D(const qSlicerReposeViewsWidget);
  return d->JointAxisActor->GetVisibility() ? int(d->JointAxes->GetNumberOfLines()) : 0;
}

QColor qSlicerReposeViewsWidget::partColor(int part) const {
  Q_D(const qSlicerReposeViewsWidget);
  return d->PartColors.value(part);
}

QString qSlicerReposeViewsWidget::probeText() const {
  Q_D(const qSlicerReposeViewsWidget);
  return d->Probe->text();
}

namespace {
// Slicer's way of writing a RAS position: each axis by the side it points to (R/L, A/P, S/I).
QString rasText(double r, double a, double s) {
  auto axis = [](double v, char positive, char negative) {
    return QString("%1 %2").arg(v < 0 ? negative : positive).arg(std::fabs(v), 0, 'f', 1);
  };
  return axis(r, 'R', 'L') + "  " + axis(a, 'A', 'P') + "  " + axis(s, 'S', 'I');
}
}  // namespace

QString qSlicerReposeViewsWidget::probe(int orientation, double r, double a, double s) {
  Q_D(qSlicerReposeViewsWidget);
  if (orientation < 0 || orientation > 2 || !d->Logic || !d->Logic->GetLive()->GetLivePose()) {
    d->ProbeView = -1;
    d->Probe->clear();
    return {};
  }
  d->ProbeView = orientation;
  d->ProbeRas[0] = r, d->ProbeRas[1] = a, d->ProbeRas[2] = s;
  auto label = [&](int value) {
    if (value < 0) return QString("outside");
    if (value == 0) return QString("0 (background)");
    return QString("%1 %2").arg(value).arg(
        QString::fromStdString(d->Logic->GetLive()->GetLiveLabelName(value)));
  };
  const qSlicerReposeSliceView* view = d->Slices[orientation];
  QString text = QString("%1 (%2)  %3   posed: %4   input: %5")
                     .arg(view->viewName(), view->orientationName().toLower(), rasText(r, a, s),
                          label(view->labelAtRas(r, a, s)),
                          label(d->Logic->GetLive()->GetLiveRestLabelAt(r, a, s)));
  // With the body-part outlines shown, the part drawn there too.
  if (const int part = view->partAtRas(r, a, s); part >= 0)
    text += part == 0
                ? QString("   part: none")
                : QString("   part: %1 %2")
                      .arg(part)
                      .arg(QString::fromStdString(d->Logic->GetLive()->GetLivePartName(part)));
  d->Probe->setText(text);
  return text;
}

QImage qSlicerReposeViewsWidget::renderViews() {
  Q_D(qSlicerReposeViewsWidget);
  d->RenderWindow->Render();
  QImage out(this->size(), QImage::Format_RGB32);
  out.fill(Qt::black);
  QPainter painter(&out);
  for (qSlicerReposeSliceView* view : d->Slices)
    painter.drawImage(view->geometry().topLeft(), view->grab().toImage());
  painter.drawImage(d->View3D->geometry(), d->View3D->grabFramebuffer());
  return out;
}
