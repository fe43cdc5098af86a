// qReposeMainWindow: builds the window around the discovered modules and routes File > Open.
#include "qReposeMainWindow.h"

#include "qReposeModuleDiscovery.h"
#include "qSlicerAbstractReposeModule.h"

#include <QAction>
#include <QApplication>
#include <QComboBox>
#include <QDockWidget>
#include <QDragEnterEvent>
#include <QDropEvent>
#include <QElapsedTimer>
#include <QLabel>
#include <QMimeData>
#include <QThread>
#include <QUrl>
#include <QFileDialog>
#include <QGroupBox>
#include <QMenuBar>
#include <QPlainTextEdit>
#include <QStackedWidget>
#include <QStatusBar>
#include <QTextBrowser>
#include <QScrollArea>
#include <QScrollBar>
#include <QVBoxLayout>

#include <algorithm>

qReposeMainWindow::qReposeMainWindow(qReposeModuleDiscovery* discovery, QWidget* parent)
    : QMainWindow(parent), Discovery(discovery) {
  this->setWindowTitle("Repose Workbench");

  auto* panel = new QWidget;
  auto* layout = new QVBoxLayout(panel);
  this->ModuleSelector = new QComboBox;
  this->ModuleSelector->setObjectName("ModuleSelector");
  for (const auto& m : discovery->modules())
    this->ModuleSelector->addItem(m.module->icon(),
                                  m.description.category + " \u203a " + m.description.title,
                                  m.description.name);
  layout->addWidget(this->ModuleSelector);
  // Help & acknowledgement, as at the top of every Slicer module panel; collapsible.
  auto* helpBox = new QGroupBox("Help && Acknowledgement");
  helpBox->setCheckable(true);
  helpBox->setChecked(false);
  auto* helpLayout = new QVBoxLayout(helpBox);
  this->HelpBrowser = new QTextBrowser;
  this->HelpBrowser->setObjectName("HelpBrowser");
  this->HelpBrowser->setOpenExternalLinks(true);
  this->HelpBrowser->setVisible(false);
  helpLayout->addWidget(this->HelpBrowser);
  connect(helpBox, &QGroupBox::toggled, this->HelpBrowser, &QWidget::setVisible);
  layout->addWidget(helpBox);
  this->ModulePanels = new QStackedWidget;
  // Scrolled, as Slicer's module panel: a panel taller than the screen (the Output section's
  // quality table and plot after an export) keeps its sections at their size.
  auto* scroll = new QScrollArea;
  scroll->setObjectName("ModulePanelScrollArea");
  scroll->setWidgetResizable(true);
  scroll->setFrameShape(QFrame::NoFrame);
  scroll->setWidget(this->ModulePanels);
  layout->addWidget(scroll, 1);

  auto* dock = new QDockWidget("Modules");
  dock->setObjectName("ModulePanelDock");
  dock->setFeatures(QDockWidget::DockWidgetMovable | QDockWidget::DockWidgetFloatable);
  dock->setWidget(panel);
  this->addDockWidget(Qt::LeftDockWidgetArea, dock);

  // The centre holds the current module's views (Slicer's layout area); the log sits below.
  this->Views = new QStackedWidget;
  this->Views->setObjectName("ModuleViews");
  auto* placeholder = new QLabel("This module has no views.");
  placeholder->setAlignment(Qt::AlignCenter);
  this->Views->addWidget(placeholder);
  this->setCentralWidget(this->Views);
  this->Log = new QPlainTextEdit;
  this->Log->setObjectName("MessageLog");
  this->Log->setReadOnly(true);
  auto* logDock = new QDockWidget("Messages");
  logDock->setObjectName("MessageDock");
  logDock->setFeatures(QDockWidget::DockWidgetMovable | QDockWidget::DockWidgetFloatable);
  logDock->setWidget(this->Log);
  this->addDockWidget(Qt::BottomDockWidgetArea, logDock);
  this->setAcceptDrops(true);

  QMenu* fileMenu = this->menuBar()->addMenu("&File");
  QAction* openAction = fileMenu->addAction("&Open...");
  openAction->setShortcut(QKeySequence::Open);
  connect(openAction, &QAction::triggered, this, &qReposeMainWindow::onOpenTriggered);
  QAction* openDicomAction = fileMenu->addAction("Open &DICOM Folder...");
  connect(openDicomAction, &QAction::triggered, this, [this] {
    const QString folder = QFileDialog::getExistingDirectory(this, "Open a DICOM series folder");
    if (!folder.isEmpty()) this->openFile(folder);
  });
  QAction* openSceneAction = fileMenu->addAction("Open &Scene Folder...");
  connect(openSceneAction, &QAction::triggered, this, &qReposeMainWindow::onOpenSceneTriggered);
  QAction* saveSceneAction = fileMenu->addAction("Save Scene &As...");
  saveSceneAction->setShortcut(QKeySequence::SaveAs);
  connect(saveSceneAction, &QAction::triggered, this, &qReposeMainWindow::onSaveSceneTriggered);
  fileMenu->addSeparator();
  QAction* exportAction = fileMenu->addAction("&Export Posed Volumes...");
  exportAction->setObjectName("ExportAction");
  connect(exportAction, &QAction::triggered, this, [this] {
    const QString folder = QFileDialog::getExistingDirectory(
        this, "Export the posed volumes and the transform into a folder");
    if (!folder.isEmpty()) this->exportResults(folder);
  });
  fileMenu->addSeparator();
  QAction* quitAction = fileMenu->addAction("&Quit");
  quitAction->setShortcut(QKeySequence::Quit);
  connect(quitAction, &QAction::triggered, this, &QWidget::close);

  for (const auto& m : discovery->modules())
    this->logMessage(QString("Loaded module %1 %2 from %3")
                         .arg(m.description.name, m.description.version, m.libraryPath));
  for (const QString& error : discovery->errors()) this->logMessage("Error: " + error);
  if (discovery->modules().isEmpty())
    this->logMessage("No modules found in: " + discovery->searchPaths().join(", "));

  connect(this->ModuleSelector, qOverload<int>(&QComboBox::currentIndexChanged), this,
          &qReposeMainWindow::onModuleIndexChanged);
  if (this->ModuleSelector->count() > 0) this->onModuleIndexChanged(0);
  this->resize(1280, 800);
  // The panel's fields whole, as Slicer's module panel shows them: the dock as wide as the widest
  // panel needs (at least a third of the window), never scrolled sideways; the messages a few
  // lines high, so the views keep the height.
  scroll->setHorizontalScrollBarPolicy(Qt::ScrollBarAlwaysOff);
  const QMargins margins = layout->contentsMargins();
  const int panelWidth = std::max(this->ModulePanels->minimumSizeHint().width(),
                                  this->ModuleSelector->sizeHint().width()) +
                         margins.left() + margins.right() +
                         scroll->verticalScrollBar()->sizeHint().width() + 8;
  this->resizeDocks({dock}, {std::max(panelWidth, this->width() / 3)}, Qt::Horizontal);
  this->resizeDocks({logDock}, {110}, Qt::Vertical);
}

