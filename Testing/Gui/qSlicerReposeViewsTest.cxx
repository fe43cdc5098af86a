// The module's panel and views together, as a user drives them, on the 8 mm phantom (run under
// xvfb-run: the 3D view needs OpenGL): load G and S, load the elbow pose, build the cage and mesh
// (a job, polled), then turn the forearm through the panel: the coronal slice view through the
// elbow shows the forearm's labels when it hangs straight and not when it is turned forward,
// undo brings the turn back, screenshots of the four views before and after are saved as test
// artifacts and are not blank, an export cancelled leaves nothing and a finished one writes the
// posed files; the workbench renders a saved scene to a PNG from the command line.
#include "qSlicerReposeModuleWidget.h"
#include "qSlicerReposeSliceView.h"
#include "qSlicerReposeViewsWidget.h"
#include "vtkMRMLReposeParametersNode.h"
#include "vtkMRMLReposePoseNode.h"
#include "vtkSlicerReposeLogic.h"

#include <QVTKOpenGLNativeWidget.h>
#include <repose/io/VolumeIO.h>
#include <repose/phantom/Phantom.h>

#include <vtkNew.h>

#include <QDir>
#include <QHBoxLayout>
#include <QProcess>
#include <QSlider>
#include <QSurfaceFormat>
#include <QTemporaryDir>
#include <QToolButton>
#include <QtTest>

#include <set>

namespace {

// Artifacts stay in the build tree for a person to look at (not deleted with the test's dir).
QString artifact(const QString& name) {
  const QString dir = QString(REPOSE_BIN_DIR) + "/../Testing/Artifacts";
  QDir().mkpath(dir);
  return QDir(dir).absoluteFilePath(name);
}

// Distinct colours in a rectangle of an image: a blank (uniform) view has one or two.
int colours(const QImage& image, const QRect& r) {
  std::set<QRgb> seen;
  for (int y = r.top(); y <= r.bottom(); y += 2)
    for (int x = r.left(); x <= r.right(); x += 2) seen.insert(image.pixel(x, y));
  return int(seen.size());
}

// Labelled pixels the coronal view shows along the left forearm hanging straight: below the
// elbow (pivot R -176, S 806) to the wrist.
int forearmPixels(const qSlicerReposeSliceView* coronal) {
  int n = 0;
  for (double s = 790; s >= 640; s -= 4)
    for (double r = -200; r <= -150; r += 4) n += coronal->labelAtRas(r, -14, s) > 0;
  return n;
}

}  // namespace

