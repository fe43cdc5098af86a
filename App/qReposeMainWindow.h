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
  // Hands `path` to the current module; the outcome goes to the log and the status bar.
  bool openFile(const QString& path);
  void logMessage(const QString& message);
  QString logText() const;

 private:
  void onOpenTriggered();
  void onModuleIndexChanged(int index);

  qReposeModuleDiscovery* Discovery;
  QComboBox* ModuleSelector = nullptr;
  QTextBrowser* HelpBrowser = nullptr;
  QStackedWidget* ModulePanels = nullptr;
  QPlainTextEdit* Log = nullptr;
  QHash<QString, QWidget*> Panels;  // by module name
};
