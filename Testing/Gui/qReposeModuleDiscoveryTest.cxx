// Tests of module discovery: the built Repose plugin is found, loads, and agrees with its
// module.json (Slicer's generic module checks), and broken descriptions give clear errors.
#include "qReposeModuleDiscovery.h"
#include "qSlicerAbstractReposeModule.h"

#include <QFile>
#include <QJsonArray>
#include <QJsonDocument>
#include <QJsonObject>
#include <QTemporaryDir>
#include <QtTest>

class qReposeModuleDiscoveryTest : public QObject {
  Q_OBJECT
 private:
  // A module folder in `root` holding `json` as module.json; returns the module.json path.
  static QString writeModule(const QString& root, const QString& folder, const QByteArray& json) {
    QDir(root).mkpath(folder);
    const QString path = root + "/" + folder + "/module.json";
    QFile file(path);
    file.open(QIODevice::WriteOnly);
    file.write(json);
    return path;
  }
  static QJsonObject installedJson() {
    QFile file(REPOSE_MODULES_DIR "/Repose/module.json");
    file.open(QIODevice::ReadOnly);
    return QJsonDocument::fromJson(file.readAll()).object();
  }
  static QByteArray with(QJsonObject json, const QString& key, const QJsonValue& value) {
    if (value.isUndefined())
      json.remove(key);
    else
      json[key] = value;
    return QJsonDocument(json).toJson();
  }

 private slots:
  void builtPluginLoadsAndAgreesWithModuleJson() {
    qReposeModuleDiscovery discovery;
    discovery.setSearchPaths({REPOSE_MODULES_DIR});
    QCOMPARE(discovery.discover(), 1);
    QVERIFY2(discovery.errors().isEmpty(), qPrintable(discovery.errors().join("\n")));
    const qReposeModuleDiscovery::Module* m = discovery.findModule("Repose");
    QVERIFY(m && m->module);
    qSlicerAbstractReposeModule* module = m->module;
    // What Slicer's generic module tests check: nothing a user sees is empty.
    QVERIFY(!module->title().trimmed().isEmpty());
    QVERIFY(!module->category().trimmed().isEmpty());
    QVERIFY(!module->contributors().isEmpty() && !module->contributors().first().isEmpty());
    QVERIFY(!module->helpText().trimmed().isEmpty());
    QVERIFY(!module->acknowledgementText().trimmed().isEmpty());
    QVERIFY(QFile::exists(":/Icons/Repose.png"));  // the plugin registered its resources
    QVERIFY(!module->fileFilters().isEmpty());
    // And the plugin agrees with module.json, field by field.
    const qReposeModuleDescription& d = m->description;
    QCOMPARE(module->name(), d.name);
    QCOMPARE(module->title(), d.title);
    QCOMPARE(module->category(), d.category);
    QCOMPARE(module->contributors(), d.contributors);
    QCOMPARE(module->helpText(), d.helpText);
    QCOMPARE(module->acknowledgementText(), d.acknowledgementText);
    QCOMPARE(d.version, QString(REPOSE_PROJECT_VERSION));
    QCOMPARE(d.library, QString("qSlicerReposeModule"));
    QVERIFY(d.dependencies.isEmpty());
    QVERIFY(d.acknowledgementText.contains("VoxMorph"));
    QVERIFY(m->libraryPath.startsWith(REPOSE_MODULES_DIR "/Repose/"));
  }

  void installedModuleJsonIsTheSourceOne() {
    qReposeModuleDescription source, installed;
    QString error;
    QVERIFY2(
        qReposeModuleDiscovery::readDescription(REPOSE_SOURCE_DIR "/module.json", &source, &error),
        qPrintable(error));
    QVERIFY2(qReposeModuleDiscovery::readDescription(REPOSE_MODULES_DIR "/Repose/module.json",
                                                     &installed, &error),
             qPrintable(error));
    QCOMPARE(installed.name, source.name);
    QCOMPARE(installed.version, source.version);
    QCOMPARE(installed.helpText, source.helpText);
    QCOMPARE(installed.description, source.description);
  }

  void searchPathsInPriorityOrder() {
    qputenv("REPOSE_MODULE_PATH", "/env/one:/env/two");
    const QStringList paths = qReposeModuleDiscovery::defaultSearchPaths({"/extra"});
    qunsetenv("REPOSE_MODULE_PATH");
    QCOMPARE(paths.size(), 4);
    QCOMPARE(paths[0], QString("/extra"));
    QCOMPARE(paths[1], QString("/env/one"));
    QCOMPARE(paths[2], QString("/env/two"));
    QCOMPARE(paths[3],
             QDir::cleanPath(QCoreApplication::applicationDirPath() + "/../lib/repose-modules"));
  }