class qSlicerReposeViewsTest : public QObject {
  Q_OBJECT
 private slots:
  void posingThroughThePanelUpdatesTheViews() {
    QTemporaryDir dir;
    repose::PhantomOptions po;
    po.voxelMm = 8;
    const auto [organs, parts] = repose::Phantom(po).makeVolumes();
    const QString G = dir.filePath("G.nii.gz"), S = dir.filePath("S.nii.gz");
    repose::writeVolume(organs, G.toStdString());
    repose::writeVolume(parts, S.toStdString());

    vtkNew<vtkSlicerReposeLogic> logic;
    vtkNew<vtkMRMLReposeParametersNode> node;
    QWidget window;
    auto* layout = new QHBoxLayout(&window);
    auto* panel = new qSlicerReposeModuleWidget;
    auto* views = new qSlicerReposeViewsWidget;
    layout->addWidget(panel);
    layout->addWidget(views, 1);
    panel->setLogic(logic);
    panel->setParameterNode(node);
    views->setLogic(logic);
    window.resize(1400, 900);
    window.show();
    QVERIFY(QTest::qWaitForWindowExposed(&window));

    // A user's steps: the segmentation, its body parts, the pose; then Build.
    QVERIFY(panel->setInputPath(G));
    node->SetBodyPartMapPath(S.toStdString());
    QVERIFY(panel->setPosePath(QString(REPOSE_SOURCE_DIR) + "/bench/poses/elbow90.pose.json"));
    QCOMPARE(QString::fromStdString(node->GetActiveGroup()), QString("left forearm and hand"));
    QVERIFY2(panel->buildRig(), qPrintable(panel->jobStatusText()));
    QVERIFY(logic->IsJobRunning());  // on the worker: the window is free meanwhile
    panel->waitForJobs();
    QVERIFY2(logic->GetLivePose() == panel->activePose(), qPrintable(panel->jobStatusText()));
    QCOMPARE(panel->activeGroupAngle(), 90.0);

    // The coronal view through the elbow: the forearm is turned forward, out of the plane.
    views->setSlicePosition(1, -14);
    const qSlicerReposeSliceView* coronal = views->sliceView(1);
    QVERIFY(coronal->labelsShown() > 5);
    const int bent = forearmPixels(coronal);
    const QImage before = views->renderViews();
    QVERIFY(before.save(artifact("views_elbow90.png")));

    // Straighten it through the panel's slider, as a drag: the views follow at once.
    auto* slider = panel->findChild<QSlider*>("AngleSlider");
    QVERIFY(slider);
    slider->setSliderDown(true);  // the handle grabbed (sliderPressed)
    for (int angle = 85; angle >= 0; angle -= 5) slider->setValue(angle);
    slider->setSliderDown(false);  // and let go (sliderReleased)
    QCOMPARE(panel->activeGroupAngle(), 0.0);
    const int straight = forearmPixels(coronal);
    qInfo(
        "forearm pixels in the coronal view: %d turned, %d straight; live frame %.1f ms, "
        "three slices %.1f ms",
        bent, straight, logic->GetLiveFrameMilliseconds(), views->lastSliceMilliseconds());
    QVERIFY2(straight > 3 * bent + 10, qPrintable(QString("%1 vs %2").arg(straight).arg(bent)));
    const QImage after = views->renderViews();
    QVERIFY(after.save(artifact("views_elbow0.png")));
    QVERIFY(before != after);
    // Not blank: each quadrant (Red, 3D, Yellow, Green) has structure.
    const int w = after.width() / 2, h = after.height() / 2;
    for (const QRect& q :
         {QRect(0, 0, w, h), QRect(w, 0, w, h), QRect(0, h, w, h), QRect(w, h, w, h)})
      QVERIFY2(
          colours(after, q) > 8,
          qPrintable(
              QString("quadrant %1,%2: %3 colours").arg(q.x()).arg(q.y()).arg(colours(after, q))));

    // One drag, one undo step: undo turns the forearm forward again.
    auto* undo = panel->findChild<QToolButton*>("UndoButton");
    QVERIFY(undo->isEnabled());
    undo->click();
    QCOMPARE(panel->activeGroupAngle(), 90.0);
    QCOMPARE(forearmPixels(coronal), bent);
    QVERIFY(!logic->CanUndo());

    // Export: cancelled, nothing is written; finished, the posed files are there.
    const QString out = dir.filePath("out");
    node->SetOutputFolder(out.toStdString());
    QVERIFY2(panel->exportPose(), qPrintable(panel->jobStatusText()));
    panel->cancelJob();
    panel->waitForJobs();
    QVERIFY2(panel->jobStatusText().startsWith("Cancelled"), qPrintable(panel->jobStatusText()));
    QVERIFY(!QFileInfo::exists(out + "/posed_G.nii.gz"));
    QVERIFY2(panel->exportPose(), qPrintable(panel->jobStatusText()));
    panel->waitForJobs();
    QVERIFY2(panel->jobStatusText().startsWith("Exported"), qPrintable(panel->jobStatusText()));
    for (const char* f : {"posed_G.nii.gz", "posed_S.nii.gz", "transform.nrrd", "report.json"})
      QVERIFY2(QFileInfo::exists(out + "/" + f), f);

    // The workbench renders the saved scene's four views from the command line.
    const QString scene = dir.filePath("scene");
    QVERIFY2(logic->SaveScene(scene.toStdString()), logic->GetLastErrorMessage().c_str());
    const QString png = artifact("workbench_scene.png");
    QFile::remove(png);
    QProcess workbench;
    QProcessEnvironment env = QProcessEnvironment::systemEnvironment();
    env.remove("REPOSE_MODULE_PATH");
    workbench.setProcessEnvironment(env);
    workbench.start(QString(REPOSE_BIN_DIR) + "/ReposeWorkbench",
                    {"--scene", scene, "--screenshot", png});
    QVERIFY(workbench.waitForFinished(240000));
    QVERIFY2(workbench.exitCode() == 0, workbench.readAllStandardError().constData());
    const QImage shot(png);
    QVERIFY(!shot.isNull());
    QVERIFY(colours(shot, shot.rect()) > 30);
  }
};

int main(int argc, char** argv) {
  QSurfaceFormat::setDefaultFormat(QVTKOpenGLNativeWidget::defaultFormat());
  QApplication app(argc, argv);
  qSlicerReposeViewsTest test;
  return QTest::qExec(&test, argc, argv);
}
#include "qSlicerReposeViewsTest.moc"
