// qReposeMainWindow: builds the window around the discovered modules and routes File > Open.
#include "qReposeMainWindow.h"

#include "qReposeModuleDiscovery.h"
#include "qSlicerAbstractReposeModule.h"

#include <QAction>
#include <QApplication>
#include <QComboBox>
#include <QDockWidget>
#include <QFileDialog>
#include <QGroupBox>
#include <QMenuBar>
#include <QPlainTextEdit>
#include <QStackedWidget>
#include <QStatusBar>
#include <QTextBrowser>
#include <QVBoxLayout>

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
  layout->addWidget(this->ModulePanels, 1);

  auto* dock = new QDockWidget("Modules");
  dock->setObjectName("ModulePanelDock");
  dock->setFeatures(QDockWidget::DockWidgetMovable | QDockWidget::DockWidgetFloatable);
  dock->setWidget(panel);
  this->addDockWidget(Qt::LeftDockWidgetArea, dock);

  this->Log = new QPlainTextEdit;
  this->Log->setObjectName("MessageLog");
  this->Log->setReadOnly(true);
  this->setCentralWidget(this->Log);

  QMenu* fileMenu = this->menuBar()->addMenu("&File");
  QAction* openAction = fileMenu->addAction("&Open...");
  openAction->setShortcut(QKeySequence::Open);
  connect(openAction, &QAction::triggered, this, &qReposeMainWindow::onOpenTriggered);
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
