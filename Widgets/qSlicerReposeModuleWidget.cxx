// qSlicerReposeModuleWidget: UI wiring (pointer-to-member connections only), the VTK observers
// that keep the panel in step with the parameter node and the logic, and the job timer.
#include "qSlicerReposeModuleWidget.h"

#include "ui_qSlicerReposeModuleWidget.h"

#include "vtkMRMLReposeParametersNode.h"
#include "vtkMRMLReposePoseNode.h"
#include "vtkMRMLReposeScene.h"
#include "vtkMRMLReposeSegmentationNode.h"
#include "vtkMRMLReposeTransferMeshNode.h"
#include "qSlicerReposeVolumeChangePlot.h"
#include "vtkSlicerReposeLogic.h"

#include <vtkCommand.h>
#include <vtkUnstructuredGrid.h>
#include <vtkSmartPointer.h>

#include <QApplication>
#include <QCheckBox>
#include <QFileDialog>
#include <QFileInfo>
#include <QGridLayout>
#include <QSlider>
#include <QSpinBox>
#include <QComboBox>
#include <QHBoxLayout>
#include <QHeaderView>
#include <QLabel>
#include <QPushButton>
#include <QScrollBar>
#include <QTableWidget>
#include <QSignalBlocker>
#include <QThread>
#include <QTimer>

#include <algorithm>
#include <cmath>
#include <optional>

namespace {}  // namespace

class qSlicerReposeModuleWidgetPrivate : public Ui_qSlicerReposeModuleWidget {
 public:
  vtkSmartPointer<vtkSlicerReposeLogic> Logic;
  vtkSmartPointer<vtkMRMLReposeParametersNode> ParameterNode;
  unsigned long LogicObserverTag = 0;
  unsigned long NodeObserverTag = 0;
  QTimer JobTimer;
  // Polls the live prediction the worker computes after a drag (the event loop never waits).
  QTimer PredictionTimer;
  enum class Step { None, OrganRig, Rig, Refine, Live, Export } RunningStep = Step::None;
  QString JobStatus = "Idle.";
  bool Updating = false;
  // After an export: its quality checks (check, measured, target, result) and the per-label
  // volume changes; hidden until then.
  QTableWidget* QualityTable = nullptr;
  qSlicerReposeVolumeChangePlot* VolumeChangePlot = nullptr;
  // The Joint row: joint, "Pose by joint", "Save pose..."; the joints of the skeleton beside
  // the body-part map, read again when that path changes. Under it, the active joint group's
  // sliders, a row per axis (label, slider, spin box), built for the joint they show.
  QComboBox* JointComboBox = nullptr;
  QPushButton* PoseJointButton = nullptr;
  QWidget* JointSliders = nullptr;
  std::string JointSlidersFor;
  std::vector<QString> JointSliderAxes;
  std::vector<QSlider*> JointAxisSliders;
  std::vector<QSpinBox*> JointAxisSpinBoxes;
  QPushButton* SavePoseButton = nullptr;
  std::vector<vtkSlicerReposePoseEditLogic::JointInfo> Joints;
  std::string JointsFor;  // the body-part map path they were read for

  const vtkSlicerReposePoseEditLogic::JointInfo* joint(const std::string& name) const {
    for (const auto& j : this->Joints)
      if (j.name == name) return &j;
    return nullptr;
  }

  void showQuality(vtkSlicerReposeLogic* logic) {
    const auto rows = logic->GetJobs()->GetLastPoseQuality();
    this->QualityTable->setRowCount(int(rows.size()));
    for (int r = 0; r < int(rows.size()); ++r) {
      const auto& row = rows[std::size_t(r)];
      const QStringList cells = {QString::fromStdString(row.name),
                                 QString::fromStdString(row.measured),
                                 QString::fromStdString(row.target), row.met ? "pass" : "FAIL"};
      for (int c = 0; c < cells.size(); ++c) {
        auto* item = new QTableWidgetItem(cells[c]);
        item->setFlags(Qt::ItemIsEnabled | Qt::ItemIsSelectable);
        if (c == 3) item->setForeground(row.met ? QColor(30, 130, 50) : QColor(200, 40, 30));
        this->QualityTable->setItem(r, c, item);
      }
    }
    this->QualityTable->resizeColumnsToContents();
    this->QualityTable->setMinimumHeight(
        this->QualityTable->horizontalHeader()->height() +
        this->QualityTable->verticalHeader()->defaultSectionSize() * int(rows.size()) +
        this->QualityTable->horizontalScrollBar()->sizeHint().height() + 4);
    this->QualityTable->setVisible(!rows.empty());
    std::vector<std::pair<QString, double>> changes;
    for (const auto& c : logic->GetJobs()->GetLastPoseLabelChanges())
      changes.push_back({QString::fromStdString(c.name.empty() ? std::to_string(c.value) : c.name),
                         c.changePercent});
    this->VolumeChangePlot->setChanges(changes);
    this->VolumeChangePlot->setVisible(!changes.empty());
  }

  // A button's job as the panel shows it: not started, "Error: " and the unmet precondition
  // (`missing`, when not empty) or the logic's message; started, the timer polls `step` and the
  // status says what runs. Returns `started`.
  bool showJobStart(bool started, const QString& missing, Step step, const QString& status) {
    if (started) {
      this->RunningStep = step;
      this->JobStatus = status;
      this->JobTimer.start();
    } else {
      this->JobStatus =
          "Error: " + (!missing.isEmpty()
                           ? missing
                           : QString::fromStdString(this->Logic->GetLastErrorMessage()));
    }
    return started;
  }
};

