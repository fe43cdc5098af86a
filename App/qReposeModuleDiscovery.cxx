// qReposeModuleDiscovery: module.json validation, plugin loading with QPluginLoader and the
// check that the loaded plugin describes itself as its module.json does.
#include "qReposeModuleDiscovery.h"

#include "qSlicerAbstractReposeModule.h"

#include <QCoreApplication>
#include <QDir>
#include <QFile>
#include <QFileInfo>
#include <QJsonArray>
#include <QJsonDocument>
#include <QJsonObject>
#include <QPluginLoader>
#include <QRegularExpression>
#include <QSet>

qReposeModuleDiscovery::qReposeModuleDiscovery() = default;

// Deleting a QPluginLoader does not unload its library (only unload() would): the plugins and
// the objects they made stay, and Qt's library registry lets them go at exit.
qReposeModuleDiscovery::~qReposeModuleDiscovery() = default;

QStringList qReposeModuleDiscovery::defaultSearchPaths(const QStringList& extraPaths) {
  QStringList paths = extraPaths;
  const QString env = qEnvironmentVariable("REPOSE_MODULE_PATH");
  paths += env.split(QDir::listSeparator(), Qt::SkipEmptyParts);
  paths += QDir(QCoreApplication::applicationDirPath()).filePath("../lib/repose-modules");
  for (QString& path : paths) path = QDir::cleanPath(QDir(path).absolutePath());
  paths.removeDuplicates();
  return paths;
}

QStringList qReposeModuleDiscovery::findDescriptionFiles() const {
  QStringList files;
  for (const QString& path : this->SearchPaths) {
    const QDir dir(path);
    if (dir.exists("module.json")) {
      files << QDir::cleanPath(dir.absoluteFilePath("module.json"));
      continue;
    }
    for (const QString& sub : dir.entryList(QDir::Dirs | QDir::NoDotAndDotDot, QDir::Name))
      if (QFileInfo::exists(dir.filePath(sub + "/module.json")))
        files << QDir::cleanPath(dir.absoluteFilePath(sub + "/module.json"));
  }
  files.removeDuplicates();  // overlapping search paths reach a folder twice
  return files;
}

namespace {
// Fails with "<file>: <problem>" so every message says which module.json is wrong.
bool fail(QString* error, const QString& file, const QString& problem) {
  if (error) *error = file + ": " + problem;
  return false;
}

bool readStringList(const QJsonValue& value, QStringList* out) {
  if (!value.isArray()) return false;
  out->clear();
  for (const QJsonValue& item : value.toArray()) {
    if (!item.isString() || item.toString().trimmed().isEmpty()) return false;
    *out << item.toString();
  }
  return true;
}
}  // namespace

bool qReposeModuleDiscovery::readDescription(const QString& jsonPath,
                                             qReposeModuleDescription* description,
                                             QString* error) {
  QFile file(jsonPath);
  if (!file.open(QIODevice::ReadOnly)) return fail(error, jsonPath, file.errorString());
  QJsonParseError parseError;
  const QJsonDocument document = QJsonDocument::fromJson(file.readAll(), &parseError);
  if (document.isNull())
    return fail(error, jsonPath,
                QString("invalid JSON at offset %1: %2")
                    .arg(parseError.offset)
                    .arg(parseError.errorString()));
  if (!document.isObject()) return fail(error, jsonPath, "expected a JSON object");
  const QJsonObject json = document.object();

  qReposeModuleDescription d;
  d.jsonPath = QFileInfo(jsonPath).absoluteFilePath();
  // Text fields: those Slicer's generic module test requires non-empty, and the others.
  const struct {
    const char* key;
    QString* target;
    bool nonEmpty;
  } strings[] = {{"name", &d.name, true},
                 {"title", &d.title, true},
                 {"version", &d.version, true},
                 {"description", &d.description, true},
                 {"category", &d.category, true},
                 {"help", &d.helpText, true},
                 {"acknowledgement", &d.acknowledgementText, true},
                 {"library", &d.library, true}};
  for (const auto& field : strings) {
    const QJsonValue value = json.value(field.key);
    if (value.isUndefined())
      return fail(error, jsonPath, QString("missing required field '%1'").arg(field.key));
    if (!value.isString())
      return fail(error, jsonPath, QString("field '%1' must be a string").arg(field.key));
    *field.target = value.toString();
    if (field.nonEmpty && field.target->trimmed().isEmpty())
      return fail(error, jsonPath, QString("field '%1' must not be empty").arg(field.key));
  }
  if (!readStringList(json.value("contributors"), &d.contributors) || d.contributors.isEmpty())
    return fail(error, jsonPath,
                "field 'contributors' must be a non-empty array of non-empty strings");
  if (!json.contains("dependencies"))
    return fail(error, jsonPath, "missing required field 'dependencies'");
  if (!readStringList(json.value("dependencies"), &d.dependencies))
    return fail(error, jsonPath, "field 'dependencies' must be an array of module names");
  static const QRegularExpression identifier("^[A-Za-z][A-Za-z0-9_]*$");
  static const QRegularExpression semver("^\\d+\\.\\d+\\.\\d+$");
  if (!identifier.match(d.name).hasMatch())
    return fail(error, jsonPath, "field 'name' must be an identifier, not '" + d.name + "'");
  if (!semver.match(d.version).hasMatch())
    return fail(error, jsonPath, "field 'version' must look like 1.2.3, not '" + d.version + "'");
  if (!identifier.match(d.library).hasMatch())
    return fail(error, jsonPath,
                "field 'library' must be a library base name, not '" + d.library + "'");
  *description = d;
  return true;
}