bool qReposeMainWindow::selectModule(const QString& name) {
  const int index = this->ModuleSelector->findData(name);
  if (index < 0) return false;
  this->ModuleSelector->setCurrentIndex(index);
  return true;
}

QString qReposeMainWindow::currentModuleName() const {
  return this->ModuleSelector->currentData().toString();
}

void qReposeMainWindow::onModuleIndexChanged(int index) {
  const QString name = this->ModuleSelector->itemData(index).toString();
  const qReposeModuleDiscovery::Module* m = this->Discovery->findModule(name);
  if (!m) return;
  if (!this->Panels.contains(name)) {
    QWidget* widget = m->module->createWidgetRepresentation(this->ModulePanels);
    this->Panels.insert(name, widget);
    this->ModulePanels->addWidget(widget);
  }
  this->ModulePanels->setCurrentWidget(this->Panels.value(name));
  if (!this->ModuleViews.contains(name)) {
    QWidget* views = m->module->createViewRepresentation(this->Views);
    this->ModuleViews.insert(name, views);
    if (views) this->Views->addWidget(views);
  }
  QWidget* views = this->ModuleViews.value(name);
  this->Views->setCurrentWidget(views ? views : this->Views->widget(0));
  this->HelpBrowser->setHtml("<p>" + m->module->helpText() + "</p><p><i>Contributors:</i> " +
                             m->module->contributors().join(", ") + "</p><p>" +
                             m->module->acknowledgementText() + "</p>");
}

