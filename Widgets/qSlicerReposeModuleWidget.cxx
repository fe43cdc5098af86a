// qSlicerReposeModuleWidget: UI wiring (pointer-to-member connections only) and the VTK
// observers that keep the panel in step with the parameter node and the logic.
#include "qSlicerReposeModuleWidget.h"

#include "ui_qSlicerReposeModuleWidget.h"

#include "vtkMRMLReposeParametersNode.h"
#include "vtkSlicerReposeLogic.h"

#include <vtkCommand.h>
#include <vtkSmartPointer.h>

#include <QFileDialog>
#include <QFileInfo>
#include <QSignalBlocker>

class qSlicerReposeModuleWidgetPrivate : public Ui_qSlicerReposeModuleWidget {
 public:
  vtkSmartPointer<vtkSlicerReposeLogic> Logic;
  vtkSmartPointer<vtkMRMLReposeParametersNode> ParameterNode;
  unsigned long LogicObserverTag = 0;
  unsigned long NodeObserverTag = 0;
};

qSlicerReposeModuleWidget::qSlicerReposeModuleWidget(QWidget* parent)
    : QWidget(parent), d_ptr(new qSlicerReposeModuleWidgetPrivate) {
  Q_D(qSlicerReposeModuleWidget);
  d->setupUi(this);
  connect(d->InputPathLineEdit, &QLineEdit::editingFinished, this,
          &qSlicerReposeModuleWidget::onInputPathEditingFinished);
  connect(d->InputBrowseButton, &QToolButton::clicked, this,
          &qSlicerReposeModuleWidget::onBrowseClicked);
  this->updateWidgetFromMRML();
}

qSlicerReposeModuleWidget::~qSlicerReposeModuleWidget() {
  // The observers hold a raw pointer to this widget: remove them before it goes.
  this->setParameterNode(nullptr);
  this->setLogic(nullptr);
}

void qSlicerReposeModuleWidget::setLogic(vtkSlicerReposeLogic* logic) {
  Q_D(qSlicerReposeModuleWidget);
  if (d->Logic == logic) return;
  if (d->Logic) d->Logic->RemoveObserver(d->LogicObserverTag);
  d->Logic = logic;
  if (logic) {
    d->LogicObserverTag = logic->AddObserver(vtkCommand::ModifiedEvent, this,
                                             &qSlicerReposeModuleWidget::updateWidgetFromMRML);
    if (d->ParameterNode) logic->SetParameterNode(d->ParameterNode);
  }
  this->updateWidgetFromMRML();
}

vtkSlicerReposeLogic* qSlicerReposeModuleWidget::logic() const {
  Q_D(const qSlicerReposeModuleWidget);
  return d->Logic;
}

void qSlicerReposeModuleWidget::setParameterNode(vtkMRMLReposeParametersNode* node) {
  Q_D(qSlicerReposeModuleWidget);
  if (d->ParameterNode == node) return;
  if (d->ParameterNode) d->ParameterNode->RemoveObserver(d->NodeObserverTag);
  d->ParameterNode = node;
  if (node)
    d->NodeObserverTag = node->AddObserver(vtkCommand::ModifiedEvent, this,
                                           &qSlicerReposeModuleWidget::updateWidgetFromMRML);
  if (d->Logic && node) d->Logic->SetParameterNode(node);
  this->updateWidgetFromMRML();
}

vtkMRMLReposeParametersNode* qSlicerReposeModuleWidget::parameterNode() const {
  Q_D(const qSlicerReposeModuleWidget);
  return d->ParameterNode;
}

bool qSlicerReposeModuleWidget::setInputPath(const QString& path) {
  Q_D(qSlicerReposeModuleWidget);
  if (!d->ParameterNode || !d->Logic) return false;
  // The logic writes the path to the node, which updates this panel; the same path reloads.
  return d->Logic->LoadVolume(path.toStdString());
}

QString qSlicerReposeModuleWidget::inputInfoText() const {
  Q_D(const qSlicerReposeModuleWidget);
  return d->InputInfoTextBox->toPlainText();
}

QStringList qSlicerReposeModuleWidget::inputFileFilters() {
  return {"Label maps (*.nii *.nii.gz *.nrrd *.nhdr *.seg.nrrd)"};
}

void qSlicerReposeModuleWidget::updateWidgetFromMRML() {
  Q_D(qSlicerReposeModuleWidget);
  vtkMRMLReposeParametersNode* node = d->ParameterNode;
  d->InputGroupBox->setEnabled(node != nullptr && d->Logic != nullptr);
  const QString path = node ? QString::fromStdString(node->GetInputSegmentationPath()) : QString();
  if (d->InputPathLineEdit->text() != path) {
    const QSignalBlocker blocker(d->InputPathLineEdit);
    d->InputPathLineEdit->setText(path);
  }
  QString info;
  if (!node)
    info = "No parameter node.";
  else if (!d->Logic)
    info = "No logic.";
  else if (!d->Logic->GetLastErrorMessage().empty())
    info = "Error: " + QString::fromStdString(d->Logic->GetLastErrorMessage());
  else if (d->Logic->GetVolumeImageData())
    info = QString::fromStdString(d->Logic->GetVolumeSummary());
  else
    info = "No volume loaded.";
  if (d->InputInfoTextBox->toPlainText() != info) d->InputInfoTextBox->setPlainText(info);
}

void qSlicerReposeModuleWidget::onInputPathEditingFinished() {
  Q_D(qSlicerReposeModuleWidget);
  const QString path = d->InputPathLineEdit->text().trimmed();
  if (d->ParameterNode && path.toStdString() != d->ParameterNode->GetInputSegmentationPath())
    this->setInputPath(path);
}

void qSlicerReposeModuleWidget::onBrowseClicked() {
  Q_D(qSlicerReposeModuleWidget);
  const QString start = QFileInfo(d->InputPathLineEdit->text()).absolutePath();
  QStringList filters = inputFileFilters();
  filters << "All files (*)";
  const QString path =
      QFileDialog::getOpenFileName(this, "Choose a label map", start, filters.join(";;"));
  if (!path.isEmpty()) this->setInputPath(path);
}