  void badDescriptionsNameFileAndProblem_data() {
    QTest::addColumn<QByteArray>("json");
    QTest::addColumn<QString>("problem");
    const QJsonObject good = installedJson();
    QTest::newRow("not JSON") << QByteArray("{\"name\": ") << "invalid JSON";
    QTest::newRow("not an object") << QByteArray("[]") << "expected a JSON object";
    QTest::newRow("no title") << with(good, "title", QJsonValue::Undefined)
                              << "missing required field 'title'";
    QTest::newRow("empty category")
        << with(good, "category", " ") << "field 'category' must not be empty";
    QTest::newRow("help not text") << with(good, "help", 3) << "field 'help' must be a string";
    QTest::newRow("no contributors")
        << with(good, "contributors", QJsonArray()) << "field 'contributors'";
    QTest::newRow("no dependencies") << with(good, "dependencies", QJsonValue::Undefined)
                                     << "missing required field 'dependencies'";
    QTest::newRow("bad version") << with(good, "version", "1.0") << "field 'version'";
    QTest::newRow("bad name") << with(good, "name", "Re pose") << "field 'name'";
  }
  void badDescriptionsNameFileAndProblem() {
    QFETCH(QByteArray, json);
    QFETCH(QString, problem);
    QTemporaryDir root;
    const QString path = writeModule(root.path(), "Broken", json);
    qReposeModuleDiscovery discovery;
    discovery.setSearchPaths({root.path()});
    QCOMPARE(discovery.discover(), 0);
    QCOMPARE(discovery.errors().size(), 1);
    const QString error = discovery.errors().first();
    QVERIFY2(error.startsWith(path + ": "), qPrintable(error));
    QVERIFY2(error.contains(problem), qPrintable(error));
  }

  void missingLibraryOrDependencyIsReported() {
    QTemporaryDir root;
    QJsonObject json = installedJson();
    json["name"] = "NoLibrary";
    json["library"] = "qSlicerNoSuchModule";
    writeModule(root.path(), "NoLibrary", QJsonDocument(json).toJson());
    json["name"] = "NeedsOther";
    json["dependencies"] = QJsonArray{"NoLibrary"};
    writeModule(root.path(), "NeedsOther", QJsonDocument(json).toJson());
    qReposeModuleDiscovery discovery;
    discovery.setSearchPaths({root.path()});
    QCOMPARE(discovery.discover(), 0);
    const QString errors = discovery.errors().join("\n");
    QVERIFY2(errors.contains("plugin library 'qSlicerNoSuchModule' not found"), qPrintable(errors));
    QVERIFY2(errors.contains("NeedsOther/module.json: a dependency is missing"),
             qPrintable(errors));
  }

  void pluginThatDisagreesWithModuleJsonIsRejected() {
    QTemporaryDir root;
    const QString plugin = REPOSE_MODULES_DIR "/Repose/libqSlicerReposeModule.so";
    // A version the plugin was not built with: caught from metadata, before any plugin code runs.
    writeModule(root.path(), "OldVersion", with(installedJson(), "version", "9.9.9"));
    QVERIFY(QFile::link(plugin, root.path() + "/OldVersion/libqSlicerReposeModule.so"));
    // A title the plugin does not return.
    writeModule(root.path(), "OtherTitle", with(installedJson(), "title", "Something else"));
    QVERIFY(QFile::link(plugin, root.path() + "/OtherTitle/libqSlicerReposeModule.so"));
    QStringList errors;
    for (const char* folder : {"OldVersion", "OtherTitle"}) {
      qReposeModuleDiscovery discovery;  // one each: both are named Repose
      discovery.setSearchPaths({root.path() + "/" + folder});
      QCOMPARE(discovery.discover(), 0);
      errors += discovery.errors();
    }
    QCOMPARE(errors.size(), 2);
    QVERIFY2(errors[0].contains("plugin was built as Repose " REPOSE_PROJECT_VERSION
                                " but its module.json says Repose 9.9.9"),
             qPrintable(errors[0]));
    QVERIFY2(errors[1].contains("plugin's title differs"), qPrintable(errors[1]));
  }

  void sameNameTwiceKeepsTheFirst() {
    QTemporaryDir root;
    const QString plugin = REPOSE_MODULES_DIR "/Repose/libqSlicerReposeModule.so";
    for (const char* folder : {"A", "B"}) {
      writeModule(root.path(), folder, QJsonDocument(installedJson()).toJson());
      QVERIFY(QFile::link(plugin, root.path() + "/" + folder + "/libqSlicerReposeModule.so"));
    }
    qReposeModuleDiscovery discovery;
    // The same folder reached twice is one module, not a duplicate.
    discovery.setSearchPaths({root.path(), root.path() + "/A"});
    QCOMPARE(discovery.discover(), 1);
    QCOMPARE(discovery.errors().size(), 1);
    QVERIFY2(discovery.errors().first().startsWith(root.path() + "/B/module.json: "),
             qPrintable(discovery.errors().first()));
    QVERIFY(discovery.errors().first().contains("already found earlier"));
    QVERIFY(discovery.findModule("Repose")->description.jsonPath.endsWith("/A/module.json"));
  }
};

QTEST_GUILESS_MAIN(qReposeModuleDiscoveryTest)
#include "qReposeModuleDiscoveryTest.moc"
