// qSlicerReposeModule: metadata (kept equal to module.json; the discovery test checks), and the
// wiring of one logic and one parameter node shared by every panel the host asks for.
#include "qSlicerReposeModule.h"

#include "qSlicerReposeModuleWidget.h"
#include "qSlicerReposeViewsWidget.h"
#include "vtkMRMLReposeParametersNode.h"
#include "vtkSlicerReposeLogic.h"

#include <QDir>
#include <QFileInfo>

qSlicerReposeModule::qSlicerReposeModule(QObject* parent) : QObject(parent) {}

qSlicerReposeModule::~qSlicerReposeModule() = default;

QString qSlicerReposeModule::name() const {
  return "Repose";
}

QString qSlicerReposeModule::title() const {
  return "Repose";
}

QString qSlicerReposeModule::category() const {
  return "Segmentation";
}

QStringList qSlicerReposeModule::contributors() const {
  return {"The Repose developers"};
}

QString qSlicerReposeModule::helpText() const {
  return "Repose deforms a segmented whole-body label map into a new posture. Load a label map "
         "(NIfTI, NRRD, a 3D Slicer .seg.nrrd or a DICOM series) in the Input section; the info "
         "box shows its dimensions, spacing, orientation, scalar type and labels. A cage is built "
         "around the body, its handles are moved, and the deformation is transferred through a "
         "tetrahedral mesh to every voxel, so each output voxel gets exactly one label.";
}

QString qSlicerReposeModule::acknowledgementText() const {
  return "Repose implements the extension of the VoxMorph cage-based deformation pipeline by "
         "Faraj, Thiery, Boubekeur et al. (Robust and Scalable Interactive Freeform Modeling of "
         "High Definition Medical Images). Test data: TotalSegmentator (Wasserthal et al., "
         "Apache-2.0, CC-BY-4.0), slicerio sample segmentations (MIT) and dcmqi sample data "
         "(BSD-3-Clause).";
}

QIcon qSlicerReposeModule::icon() const {
  return QIcon(":/Icons/Repose.png");
}

void qSlicerReposeModule::setup() {
  // Registers the icon; needed when the plugin is linked statically, harmless otherwise.
  Q_INIT_RESOURCE(qSlicerReposeModule);
  if (this->Logic) return;
  this->Logic = vtkSmartPointer<vtkSlicerReposeLogic>::New();
  this->ParameterNode = vtkSmartPointer<vtkMRMLReposeParametersNode>::New();
  this->Logic->SetParameterNode(this->ParameterNode);
}

QWidget* qSlicerReposeModule::createWidgetRepresentation(QWidget* parent) {
  this->setup();
  auto* widget = new qSlicerReposeModuleWidget(parent);
  widget->setLogic(this->Logic);
  widget->setParameterNode(this->ParameterNode);
  this->Panel = widget;
  return widget;
}

QStringList qSlicerReposeModule::fileFilters() const {
  return qSlicerReposeModuleWidget::inputFileFilters() << "Pose files (*.pose.json)";
}

bool qSlicerReposeModule::exportResults(const QString& folder, QString* errorMessage) {
  this->setup();
  this->ParameterNode->SetOutputFolder(folder.toStdString());
  const bool ok = this->Panel && this->Panel->exportPose();
  if (!ok && errorMessage)
    *errorMessage = this->Panel ? this->Panel->jobStatusText() : QString("the module has no panel");
  return ok;
}

bool qSlicerReposeModule::openFile(const QString& path, QString* errorMessage) {
  this->setup();
  const QString clean = QDir::cleanPath(path);
  if (QFileInfo(clean).isDir() && QFileInfo(clean + "/scene.json").exists())
    return this->openScene(clean, errorMessage);
  if (clean.endsWith(".pose.json")) {  // a pose: loaded into a pose node, made the active one
    const bool ok = this->Panel && this->Panel->setPosePath(clean);
    if (!ok && errorMessage)
      *errorMessage = this->Panel ? QString::fromStdString(this->Logic->GetLastErrorMessage())
                                  : QString("the module has no panel to open a pose in");
    return ok;
  }
  // The logic writes the path to the parameter node, so every panel showing it updates.
  const bool ok = this->Logic->LoadVolume(clean.toStdString());
  if (!ok && errorMessage)
    *errorMessage = QString::fromStdString(this->Logic->GetLastErrorMessage());
  return ok;
}

bool qSlicerReposeModule::openScene(const QString& folder, QString* errorMessage) {
  // The Logic loads the scene, points the parameter node (and so every panel) at it and makes a
  // rigged pose live; the module only reports.
  const bool ok = this->Logic->OpenScene(folder.toStdString());
  if (!ok && errorMessage)
    *errorMessage = QString::fromStdString(this->Logic->GetLastErrorMessage());
  return ok;
}

QWidget* qSlicerReposeModule::createViewRepresentation(QWidget* parent) {
  this->setup();
  auto* views = new qSlicerReposeViewsWidget(parent);
  views->setLogic(this->Logic);
  return views;
}

bool qSlicerReposeModule::saveScene(const QString& folder, QString* errorMessage) {
  this->setup();
  const bool ok = this->Logic->SaveScene(folder.toStdString());
  if (!ok && errorMessage)
    *errorMessage = QString::fromStdString(this->Logic->GetLastErrorMessage());
  return ok;
}

bool qSlicerReposeModule::isBusy() const {
  return this->Logic && this->Logic->GetJobs()->IsJobRunning();
}

vtkSlicerReposeLogic* qSlicerReposeModule::logic() const {
  return this->Logic;
}

vtkMRMLReposeParametersNode* qSlicerReposeModule::parameterNode() const {
  return this->ParameterNode;
}