QString qReposeModuleDiscovery::libraryPath(const qReposeModuleDescription& description) {
  const QDir dir = QFileInfo(description.jsonPath).absoluteDir();
  for (const QString& prefix : {QString("lib"), QString()})
    for (const char* suffix : {".so", ".dylib", ".dll"}) {
      const QString candidate = dir.filePath(prefix + description.library + suffix);
      if (QFileInfo(candidate).isFile()) return candidate;
    }
  return {};
}

bool qReposeModuleDiscovery::load(const qReposeModuleDescription& d, QString* error) {
  const QString path = libraryPath(d);
  if (path.isEmpty())
    return fail(error, d.jsonPath, "plugin library '" + d.library + "' not found beside it");
  auto loader = std::make_unique<QPluginLoader>(path);
  // The metadata is read without running any of the library's code.
  const QJsonObject meta = loader->metaData();
  if (meta.value("IID").toString() != qSlicerAbstractReposeModule_iid)
    return fail(error, path,
                "not a Repose module plugin (interface '" + meta.value("IID").toString() + "')");
  const QJsonObject built = meta.value("MetaData").toObject();
  const QString builtName = built.value("name").toString();
  const QString builtVersion = built.value("version").toString();
  if (builtName != d.name || builtVersion != d.version)
    return fail(error, path,
                QString("plugin was built as %1 %2 but its module.json says %3 %4")
                    .arg(builtName, builtVersion, d.name, d.version));
  QObject* instance = loader->instance();
  if (!instance) return fail(error, path, loader->errorString());
  auto* module = qobject_cast<qSlicerAbstractReposeModule*>(instance);
  if (!module) return fail(error, path, "plugin does not implement qSlicerAbstractReposeModule");
  const struct {
    const char* key;
    QString plugin, json;
  } checks[] = {{"name", module->name(), d.name},
                {"title", module->title(), d.title},
                {"category", module->category(), d.category},
                {"contributors", module->contributors().join("; "), d.contributors.join("; ")},
                {"help", module->helpText(), d.helpText},
                {"acknowledgement", module->acknowledgementText(), d.acknowledgementText}};
  for (const auto& check : checks) {
    if (check.plugin.trimmed().isEmpty())
      return fail(error, path, QString("plugin returns an empty %1").arg(check.key));
    if (check.plugin != check.json)
      return fail(error, path, QString("plugin's %1 differs from %2").arg(check.key, d.jsonPath));
  }
  module->setup();
  this->Modules.append({d, path, module});
  this->Loaders.push_back(std::move(loader));
  return true;
}

int qReposeModuleDiscovery::discover() {
  QList<qReposeModuleDescription> pending;
  QSet<QString> names;
  for (const QString& jsonPath : this->findDescriptionFiles()) {
    qReposeModuleDescription d;
    QString error;
    if (!readDescription(jsonPath, &d, &error)) {
      this->Errors << error;
    } else if (names.contains(d.name) || this->findModule(d.name)) {
      this->Errors << jsonPath + ": module '" + d.name + "' already found earlier; skipped";
    } else {
      names.insert(d.name);
      pending << d;
    }
  }
  // Load in dependency order: each pass loads the modules whose dependencies are all loaded.
  int loaded = 0;
  for (bool progress = true; progress && !pending.isEmpty();) {
    progress = false;
    for (int i = 0; i < pending.size(); ++i) {
      const qReposeModuleDescription d = pending[i];
      bool ready = true, missing = false;
      for (const QString& dependency : d.dependencies) {
        ready = ready && this->findModule(dependency);
        missing = missing || !names.contains(dependency);
      }
      if (!ready && !missing) continue;
      pending.removeAt(i--);
      progress = true;
      QString error;
      if (missing) {
        names.remove(d.name);  // so modules that need this one report it too
        this->Errors << d.jsonPath + ": a dependency is missing (needs " +
                            d.dependencies.join(", ") + ")";
      } else if (this->load(d, &error)) {
        ++loaded;
      } else {
        names.remove(d.name);
        this->Errors << error;
      }
    }
  }
  for (const qReposeModuleDescription& d : pending)
    this->Errors << d.jsonPath + ": dependency cycle (needs " + d.dependencies.join(", ") + ")";
  return loaded;
}

const qReposeModuleDiscovery::Module* qReposeModuleDiscovery::findModule(
    const QString& name) const {
  for (const Module& m : this->Modules)
    if (m.description.name == name) return &m;
  return nullptr;
}
