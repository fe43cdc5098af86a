// qSlicerReposeModule: metadata (kept equal to module.json; the discovery test checks), and the
// wiring of one logic and one parameter node shared by every panel the host asks for.
#include "qSlicerReposeModule.h"

#include "qSlicerReposeModuleWidget.h"
#include "vtkMRMLReposeParametersNode.h"
#include "vtkSlicerReposeLogic.h"

#include <QDir>

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
  return widget;
}

QStringList qSlicerReposeModule::fileFilters() const {
  return qSlicerReposeModuleWidget::inputFileFilters();
}

bool qSlicerReposeModule::openFile(const QString& path, QString* errorMessage) {
  this->setup();
  // The logic writes the path to the parameter node, so every panel showing it updates.
  const bool ok = this->Logic->LoadVolume(QDir::cleanPath(path).toStdString());
  if (!ok && errorMessage)
    *errorMessage = QString::fromStdString(this->Logic->GetLastErrorMessage());
  return ok;
}

vtkSlicerReposeLogic* qSlicerReposeModule::logic() const {
  return this->Logic;
}

vtkMRMLReposeParametersNode* qSlicerReposeModule::parameterNode() const {
  return this->ParameterNode;
}