qSlicerReposeModuleWidget::qSlicerReposeModuleWidget(QWidget* parent)
    : QWidget(parent), d_ptr(new qSlicerReposeModuleWidgetPrivate) {
  Q_D(qSlicerReposeModuleWidget);
  d->setupUi(this);
  d->JobTimer.setInterval(100);
  connect(&d->JobTimer, &QTimer::timeout, this, &qSlicerReposeModuleWidget::onJobTimer);
  d->PredictionTimer.setInterval(25);
  connect(&d->PredictionTimer, &QTimer::timeout, this,
          &qSlicerReposeModuleWidget::onPredictionTimer);
  d->JobStatusLabel->setWordWrap(true);  // "Rigged (...)", errors: whole, not cut at the edge
  d->LiveStatusLabel->setWordWrap(true);
  // The Joint row, under the Angle row of the Pose section.
  d->JointComboBox = new QComboBox(d->PoseGroupBox);
  d->JointComboBox->setObjectName("JointComboBox");
  d->JointComboBox->setToolTip("A joint of the skeleton beside the body-part map");
  d->PoseJointButton = new QPushButton("Pose by joint", d->PoseGroupBox);
  d->PoseJointButton->setObjectName("PoseJointButton");
  d->PoseJointButton->setToolTip(
      "Turn the parts distal to this joint about its axes: a handle group (chained to the "
      "limb's other joints), the cage and mesh built for it, then a slider per axis moves the "
      "joint within its anatomical range");
  d->JointSliders = new QWidget(d->PoseGroupBox);
  d->JointSliders->setObjectName("JointSliders");
  auto* sliderGrid = new QGridLayout(d->JointSliders);
  sliderGrid->setContentsMargins(0, 0, 0, 0);
  d->JointSliders->setVisible(false);
  d->SavePoseButton = new QPushButton("Save pose...", d->PoseGroupBox);
  d->SavePoseButton->setObjectName("SavePoseButton");
  d->SavePoseButton->setToolTip(
      "Write the pose as a pose file (joints by name: it poses any "
      "rigged body)");
  {
    const int row = d->poseLayout->rowCount();
    d->poseLayout->addWidget(new QLabel("Joint:", d->PoseGroupBox), row, 0);
    auto* pick = new QHBoxLayout;
    pick->addWidget(d->JointComboBox, 1);
    pick->addWidget(d->PoseJointButton);
    pick->addWidget(d->SavePoseButton);
    d->poseLayout->addLayout(pick, row, 1, 1, d->poseLayout->columnCount() - 1);
    d->poseLayout->addWidget(d->JointSliders, row + 1, 0, 1, d->poseLayout->columnCount());
  }
  connect(d->PoseJointButton, &QPushButton::clicked, this,
          [this, d] { this->poseByJoint(d->JointComboBox->currentText()); });
  connect(d->SavePoseButton, &QPushButton::clicked, this, [this] {
    const QString path =
        QFileDialog::getSaveFileName(this, "Save the pose", QString(), "Pose files (*.pose.json)");
    if (!path.isEmpty()) this->savePose(path);
  });
  d->QualityTable = new QTableWidget(0, 4, d->OutputGroupBox);
  d->QualityTable->setObjectName("QualityTable");
  d->QualityTable->setHorizontalHeaderLabels({"Check", "Measured", "Target", "Result"});
  d->QualityTable->verticalHeader()->hide();
  d->QualityTable->setEditTriggers(QAbstractItemView::NoEditTriggers);
  d->QualityTable->setVisible(false);
  d->VolumeChangePlot = new qSlicerReposeVolumeChangePlot(d->OutputGroupBox);
  d->VolumeChangePlot->setVisible(false);
  d->outputLayout->addWidget(d->QualityTable, d->outputLayout->rowCount(), 0, 1, 3);
  d->outputLayout->addWidget(d->VolumeChangePlot, d->outputLayout->rowCount(), 0, 1, 3);
  connect(d->InputPathLineEdit, &QLineEdit::editingFinished, this,
          &qSlicerReposeModuleWidget::onInputPathEditingFinished);
  connect(d->InputBrowseButton, &QToolButton::clicked, this,
          &qSlicerReposeModuleWidget::onBrowseClicked);
  auto pathEdit = [this, d](QLineEdit* edit,
                            void (vtkMRMLReposeParametersNode::*set)(std::string)) {
    connect(edit, &QLineEdit::editingFinished, this, [this, d, edit, set] {
      if (d->ParameterNode)
        (d->ParameterNode.GetPointer()->*set)(edit->text().trimmed().toStdString());
    });
  };
  pathEdit(d->BodyPartPathLineEdit, &vtkMRMLReposeParametersNode::SetBodyPartMapPath);
  pathEdit(d->ImagePathLineEdit, &vtkMRMLReposeParametersNode::SetImagePath);
  pathEdit(d->OutputFolderLineEdit, &vtkMRMLReposeParametersNode::SetOutputFolder);
  auto browse = [this](QToolButton* button, QLineEdit* edit, bool folder) {
    connect(button, &QToolButton::clicked, this, [this, edit, folder] {
      const QString start = QFileInfo(edit->text()).absolutePath();
      const QString path =
          folder ? QFileDialog::getExistingDirectory(this, "Choose a folder", start)
                 : QFileDialog::getOpenFileName(this, "Choose a file", start,
                                                inputFileFilters().join(";;") + ";;All files (*)");
      if (path.isEmpty()) return;
      edit->setText(path);
      emit edit->editingFinished();
    });
  };
  browse(d->BodyPartBrowseButton, d->BodyPartPathLineEdit, false);
  browse(d->ImageBrowseButton, d->ImagePathLineEdit, false);
  browse(d->OutputBrowseButton, d->OutputFolderLineEdit, true);
  connect(d->PosePathLineEdit, &QLineEdit::editingFinished, this,
          &qSlicerReposeModuleWidget::onPosePathEditingFinished);
  connect(d->PoseBrowseButton, &QToolButton::clicked, this,
          &qSlicerReposeModuleWidget::onPoseBrowseClicked);
  connect(d->CageVertexCountSpinBox, qOverload<int>(&QSpinBox::valueChanged), this, [d](int v) {
    if (d->ParameterNode && !d->Updating) d->ParameterNode->SetCageVertexCount(v);
  });
  connect(d->CageDilationSpinBox, qOverload<double>(&QDoubleSpinBox::valueChanged), this,
          [d](double v) {
            if (d->ParameterNode && !d->Updating) d->ParameterNode->SetCageDilationMm(v);
          });
  connect(d->TransferMeshSizeSpinBox, qOverload<double>(&QDoubleSpinBox::valueChanged), this,
          [d](double v) {
            if (d->ParameterNode && !d->Updating) d->ParameterNode->SetTransferMeshSizeMm(v);
          });
  connect(d->MemoryBudgetSpinBox, qOverload<int>(&QSpinBox::valueChanged), this, [d](int v) {
    if (d->ParameterNode && !d->Updating) d->ParameterNode->SetOutputMemoryBudgetMB(v);
  });
  connect(d->OpacitySlider, &QSlider::valueChanged, this, [d](int v) {
    if (d->ParameterNode && !d->Updating) d->ParameterNode->SetLabelOpacity(v / 100.0);
  });
  connect(d->ShowBodyPartsCheckBox, &QCheckBox::toggled, this, [d](bool on) {
    if (d->ParameterNode && !d->Updating) d->ParameterNode->SetShowBodyParts(on);
  });
  connect(d->ShowJointsCheckBox, &QCheckBox::toggled, this, [d](bool on) {
    if (d->ParameterNode && !d->Updating) d->ParameterNode->SetShowJoints(on);
  });
  connect(d->GroupComboBox, &QComboBox::currentTextChanged, this, [d](const QString& group) {
    if (d->ParameterNode && !d->Updating && !group.isEmpty())
      d->ParameterNode->SetActiveGroup(group.toStdString());
  });
  connect(d->AngleSlider, &QSlider::sliderPressed, this,
          &qSlicerReposeModuleWidget::onAngleSliderPressed);
  connect(d->AngleSlider, &QSlider::sliderReleased, this,
          &qSlicerReposeModuleWidget::onAngleSliderReleased);
  connect(d->AngleSlider, &QSlider::valueChanged, this, &qSlicerReposeModuleWidget::onAngleChanged);
  connect(d->AngleSpinBox, qOverload<int>(&QSpinBox::valueChanged), this,
          &qSlicerReposeModuleWidget::onAngleChanged);
  connect(d->KeyframeSpinBox, qOverload<int>(&QSpinBox::valueChanged), this, [this, d](int k) {
    if (vtkMRMLReposePoseNode* pose = this->activePose(); pose && !d->Updating)
      pose->SetCurrentFrame(k);
  });
  connect(d->UndoButton, &QToolButton::clicked, this, [d] {
    if (d->Logic) d->Logic->GetPoseEdits()->Undo();
  });
  connect(d->RedoButton, &QToolButton::clicked, this, [d] {
    if (d->Logic) d->Logic->GetPoseEdits()->Redo();
  });
  connect(d->AddSeparationButton, &QPushButton::clicked, this, [this, d] {
    this->addSeparation(d->SeparatePartACombo->currentText(), d->SeparatePartBCombo->currentText(),
                        d->SeparationRegionLineEdit->text());
  });
  connect(d->RefineMeshButton, &QPushButton::clicked, this, &qSlicerReposeModuleWidget::refineMesh);
  connect(d->NewPoseButton, &QPushButton::clicked, this, &qSlicerReposeModuleWidget::newPose);
  connect(d->ClearSelectionButton, &QToolButton::clicked, this,
          &qSlicerReposeModuleWidget::clearSelection);
  connect(d->SelectPartButton, &QToolButton::clicked, this,
          [this, d] { this->selectBodyPart(d->PartComboBox->currentData().toInt()); });
  connect(d->NewGroupButton, &QPushButton::clicked, this,
          &qSlicerReposeModuleWidget::newGroupFromSelection);
  connect(d->BuildRigButton, &QPushButton::clicked, this, &qSlicerReposeModuleWidget::buildRig);
  connect(d->RigFromOrganMapButton, &QPushButton::clicked, this,
          &qSlicerReposeModuleWidget::rigFromOrganMap);
  connect(d->ExportButton, &QPushButton::clicked, this, &qSlicerReposeModuleWidget::exportPose);
  connect(d->CancelButton, &QPushButton::clicked, this, &qSlicerReposeModuleWidget::cancelJob);
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

bool qSlicerReposeModuleWidget::setPosePath(const QString& path) {
  Q_D(qSlicerReposeModuleWidget);
  if (!d->ParameterNode || !d->Logic) return false;
  vtkMRMLReposePoseNode* pose = d->Logic->AddPose(path.toStdString());
  const int state = d->ParameterNode->StartModify();
  d->ParameterNode->SetPosePath(path.toStdString());
  d->ParameterNode->SetActivePoseNodeID(pose ? pose->GetID() : "");
  const vtkSlicerReposePoseEditLogic::PoseSummary summary =
      d->Logic->GetPoseEdits()->GetPoseSummary(pose);
  d->ParameterNode->SetActiveGroup(summary.movableGroups.empty() ? std::string()
                                                                 : summary.movableGroups.front());
  d->ParameterNode->EndModify(state);
  if (!pose) d->JobStatus = "Error: " + QString::fromStdString(d->Logic->GetLastErrorMessage());
  this->updateWidgetFromMRML();
  return pose != nullptr;
}

vtkMRMLReposePoseNode* qSlicerReposeModuleWidget::activePose() const {
  Q_D(const qSlicerReposeModuleWidget);
  if (!d->Logic || !d->ParameterNode) return nullptr;
  return vtkMRMLReposePoseNode::SafeDownCast(
      d->Logic->GetScene()->GetNodeByID(d->ParameterNode->GetActivePoseNodeID()));
}

bool qSlicerReposeModuleWidget::buildRig() {
  Q_D(qSlicerReposeModuleWidget);
  if (!d->Logic || !d->ParameterNode) return false;
  vtkMRMLReposePoseNode* pose = this->activePose();
  auto fail = [&](const QString& why) {
    d->JobStatus = "Error: " + why;
    this->updateWidgetFromMRML();
    return false;
  };
  if (d->ParameterNode->GetInputSegmentationPath().empty())
    return fail("choose a segmentation first");
  if (!pose) {  // no pose file: a new pose, everything fixed until groups are made in the views
    this->newPose();
    pose = this->activePose();
    if (!pose) return fail(QString::fromStdString(d->Logic->GetLastErrorMessage()));
  }
  // The segmentation node of the current paths, read again only when a path or its file changed.
  // (The node's file names are those of a saved scene's folder, so they could not tell this:
  // every build had read G, S and the image into one more node.)
  auto* seg = vtkMRMLReposeSegmentationNode::SafeDownCast(
      d->Logic->GetScene()->GetNodeByID(d->ParameterNode->GetInputSegmentationNodeID()));
  if (!d->Logic->IsSegmentationOf(seg, d->ParameterNode->GetInputSegmentationPath(),
                                  d->ParameterNode->GetBodyPartMapPath(),
                                  d->ParameterNode->GetImagePath())) {
    seg = d->Logic->AddSegmentation(d->ParameterNode->GetInputSegmentationPath(),
                                    d->ParameterNode->GetBodyPartMapPath(),
                                    d->ParameterNode->GetImagePath());
    if (!seg) return fail(QString::fromStdString(d->Logic->GetLastErrorMessage()));
    d->ParameterNode->SetInputSegmentationNodeID(seg->GetID());
  }
  if (!d->Logic->GetJobs()->StartBuildRig(seg, pose))
    return fail(QString::fromStdString(d->Logic->GetLastErrorMessage()));
  d->RunningStep = qSlicerReposeModuleWidgetPrivate::Step::Rig;
  d->JobStatus = "Building the cage and the transfer mesh...";
  d->JobTimer.start();
  this->updateWidgetFromMRML();
  return true;
}

QString qSlicerReposeModuleWidget::rigFolder() const {
  Q_D(const qSlicerReposeModuleWidget);
  if (!d->ParameterNode) return {};
  return QString::fromStdString(vtkSlicerReposeJobsLogic::DefaultRigFolder(
      d->ParameterNode->GetInputSegmentationPath(), d->ParameterNode->GetOutputFolder()));
}

bool qSlicerReposeModuleWidget::rigFromOrganMap() {
  Q_D(qSlicerReposeModuleWidget);
  if (!d->Logic || !d->ParameterNode) return false;
  const std::string labels = d->ParameterNode->GetInputSegmentationPath();
  const QString folder = this->rigFolder();
  const bool started = d->showJobStart(
      !labels.empty() && d->Logic->GetJobs()->StartRigFromOrganMap(labels, folder.toStdString()),
      labels.empty() ? "choose a segmentation first" : "",
      qSlicerReposeModuleWidgetPrivate::Step::OrganRig,
      "Rigging from the organ map into " + folder + "...");
  this->updateWidgetFromMRML();
  return started;
}

QStringList qSlicerReposeModuleWidget::joints() const {
  Q_D(const qSlicerReposeModuleWidget);
  QStringList names;
  for (const auto& j : d->Joints) names << QString::fromStdString(j.name);
  return names;
}

bool qSlicerReposeModuleWidget::poseByJoint(const QString& joint) {
  Q_D(qSlicerReposeModuleWidget);
  if (!d->Logic || !d->ParameterNode) return false;
  auto fail = [&](const QString& why) {
    d->JobStatus = "Error: " + why;
    this->updateWidgetFromMRML();
    return false;
  };
  if (joint.isEmpty()) return fail("choose a joint (the skeleton beside the body-part map)");
  if (!this->activePose() && !this->newPose())
    return fail(QString::fromStdString(d->Logic->GetLastErrorMessage()));
  const std::string group = d->Logic->GetPoseEdits()->SetPoseJoint(
      this->activePose(), d->ParameterNode->GetBodyPartMapPath(), joint.toStdString());
  if (group.empty()) return fail(QString::fromStdString(d->Logic->GetLastErrorMessage()));
  d->ParameterNode->SetActiveGroup(group);
  // A new group changes the rig (its separations, whole pieces): built again, then live.
  return this->buildRig();
}

bool qSlicerReposeModuleWidget::setJointAngle(const QString& axis, double angleDeg) {
  Q_D(qSlicerReposeModuleWidget);
  const auto at = std::find(d->JointSliderAxes.begin(), d->JointSliderAxes.end(), axis);
  vtkMRMLReposePoseNode* pose = this->activePose();
  if (!d->Logic || !pose || !d->JointSliders->isVisibleTo(d->PoseGroupBox) ||
      at == d->JointSliderAxes.end())
    return false;
  return d->Logic->GetPoseEdits()->SetPoseGroupTurnAngle(
      pose, d->ParameterNode->GetActiveGroup(), int(at - d->JointSliderAxes.begin()), angleDeg);
}

double qSlicerReposeModuleWidget::jointAngle(const QString& axis) const {
  Q_D(const qSlicerReposeModuleWidget);
  const auto at = std::find(d->JointSliderAxes.begin(), d->JointSliderAxes.end(), axis);
  vtkMRMLReposePoseNode* pose = this->activePose();
  if (!d->Logic || !pose || at == d->JointSliderAxes.end()) return 0;
  const auto turns =
      d->Logic->GetPoseEdits()->GetPoseGroupTurns(pose, d->ParameterNode->GetActiveGroup());
  const std::size_t k = std::size_t(at - d->JointSliderAxes.begin());
  return k < turns.size() ? turns[k].angleDeg : 0;
}

QStringList qSlicerReposeModuleWidget::jointAxesShown() const {
  Q_D(const qSlicerReposeModuleWidget);
  QStringList axes;
  if (d->JointSliders->isVisibleTo(d->PoseGroupBox))
    for (const QString& a : d->JointSliderAxes) axes << a;
  return axes;
}

void qSlicerReposeModuleWidget::updateJointSliders(const std::string& group) {
  Q_D(qSlicerReposeModuleWidget);
  // A joint's group (named after the joint) whose every turn is about one of the joint's axes
  // gets a slider per turn; a group of one axis ("elbow_left.flexion", from a pose file) or one
  // turned otherwise keeps the Angle row.
  const vtkSlicerReposePoseEditLogic::JointInfo* joint = d->joint(group);
  vtkMRMLReposePoseNode* pose = this->activePose();
  const auto turns = joint && pose ? d->Logic->GetPoseEdits()->GetPoseGroupTurns(pose, group)
                                   : std::vector<vtkSlicerReposePoseEditLogic::GroupTurn>{};
  // Each turn's axis by name: the one it names, or the joint's axis it equals (once resolved).
  std::vector<QString> axes;
  for (const auto& turn : turns) {
    QString name;
    if (!turn.axisName.empty()) {
      if (turn.axisName.rfind(group + ".", 0) == 0)
        name = QString::fromStdString(turn.axisName.substr(group.size() + 1));
    } else {
      for (std::size_t k = 0; k < joint->axes.size(); ++k) {
        const auto& v = joint->axisVectors[k];
        if (v[0] * turn.axis[0] + v[1] * turn.axis[1] + v[2] * turn.axis[2] > 1 - 1e-9)
          name = QString::fromStdString(joint->axes[k]);
      }
    }
    if (name.isEmpty() || std::find(axes.begin(), axes.end(), name) != axes.end()) {
      axes.clear();
      break;
    }
    axes.push_back(name);
  }
  const bool show = !axes.empty();
  d->JointSliders->setVisible(show);
  d->AngleSlider->setEnabled(!show);
  d->AngleSpinBox->setEnabled(!show);
  if (!show) return;
  if (d->JointSlidersFor != group || d->JointSliderAxes != axes) {
    d->JointSlidersFor = group;
    auto* grid = static_cast<QGridLayout*>(d->JointSliders->layout());
    while (QLayoutItem* item = grid->takeAt(0)) {
      delete item->widget();
      delete item;
    }
    d->JointSliderAxes.clear();
    d->JointAxisSliders.clear();
    d->JointAxisSpinBoxes.clear();
    for (std::size_t k = 0; k < axes.size(); ++k) {
      const QString axis = axes[k];
      const std::size_t a =
          std::size_t(std::find(joint->axes.begin(), joint->axes.end(), axis.toStdString()) -
                      joint->axes.begin());
      const auto [lo, hi] = joint->rangesDeg[a];
      auto* label = new QLabel(axis + ":", d->JointSliders);
      auto* slider = new QSlider(Qt::Horizontal, d->JointSliders);
      slider->setObjectName("JointSlider_" + axis);
      slider->setRange(int(lo), int(hi));
      slider->setToolTip(QString("%1 of %2, %3 to %4 degrees")
                             .arg(axis, QString::fromStdString(group))
                             .arg(lo)
                             .arg(hi));
      auto* spin = new QSpinBox(d->JointSliders);
      spin->setObjectName("JointSpinBox_" + axis);
      spin->setRange(int(lo), int(hi));
      spin->setSuffix(" \u00b0");
      // Flexion on top, the limb's own rotation last (the turns' order reversed).
      const int row = int(axes.size() - 1 - k);
      grid->addWidget(label, row, 0);
      grid->addWidget(slider, row, 1);
      grid->addWidget(spin, row, 2);
      d->JointSliderAxes.push_back(axis);
      d->JointAxisSliders.push_back(slider);
      d->JointAxisSpinBoxes.push_back(spin);
      // A drag is one undo step, each move re-solves live, as the Angle slider.
      connect(slider, &QSlider::sliderPressed, this,
              &qSlicerReposeModuleWidget::onAngleSliderPressed);
      connect(slider, &QSlider::sliderReleased, this,
              &qSlicerReposeModuleWidget::onAngleSliderReleased);
      auto set = [this, d, axis](int value) {
        if (!d->Updating) this->setJointAngle(axis, value);
      };
      connect(slider, &QSlider::valueChanged, this, set);
      connect(spin, qOverload<int>(&QSpinBox::valueChanged), this, set);
    }
  }
  for (std::size_t k = 0; k < d->JointAxisSliders.size() && k < turns.size(); ++k) {
    const int value = int(std::lround(turns[k].angleDeg));
    if (!d->JointAxisSliders[k]->isSliderDown()) d->JointAxisSliders[k]->setValue(value);
    d->JointAxisSpinBoxes[k]->setValue(value);
  }
}

bool qSlicerReposeModuleWidget::savePose(const QString& path) {
  Q_D(qSlicerReposeModuleWidget);
  if (!d->Logic || !d->ParameterNode) return false;
  const bool ok =
      this->activePose() &&
      d->Logic->GetPoseEdits()->WritePoseFile(
          this->activePose(), d->ParameterNode->GetBodyPartMapPath(), path.toStdString());
  d->JobStatus =
      ok ? "Pose saved to " + path
         : "Error: " + (this->activePose() ? QString::fromStdString(d->Logic->GetLastErrorMessage())
                                           : QString("no pose to save"));
  this->updateWidgetFromMRML();
  return ok;
}

bool qSlicerReposeModuleWidget::exportPose() {
  Q_D(qSlicerReposeModuleWidget);
  if (!d->Logic || !d->ParameterNode) return false;
  const std::string folder = d->ParameterNode->GetOutputFolder();
  const bool started = d->showJobStart(
      !folder.empty() && this->activePose() &&
          d->Logic->GetJobs()->StartApplyPose(this->activePose(), folder),
      folder.empty() ? "choose an output folder first" : "",
      qSlicerReposeModuleWidgetPrivate::Step::Export, "Exporting at full resolution...");
  this->updateWidgetFromMRML();
  return started;
}

void qSlicerReposeModuleWidget::cancelJob() {
  Q_D(qSlicerReposeModuleWidget);
  if (d->Logic && d->Logic->GetJobs()->IsJobRunning()) d->Logic->GetJobs()->CancelJob();
}

void qSlicerReposeModuleWidget::waitForJobs() {
  Q_D(qSlicerReposeModuleWidget);
  while (d->RunningStep != qSlicerReposeModuleWidgetPrivate::Step::None) {
    QApplication::processEvents();
    QThread::msleep(20);
    this->onJobTimer();
  }
}

QString qSlicerReposeModuleWidget::jobStatusText() const {
  Q_D(const qSlicerReposeModuleWidget);
  return d->JobStatus;
}

void qSlicerReposeModuleWidget::onPredictionTimer() {
  Q_D(qSlicerReposeModuleWidget);
  if (d->Logic && d->Logic->GetLive()->PeekLivePrediction().pending) return;
  d->PredictionTimer.stop();
  this->updateWidgetFromMRML();  // the prediction, or the next frame's request
}

void qSlicerReposeModuleWidget::onJobTimer() {
  Q_D(qSlicerReposeModuleWidget);
  using Step = qSlicerReposeModuleWidgetPrivate::Step;
  if (!d->Logic || d->RunningStep == Step::None) {
    d->JobTimer.stop();
    return;
  }
  const int status = d->Logic->GetJobs()->PollJob();
  if (status == vtkSlicerReposeJobsLogic::JobRunning) {
    d->JobProgressBar->setValue(int(std::lround(100 * d->Logic->GetJobs()->GetJobProgress())));
    d->JobStatusLabel->setText(QString::fromStdString(d->Logic->GetJobs()->GetJobStage()) + "...");
    return;
  }
  const Step finished = d->RunningStep;
  d->RunningStep = Step::None;
  d->JobTimer.stop();
  if (status == vtkSlicerReposeJobsLogic::JobSucceeded &&
      (finished == Step::Rig || finished == Step::Refine)) {
    // The rig is there: prepare live posing at once, so the views follow the pose.
    if (d->Logic->GetLive()->StartLivePose(this->activePose())) {
      d->RunningStep = Step::Live;
      d->JobStatus =
          finished == Step::Refine
              ? "Transfer mesh " +
                    QString::fromStdString(d->Logic->GetJobs()->GetLastRefinementSummary()) +
                    "; preparing live posing..."
              : QString("Preparing live posing...");
      d->JobTimer.start();
    } else {
      d->JobStatus = "Error: " + QString::fromStdString(d->Logic->GetLastErrorMessage());
    }
  } else if (status == vtkSlicerReposeJobsLogic::JobSucceeded && finished == Step::OrganRig) {
    d->JobStatus = "Rigged (" + QString::fromStdString(d->Logic->GetJobs()->GetLastRigSummary()) +
                   "): body parts from " +
                   QString::fromStdString(d->ParameterNode->GetBodyPartMapPath()) +
                   "; build the cage and mesh next.";
  } else if (status == vtkSlicerReposeJobsLogic::JobSucceeded && finished == Step::Export) {
    // The report's quality on screen, and the job's warnings in the message line.
    d->showQuality(d->Logic);
    const auto rows = d->Logic->GetJobs()->GetLastPoseQuality();
    const auto failed =
        std::count_if(rows.begin(), rows.end(), [](const auto& r) { return !r.met; });
    d->JobStatus = "Exported to " + QString::fromStdString(d->ParameterNode->GetOutputFolder()) +
                   (failed == 0 ? QString("; every quality target met")
                                : QString("; %1 of %2 quality targets missed (table below)")
                                      .arg(failed)
                                      .arg(rows.size()));
    for (const std::string& w : d->Logic->GetJobs()->GetLastPoseWarnings())
      d->JobStatus += "\nWarning: " + QString::fromStdString(w);
  } else if (status == vtkSlicerReposeJobsLogic::JobSucceeded) {
    d->JobStatus = "Live: drag a handle in the 3D view or the angle; the views follow.";
  } else if (status == vtkSlicerReposeJobsLogic::JobCancelled) {
    d->JobStatus = "Cancelled; nothing was written.";
  } else {
    d->JobStatus = "Error: " + QString::fromStdString(d->Logic->GetLastErrorMessage());
  }
  this->updateWidgetFromMRML();
}

bool qSlicerReposeModuleWidget::setActiveGroupAngle(double angleDeg) {
  Q_D(qSlicerReposeModuleWidget);
  vtkMRMLReposePoseNode* pose = this->activePose();
  if (!pose || !d->Logic) return false;
  const std::string group = d->ParameterNode->GetActiveGroup();
  const auto t = d->Logic->GetPoseEdits()->GetPoseGroupTransform(pose, group);
  return t && d->Logic->GetPoseEdits()->SetPoseGroupTransform(pose, group, t->axis, angleDeg,
                                                              t->pivot, t->translation);
}

double qSlicerReposeModuleWidget::activeGroupAngle() const {
  Q_D(const qSlicerReposeModuleWidget);
  vtkMRMLReposePoseNode* pose = this->activePose();
  if (!pose || !d->ParameterNode || !d->Logic) return 0;
  const auto t =
      d->Logic->GetPoseEdits()->GetPoseGroupTransform(pose, d->ParameterNode->GetActiveGroup());
  return t ? t->angleDeg : 0;
}

bool qSlicerReposeModuleWidget::newPose() {
  Q_D(qSlicerReposeModuleWidget);
  if (!d->Logic || !d->ParameterNode) return false;
  vtkMRMLReposePoseNode* previous = this->activePose();
  vtkMRMLReposePoseNode* pose = d->Logic->GetPoseEdits()->NewPose("pose");
  if (!pose) return false;
  // The rig of the pose posed so far (segmentation, cage, transfer mesh) serves the new one.
  if (previous)
    for (const auto& [role, id] : previous->GetNodeReferences()) pose->SetNodeReferenceID(role, id);
  const int state = d->ParameterNode->StartModify();
  d->ParameterNode->SetPosePath("");
  d->ParameterNode->SetActivePoseNodeID(pose->GetID());
  d->ParameterNode->SetActiveGroup("");
  d->ParameterNode->SetSelectedCageVertices({});
  d->ParameterNode->SetSelectedBodyPart(0);
  d->ParameterNode->EndModify(state);
  // A rig already built serves the new pose too (its groups need no separation): go live.
  if (d->Logic->GetLive()->StartLivePose(pose)) {
    d->RunningStep = qSlicerReposeModuleWidgetPrivate::Step::Live;
    d->JobStatus = "Preparing live posing...";
    d->JobTimer.start();
  }
  this->updateWidgetFromMRML();
  return true;
}

int qSlicerReposeModuleWidget::selectBodyPart(int label) {
  Q_D(qSlicerReposeModuleWidget);
  if (!d->Logic || !d->ParameterNode) return 0;
  const std::vector<int> vertices = d->Logic->GetLive()->GetLiveCageVerticesOfPart(label);
  const int state = d->ParameterNode->StartModify();
  d->ParameterNode->SetSelectedCageVertices(vertices);
  d->ParameterNode->SetSelectedBodyPart(vertices.empty() ? 0 : label);
  d->ParameterNode->EndModify(state);
  return int(vertices.size());
}

void qSlicerReposeModuleWidget::clearSelection() {
  Q_D(qSlicerReposeModuleWidget);
  if (!d->ParameterNode) return;
  const int state = d->ParameterNode->StartModify();
  d->ParameterNode->SetSelectedCageVertices({});
  d->ParameterNode->SetSelectedBodyPart(0);
  d->ParameterNode->EndModify(state);
}

bool qSlicerReposeModuleWidget::addSeparation(const QString& partA, const QString& partB,
                                              const QString& region) {
  Q_D(qSlicerReposeModuleWidget);
  vtkMRMLReposePoseNode* pose = this->activePose();
  const bool ok = d->Logic && pose &&
                  d->Logic->GetPoseEdits()->AddPoseSeparation(pose, partA.trimmed().toStdString(),
                                                              partB.trimmed().toStdString(),
                                                              region.trimmed().toStdString());
  d->JobStatus = ok ? QString("Separation added: build the cage and mesh to apply it.")
                    : "Error: " + (pose ? QString::fromStdString(d->Logic->GetLastErrorMessage())
                                        : QString("no pose to add the separation to"));
  this->updateWidgetFromMRML();
  return ok;
}

bool qSlicerReposeModuleWidget::refineMesh() {
  Q_D(qSlicerReposeModuleWidget);
  if (!d->Logic || !d->Logic->GetJobs()->StartRefineMesh(this->activePose())) {
    d->JobStatus = "Error: " + (d->Logic ? QString::fromStdString(d->Logic->GetLastErrorMessage())
                                         : QString("no logic"));
    this->updateWidgetFromMRML();
    return false;
  }
  d->RunningStep = qSlicerReposeModuleWidgetPrivate::Step::Refine;
  d->JobStatus = "Refining the transfer mesh for this pose...";
  d->JobTimer.start();
  this->updateWidgetFromMRML();
  return true;
}

QString qSlicerReposeModuleWidget::newGroupFromSelection() {
  Q_D(qSlicerReposeModuleWidget);
  vtkMRMLReposePoseNode* pose = this->activePose();
  if (!d->Logic || !d->ParameterNode || !pose) return {};
  const std::string group = d->Logic->GetPoseEdits()->AddPoseGroup(
      pose, d->ParameterNode->GetSelectedCageVertices(), d->ParameterNode->GetSelectedBodyPart());
  if (group.empty()) {
    d->JobStatus = "Error: " + QString::fromStdString(d->Logic->GetLastErrorMessage());
    this->updateWidgetFromMRML();
    return {};
  }
  const int state = d->ParameterNode->StartModify();
  d->ParameterNode->SetActiveGroup(group);
  d->ParameterNode->SetSelectedCageVertices({});
  d->ParameterNode->SetSelectedBodyPart(0);
  d->ParameterNode->EndModify(state);
  return QString::fromStdString(group);
}

void qSlicerReposeModuleWidget::onAngleSliderPressed() {
  Q_D(qSlicerReposeModuleWidget);
  if (d->Logic) d->Logic->GetPoseEdits()->BeginPoseInteraction();
}

void qSlicerReposeModuleWidget::onAngleSliderReleased() {
  Q_D(qSlicerReposeModuleWidget);
  if (d->Logic) d->Logic->GetPoseEdits()->EndPoseInteraction();
}

void qSlicerReposeModuleWidget::onAngleChanged(int angle) {
  Q_D(qSlicerReposeModuleWidget);
  if (d->Updating) return;
  this->setActiveGroupAngle(angle);
}

QStringList qSlicerReposeModuleWidget::inputFileFilters() {
  return {"Label maps (*.nii *.nii.gz *.nrrd *.nhdr *.seg.nrrd *.dcm)",
          "DICOM segmentations (*.dcm)"};
}

void qSlicerReposeModuleWidget::updateWidgetFromMRML() {
  Q_D(qSlicerReposeModuleWidget);
  if (d->Updating) return;
  d->Updating = true;
  vtkMRMLReposeParametersNode* node = d->ParameterNode;
  const bool ready = node != nullptr && d->Logic != nullptr;
  for (QWidget* w :
       {static_cast<QWidget*>(d->InputGroupBox), static_cast<QWidget*>(d->PoseGroupBox),
        static_cast<QWidget*>(d->CageGroupBox), static_cast<QWidget*>(d->TransferMeshGroupBox),
        static_cast<QWidget*>(d->OutputGroupBox)})
    w->setEnabled(ready);
  auto setText = [](QLineEdit* edit, const std::string& text) {
    const QString t = QString::fromStdString(text);
    if (edit->text() != t) {
      const QSignalBlocker blocker(edit);
      edit->setText(t);
    }
  };
  setText(d->InputPathLineEdit, node ? node->GetInputSegmentationPath() : "");
  setText(d->BodyPartPathLineEdit, node ? node->GetBodyPartMapPath() : "");
  setText(d->ImagePathLineEdit, node ? node->GetImagePath() : "");
  setText(d->PosePathLineEdit, node ? node->GetPosePath() : "");
  setText(d->OutputFolderLineEdit, node ? node->GetOutputFolder() : "");
  if (node) {
    d->CageVertexCountSpinBox->setValue(node->GetCageVertexCount());
    d->CageDilationSpinBox->setValue(node->GetCageDilationMm());
    d->TransferMeshSizeSpinBox->setValue(node->GetTransferMeshSizeMm());
    d->MemoryBudgetSpinBox->setValue(node->GetOutputMemoryBudgetMB());
    d->OpacitySlider->setValue(int(std::lround(100 * node->GetLabelOpacity())));
    d->ShowBodyPartsCheckBox->setChecked(node->GetShowBodyParts());
    d->ShowJointsCheckBox->setChecked(node->GetShowJoints());
  }
  QString info;
  if (!node)
    info = "No parameter node.";
  else if (!d->Logic)
    info = "No logic.";
  else if (!d->Logic->GetLastErrorMessage().empty() && !d->Logic->GetVolumeImageData())
    info = "Error: " + QString::fromStdString(d->Logic->GetLastErrorMessage());
  else if (d->Logic->GetVolumeImageData())
    info = QString::fromStdString(d->Logic->GetVolumeSummary());
  else
    info = "No volume loaded.";
  if (d->InputInfoTextBox->toPlainText() != info) d->InputInfoTextBox->setPlainText(info);

  // Pose: the groups that can turn, the active one's angle, keyframes, undo/redo.
  vtkMRMLReposePoseNode* pose = this->activePose();
  const vtkSlicerReposePoseEditLogic::PoseSummary summary =
      d->Logic ? d->Logic->GetPoseEdits()->GetPoseSummary(pose)
               : vtkSlicerReposePoseEditLogic::PoseSummary();
  QStringList groups;
  for (const std::string& g : summary.movableGroups) groups << QString::fromStdString(g);
  const int keyframes = summary.keyframes;
  QStringList current;
  for (int i = 0; i < d->GroupComboBox->count(); ++i) current << d->GroupComboBox->itemText(i);
  if (current != groups) {
    d->GroupComboBox->clear();
    d->GroupComboBox->addItems(groups);
  }
  if (node) d->GroupComboBox->setCurrentText(QString::fromStdString(node->GetActiveGroup()));
  // The Joint row: the skeleton's joints (read again when the body-part map changes).
  const std::string partsPath = node ? node->GetBodyPartMapPath() : "";
  if (partsPath != d->JointsFor) {
    d->JointsFor = partsPath;
    d->Joints = vtkSlicerReposePoseEditLogic::GetJointsBeside(partsPath);
    const QString was = d->JointComboBox->currentText();
    d->JointComboBox->clear();  // its signal fills the axes of the first joint
    for (const auto& j : d->Joints) d->JointComboBox->addItem(QString::fromStdString(j.name));
    if (d->JointComboBox->findText(was) >= 0) d->JointComboBox->setCurrentText(was);
  }
  d->JointComboBox->setEnabled(!d->Joints.empty());
  d->SavePoseButton->setEnabled(pose != nullptr);
  this->updateJointSliders(node ? node->GetActiveGroup() : "");
  // The Angle slider's range: the active joint group's anatomical range, else a full turn.
  std::pair<double, double> range{-180, 180};
  if (node) {
    const std::string active = node->GetActiveGroup();
    const std::size_t dot = active.find('.');
    if (const auto* j = dot == std::string::npos ? nullptr : d->joint(active.substr(0, dot)))
      for (std::size_t a = 0; a < j->axes.size(); ++a)
        if (j->axes[a] == active.substr(dot + 1)) range = j->rangesDeg[a];
  }
  d->AngleSlider->setRange(int(range.first), int(range.second));
  d->AngleSpinBox->setRange(int(range.first), int(range.second));
  const int angle = int(std::lround(this->activeGroupAngle()));
  if (!d->AngleSlider->isSliderDown()) d->AngleSlider->setValue(angle);
  d->AngleSpinBox->setValue(angle);
  d->KeyframeSpinBox->setMaximum(std::max(0, keyframes - 1));
  d->KeyframeSpinBox->setValue(pose ? pose->GetCurrentFrame() : 0);
  d->KeyframeSpinBox->setEnabled(keyframes > 1);
  d->UndoButton->setEnabled(d->Logic && d->Logic->GetPoseEdits()->CanUndo());
  d->RedoButton->setEnabled(d->Logic && d->Logic->GetPoseEdits()->CanRedo());
  const bool live = d->Logic && pose && d->Logic->GetLive()->GetLivePose() == pose;
  // Selection and body parts (of the live rig's S).
  const std::size_t selected = node ? node->GetSelectedCageVertices().size() : 0;
  d->SelectionInfoLabel->setText(
      selected == 0 ? QString("none: Shift+click or Shift+drag the cage")
      : node->GetSelectedBodyPart() > 0
          ? QString("%1 cage vertices of part %2").arg(selected).arg(node->GetSelectedBodyPart())
          : QString("%1 cage vertices").arg(selected));
  std::vector<std::pair<int, std::string>> parts;
  if (live) parts = d->Logic->GetLive()->GetLiveBodyParts();
  if (d->PartComboBox->count() != int(parts.size()) ||
      (!parts.empty() && d->PartComboBox->itemData(0).toInt() != parts.front().first)) {
    const QSignalBlocker blocker(d->PartComboBox);
    const QVariant chosen = d->PartComboBox->currentData();  // kept across a re-preparation
    d->PartComboBox->clear();
    for (const auto& [label, name] : parts)
      d->PartComboBox->addItem(QString("%1 (%2)").arg(QString::fromStdString(name)).arg(label),
                               label);
    if (chosen.isValid() && d->PartComboBox->findData(chosen) >= 0)
      d->PartComboBox->setCurrentIndex(d->PartComboBox->findData(chosen));
  }
  // Separation part choices (editable: a name or label can be typed before the rig exists).
  for (QComboBox* combo : {d->SeparatePartACombo, d->SeparatePartBCombo})
    if (combo->count() != int(parts.size())) {
      const QSignalBlocker blocker(combo);
      const QString typed = combo->currentText();
      combo->clear();
      for (const auto& [label, name] : parts) combo->addItem(QString::fromStdString(name));
      combo->setCurrentText(typed);
    }
  QStringList separations;
  for (const std::string& sep : summary.separations) separations << QString::fromStdString(sep);
  d->SeparationsInfoLabel->setText(
      separations.isEmpty() ? QString("No separation.") : "Separations: " + separations.join(", "));
  d->AddSeparationButton->setEnabled(pose != nullptr);
  // The transfer mesh the pose uses.
  auto* tm = pose ? vtkMRMLReposeTransferMeshNode::SafeDownCast(
                        d->Logic->GetScene()->GetReferencedNode(pose, "transfer_mesh"))
                  : nullptr;
  d->TransferMeshInfoLabel->setText(tm && tm->GetMesh()
                                        ? QString("%1: %2 vertices, %3 tets")
                                              .arg(QString::fromStdString(tm->GetName()))
                                              .arg(tm->GetMesh()->GetNumberOfPoints())
                                              .arg(tm->GetMesh()->GetNumberOfCells())
                                        : QString("No transfer mesh yet."));
  d->PartComboBox->setEnabled(live);
  d->SelectPartButton->setEnabled(live && !parts.empty());
  d->ClearSelectionButton->setEnabled(selected > 0);
  d->NewGroupButton->setEnabled(live && selected > 0);
  d->NewPoseButton->setEnabled(d->Logic != nullptr);
  // A joint group turns by its sliders (updateJointSliders), other groups by the Angle row.
  const bool angleRow =
      pose != nullptr && !groups.isEmpty() && !d->JointSliders->isVisibleTo(d->PoseGroupBox);
  d->AngleSlider->setEnabled(angleRow);
  d->AngleSpinBox->setEnabled(angleRow);
  QString liveText = pose ? "Build the cage and mesh to pose live." : "No pose loaded.";
  if (live) {
    // What the export will show, predicted from the live frame's transfer mesh: after a drag,
    // not during it (it costs about as much as the frame and the three slices together), on the
    // Logic's worker: shown when it is ready (onPredictionTimer), "predicting" meanwhile.
    const bool dragging =
        d->AngleSlider->isSliderDown() || d->Logic->GetPoseEdits()->IsPoseInteractionActive();
    vtkSlicerReposeLiveLogic::LivePrediction p;
    if (!dragging) {
      d->Logic->GetLive()->RequestLivePrediction();
      p = d->Logic->GetLive()->PeekLivePrediction();
    }
    if (p.pending && !d->PredictionTimer.isActive()) d->PredictionTimer.start();
    liveText = QString("Live: frame solved in %1 ms")
                   .arg(d->Logic->GetLive()->GetLiveFrameMilliseconds(), 0, 'f', 1);
    if (p.pending) liveText += "; predicting the export's volumes...";
    if (p.valid) {
      liveText += QString("; body volume %1%2 % (predicted)")
                      .arg(p.bodyChangePercent >= 0 ? "+" : "")
                      .arg(p.bodyChangePercent, 0, 'f', 2);
      // A part stretched by another it is tied to (tissue dragged along a contact), or folded:
      // the export will be written, but it will miss its targets, said before it is made.
      if (!p.met)
        liveText +=
            QString("; the export will MISS its targets: %1%2")
                .arg(QString::fromStdString(p.missed))
                .arg(p.draggedBy.empty() ? QString()
                                         : ", dragged by " + QString::fromStdString(p.draggedBy));
    }
  }
  d->LiveStatusLabel->setText(liveText);

  // Jobs: progress, status, what can be pressed. A job someone else started (the module opening
  // a scene) is polled here too, so it commits and the views follow.
  const bool running = d->Logic && d->Logic->GetJobs()->IsJobRunning();
  if (running && d->RunningStep == qSlicerReposeModuleWidgetPrivate::Step::None) {
    d->RunningStep = qSlicerReposeModuleWidgetPrivate::Step::Live;
    d->JobStatus = QString::fromStdString(d->Logic->GetJobs()->GetJobStage()) + "...";
    d->JobTimer.start();
  }
  d->BuildRigButton->setEnabled(ready && !running);
  d->PoseJointButton->setEnabled(ready && !running && !d->Joints.empty());
  d->RigFromOrganMapButton->setEnabled(
      d->ParameterNode && !d->ParameterNode->GetInputSegmentationPath().empty() && !running);
  d->RefineMeshButton->setEnabled(live && !running);
  d->ExportButton->setEnabled(ready && !running && pose != nullptr);
  d->CancelButton->setEnabled(running);
  if (!running) d->JobProgressBar->setValue(d->JobStatus.startsWith("Error") ? 0 : 100);
  d->JobStatusLabel->setText(d->JobStatus);
  d->Updating = false;
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

void qSlicerReposeModuleWidget::onPosePathEditingFinished() {
  Q_D(qSlicerReposeModuleWidget);
  const QString path = d->PosePathLineEdit->text().trimmed();
  if (d->ParameterNode && !path.isEmpty() && path.toStdString() != d->ParameterNode->GetPosePath())
    this->setPosePath(path);
}

void qSlicerReposeModuleWidget::onPoseBrowseClicked() {
  Q_D(qSlicerReposeModuleWidget);
  const QString path = QFileDialog::getOpenFileName(
      this, "Choose a pose file", QFileInfo(d->PosePathLineEdit->text()).absolutePath(),
      "Pose files (*.pose.json);;All files (*)");
  if (!path.isEmpty()) this->setPosePath(path);
}