bool qReposeMainWindow::openFile(const QString& path) {
  const qReposeModuleDiscovery::Module* m = this->Discovery->findModule(this->currentModuleName());
  QString error;
  const bool ok = m ? m->module->openFile(path, &error) : false;
  if (!m) error = "no module is loaded to open " + path;
  const QString message = ok ? "Opened " + path : "Error: " + error;
  this->logMessage(message);
  this->statusBar()->showMessage(message, 10000);
  return ok;
}

bool qReposeMainWindow::saveScene(const QString& folder) {
  const qReposeModuleDiscovery::Module* m = this->Discovery->findModule(this->currentModuleName());
  QString error;
  const bool ok = m ? m->module->saveScene(folder, &error) : false;
  if (!m) error = "no module is loaded to save a scene";
  const QString message = ok ? "Saved the scene to " + folder : "Error: " + error;
  this->logMessage(message);
  this->statusBar()->showMessage(message, 10000);
  return ok;
}

bool qReposeMainWindow::exportResults(const QString& folder) {
  const qReposeModuleDiscovery::Module* m = this->Discovery->findModule(this->currentModuleName());
  QString error;
  const bool ok = m ? m->module->exportResults(folder, &error) : false;
  if (!m) error = "no module is loaded to export from";
  const QString message =
      ok ? "Exporting to " + folder + " (progress in the module panel)" : "Error: " + error;
  this->logMessage(message);
  this->statusBar()->showMessage(message, 10000);
  return ok;
}

bool qReposeMainWindow::waitWhileBusy(double seconds) {
  const qReposeModuleDiscovery::Module* m = this->Discovery->findModule(this->currentModuleName());
  QElapsedTimer timer;
  timer.start();
  while (m && m->module->isBusy()) {
    if (timer.elapsed() > seconds * 1000) return false;
    QCoreApplication::processEvents(QEventLoop::AllEvents, 50);
    QThread::msleep(10);
  }
  QCoreApplication::processEvents();
  return true;
}

QWidget* qReposeMainWindow::currentViews() const {
  return this->ModuleViews.value(this->currentModuleName());
}

void qReposeMainWindow::dragEnterEvent(QDragEnterEvent* event) {
  if (event->mimeData()->hasUrls()) event->acceptProposedAction();
}

void qReposeMainWindow::dropEvent(QDropEvent* event) {
  for (const QUrl& url : event->mimeData()->urls())
    if (url.isLocalFile()) this->openFile(url.toLocalFile());
  event->acceptProposedAction();
}

void qReposeMainWindow::onOpenSceneTriggered() {
  const QString folder = QFileDialog::getExistingDirectory(this, "Open a scene folder");
  if (!folder.isEmpty()) this->openFile(folder);
}

void qReposeMainWindow::onSaveSceneTriggered() {
  const QString folder = QFileDialog::getExistingDirectory(this, "Save the scene into a folder");
  if (!folder.isEmpty()) this->saveScene(folder);
}

void qReposeMainWindow::onOpenTriggered() {
  const qReposeModuleDiscovery::Module* m = this->Discovery->findModule(this->currentModuleName());
  QStringList filters = m ? m->module->fileFilters() : QStringList();
  filters << "All files (*)";
  const QString path = QFileDialog::getOpenFileName(this, "Open", QString(), filters.join(";;"));
  if (!path.isEmpty()) this->openFile(path);
}

void qReposeMainWindow::logMessage(const QString& message) {
  this->Log->appendPlainText(message);
}

QString qReposeMainWindow::logText() const {
  return this->Log->toPlainText();
}
