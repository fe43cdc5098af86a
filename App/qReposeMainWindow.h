// qReposeMainWindow: the workbench window. Module panel on the left (selector, help, the
// module's widget), a message log in the centre, File > Open... handing files to the module.
#pragma once

#include <QHash>
#include <QMainWindow>

class QComboBox;
class QPlainTextEdit;
class QStackedWidget;
class QTextBrowser;
class qReposeModuleDiscovery;

class qReposeMainWindow : public QMainWindow {
  Q_OBJECT
 public:
  // `discovery` must outlive the window; its errors are shown in the log.
  explicit qReposeMainWindow(qReposeModuleDiscovery* discovery, QWidget* parent = nullptr);

  // Shows a module's panel (created on first selection). False if no module has that name.
  bool selectModule(const QString& name);
  QString currentModuleName() const;
  // Hands `path` (a file, or a folder such as a scene folder) to the current module; the outcome
  // goes to the log and the status bar.
  bool openFile(const QString& path);
  bool saveScene(const QString& folder);
  // File > Export: the current module's results into `folder` (started in the background).
  bool exportResults(const QString& folder);
  // Lets the current module's background work finish (processing events), at most `seconds`.
  // False if it was still busy then.
  bool waitWhileBusy(double seconds);
  // The current module's views (the window's centre), or null if it has none.
  QWidget* currentViews() const;
  void logMessage(const QString& message);
  QString logText() const;

 protected:
  void dragEnterEvent(QDragEnterEvent* event) override;
  void dropEvent(QDropEvent* event) override;

 private:
  void onOpenTriggered();
  void onOpenSceneTriggered();
  void onSaveSceneTriggered();
  void onModuleIndexChanged(int index);

  qReposeModuleDiscovery* Discovery;
  QComboBox* ModuleSelector = nullptr;
  QTextBrowser* HelpBrowser = nullptr;
  QStackedWidget* ModulePanels = nullptr;
  QPlainTextEdit* Log = nullptr;
  QStackedWidget* Views = nullptr;       // the modules' views; a placeholder for modules without
  QHash<QString, QWidget*> Panels;       // by module name
  QHash<QString, QWidget*> ModuleViews;  // by module name
};
