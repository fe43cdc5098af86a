// qReposeModuleDiscovery: finds modules by their module.json in module folders, validates the
// description, loads the plugin it names and checks that the plugin agrees with it.
#pragma once

#include <QList>
#include <QString>
#include <QStringList>

#include <memory>
#include <vector>

class QPluginLoader;
class qSlicerAbstractReposeModule;

// What a module.json says, plus where it was found.
struct qReposeModuleDescription {
  QString name, title, version, description, category, helpText, acknowledgementText, library;
  QStringList contributors, dependencies;
  QString jsonPath;  // absolute path of the module.json
};

class qReposeModuleDiscovery {
 public:
  qReposeModuleDiscovery();
  ~qReposeModuleDiscovery();  // plugins stay loaded (never unloaded): their objects may outlive
                              // this

  // Where modules are looked for, highest priority first: `extraPaths` (--module-path), then
  // REPOSE_MODULE_PATH (list separated by ':'), then <application dir>/../lib/repose-modules.
  static QStringList defaultSearchPaths(const QStringList& extraPaths = {});
  void setSearchPaths(const QStringList& paths) { this->SearchPaths = paths; }
  const QStringList& searchPaths() const { return this->SearchPaths; }

  // module.json files under the search paths: a path is a module folder or holds module folders.
  QStringList findDescriptionFiles() const;
  // Parses and validates one module.json; on failure `error` names the file and the problem.
  static bool readDescription(const QString& jsonPath, qReposeModuleDescription* description,
                              QString* error);
  // The plugin library file a description names, in its folder; empty if there is none.
  static QString libraryPath(const qReposeModuleDescription& description);

  // Finds, validates, loads (dependencies first) and sets up every module. Problems go to
  // errors() and skip that module only. A name already loaded from a higher-priority path
  // is skipped with an error. Returns the number of modules loaded.
  int discover();

  struct Module {
    qReposeModuleDescription description;
    QString libraryPath;
    qSlicerAbstractReposeModule* module = nullptr;
  };
  const QList<Module>& modules() const { return this->Modules; }
  const Module* findModule(const QString& name) const;
  const QStringList& errors() const { return this->Errors; }

 private:
  bool load(const qReposeModuleDescription& description, QString* error);

  QStringList SearchPaths;
  QList<Module> Modules;
  QStringList Errors;
  std::vector<std::unique_ptr<QPluginLoader>> Loaders;
};
