// Tests of the workbench: the ReposeWorkbench executable lists modules without a display and
// renders screenshots; in process, the main window shows the module and routes File > Open.
#include "qReposeMainWindow.h"
#include "qReposeModuleDiscovery.h"
#include "qSlicerAbstractReposeModule.h"

#include <QImage>
#include <QPlainTextEdit>
#include <QScrollArea>
#include <QProcess>
#include <QTemporaryDir>
#include <QtTest>

namespace {
const QString kWorkbench = REPOSE_BIN_DIR "/ReposeWorkbench";
const QString kSegmentation = REPOSE_DATA_DIR "/totalsegmentator/example_seg.nii.gz";

struct Run {
  int exitCode = -1;
  QString out, err;
};
Run run(const QStringList& arguments, const QProcessEnvironment& env) {
  QProcess process;
  process.setProcessEnvironment(env);
  process.start(kWorkbench, arguments);
  Run result;
  if (!process.waitForFinished(120000)) return result;
  result.exitCode = process.exitStatus() == QProcess::NormalExit ? process.exitCode() : -2;
  result.out = QString::fromUtf8(process.readAllStandardOutput());
  result.err = QString::fromUtf8(process.readAllStandardError());
  return result;
}
QProcessEnvironment offscreen() {
  QProcessEnvironment env = QProcessEnvironment::systemEnvironment();
  env.insert("QT_QPA_PLATFORM", "offscreen");
  env.remove("REPOSE_MODULE_PATH");
  return env;
}
}  // namespace

class qReposeWorkbenchTest : public QObject {
  Q_OBJECT
 private slots:
  void listModulesNeedsNoDisplay() {
    QProcessEnvironment env = QProcessEnvironment::systemEnvironment();
    env.remove("QT_QPA_PLATFORM");
    env.remove("DISPLAY");
    env.remove("WAYLAND_DISPLAY");
    env.remove("REPOSE_MODULE_PATH");
    const Run r = run({"--list-modules"}, env);
    QVERIFY2(r.exitCode == 0, qPrintable(r.err));
    QVERIFY2(r.out.startsWith("Repose\t" REPOSE_PROJECT_VERSION "\tSegmentation\tRepose\t"),
             qPrintable(r.out));
    QVERIFY(r.out.contains("/lib/repose-modules/Repose/module.json"));
  }

  void brokenModuleOnModulePathFailsTheListing() {
    QTemporaryDir root;
    QDir(root.path()).mkpath("Broken");
    QFile file(root.path() + "/Broken/module.json");
    QVERIFY(file.open(QIODevice::WriteOnly));
    file.write("{}");
    file.close();
    const Run r = run({"--list-modules", "--module-path", root.path()}, offscreen());
    QCOMPARE(r.exitCode, 1);
    QVERIFY(r.out.contains("Repose\t"));  // the good module is still listed
    QVERIFY2(r.err.contains(root.path() + "/Broken/module.json: missing required field 'name'"),
             qPrintable(r.err));
  }

  void screenshotWithAnOpenedFile() {
    QTemporaryDir dir;
    const QString png = dir.filePath("workbench.png");
    const Run r = run({"--open", kSegmentation, "--screenshot", png}, offscreen());
    QVERIFY2(r.exitCode == 0, qPrintable(r.err));
    const QImage image(png);
    QVERIFY(!image.isNull());
    QVERIFY(image.width() >= 640 && image.height() >= 400);
    // A missing file or module makes the run fail.
    QCOMPARE(run({"--open", "/no/such.nii", "--screenshot", png}, offscreen()).exitCode, 1);
    QCOMPARE(run({"--module", "NoSuchModule", "--screenshot", png}, offscreen()).exitCode, 1);
  }

  void mainWindowShowsModuleAndOpensFiles() {
    qReposeModuleDiscovery discovery;
    discovery.setSearchPaths({REPOSE_MODULES_DIR});
    QCOMPARE(discovery.discover(), 1);
    qReposeMainWindow window(&discovery);
    window.show();
    QCOMPARE(window.currentModuleName(), QString("Repose"));
    QVERIFY(window.selectModule("Repose"));
    QVERIFY(!window.selectModule("Nope"));
    auto* info = window.findChild<QPlainTextEdit*>("InputInfoTextBox");
    QVERIFY(info);  // the module's panel is in the window
    QVERIFY(!discovery.modules().first().module->icon().pixmap(32).isNull());

    QVERIFY(window.openFile(kSegmentation));
    QVERIFY2(info->toPlainText().contains("Dimensions: 122 x 101 x 30"),
             qPrintable(info->toPlainText()));
    QVERIFY(window.logText().contains("Opened " + kSegmentation));
    QVERIFY(window.logText().contains("Loaded module Repose " REPOSE_PROJECT_VERSION));

    // At the window's 1280 x 800 the panel's fields are whole: the panel is never scrolled
    // sideways and the dock is as wide as its widest field needs (issue 55).
    QCOMPARE(window.size(), QSize(1280, 800));
    QCoreApplication::processEvents();
    auto* scroll = window.findChild<QScrollArea*>("ModulePanelScrollArea");
    QVERIFY(scroll);
    QCOMPARE(scroll->horizontalScrollBarPolicy(), Qt::ScrollBarAlwaysOff);
    QVERIFY2(scroll->widget()->minimumSizeHint().width() <= scroll->viewport()->width(),
             qPrintable(QString("panel needs %1 px, shows %2")
                            .arg(scroll->widget()->minimumSizeHint().width())
                            .arg(scroll->viewport()->width())));
    for (const char* name : {"RigFromOrganMapButton", "InputInfoTextBox"}) {
      auto* field = window.findChild<QWidget*>(name);
      QVERIFY2(field, name);
      const QRect inViewport(field->mapTo(scroll->viewport(), QPoint(0, 0)), field->size());
      QVERIFY2(inViewport.right() < scroll->viewport()->width(), name);
    }

    QVERIFY(!window.openFile("/no/such/file.nii.gz"));
    QVERIFY(window.logText().contains("Error: /no/such/file.nii.gz"));
    QVERIFY(info->toPlainText().startsWith("Error: "));
  }
};

QTEST_MAIN(qReposeWorkbenchTest)
#include "qReposeWorkbenchTest.moc"
