// Tests of qSlicerReposeModuleWidget: it shows what its parameter node and logic hold, loads a
// real file through its API and through typing, and follows changes made to the node elsewhere.
#include "qSlicerReposeModuleWidget.h"
#include "vtkMRMLReposeParametersNode.h"
#include "vtkSlicerReposeLogic.h"

#include <vtkNew.h>

#include <QGroupBox>
#include <QLineEdit>
#include <QPlainTextEdit>
#include <QtTest>

namespace {
QString dataPath(const char* relative) {
  return QString(REPOSE_DATA_DIR) + "/" + relative;
}
}  // namespace

class qSlicerReposeModuleWidgetTest : public QObject {
  Q_OBJECT
 private slots:
  void disabledWithoutNode() {
    qSlicerReposeModuleWidget widget;
    QVERIFY(!widget.findChild<QGroupBox*>("InputGroupBox")->isEnabled());
    QCOMPARE(widget.inputInfoText(), QString("No parameter node."));
    QVERIFY(!widget.setInputPath(dataPath("totalsegmentator/example_seg.nii.gz")));
  }

  void loadsRealFileAndShowsItsInfo() {
    vtkNew<vtkSlicerReposeLogic> logic;
    vtkNew<vtkMRMLReposeParametersNode> node;
    qSlicerReposeModuleWidget widget;
    widget.setLogic(logic);
    widget.setParameterNode(node);
    widget.show();
    QVERIFY(widget.findChild<QGroupBox*>("InputGroupBox")->isEnabled());
    QCOMPARE(widget.inputInfoText(), QString("No volume loaded."));
    QCOMPARE(logic->GetParameterNode(), node.GetPointer());  // the widget shares its node

    const QString path = dataPath("totalsegmentator/example_seg.nii.gz");
    QVERIFY(widget.setInputPath(path));
    QCOMPARE(QString::fromStdString(node->GetInputSegmentationPath()), path);
    QCOMPARE(widget.findChild<QLineEdit*>("InputPathLineEdit")->text(), path);
    const QString info = widget.inputInfoText();
    QVERIFY2(info.contains("Dimensions: 122 x 101 x 30"), qPrintable(info));
    QVERIFY2(info.contains("Spacing: 3 x 3 x 3 mm"), qPrintable(info));
    QVERIFY2(info.contains("Orientation: RAS"), qPrintable(info));
    QVERIFY2(info.contains("Scalar type: uint8"), qPrintable(info));
    QVERIFY2(info.contains("Labels: 41 present"), qPrintable(info));
    QVERIFY(widget.findChild<QPlainTextEdit*>("InputInfoTextBox")->isReadOnly());
  }

  void followsNodeChanges() {
    vtkNew<vtkSlicerReposeLogic> logic;
    vtkNew<vtkMRMLReposeParametersNode> node;
    qSlicerReposeModuleWidget widget;
    widget.setParameterNode(node);  // node first, logic second: the widget still connects them
    widget.setLogic(logic);
    const QString seg = dataPath("slicer_seg/Segmentation.seg.nrrd");
    node->SetInputSegmentationPath(seg.toStdString());  // as a script or scene load would
    QCOMPARE(widget.findChild<QLineEdit*>("InputPathLineEdit")->text(), seg);
    QVERIFY2(widget.inputInfoText().contains("Dimensions: 128 x 128 x 34"),
             qPrintable(widget.inputInfoText()));

    const QString missing = dataPath("no/such.nii.gz");
    node->SetInputSegmentationPath(missing.toStdString());
    QVERIFY2(widget.inputInfoText().startsWith("Error: " + missing),
             qPrintable(widget.inputInfoText()));
    QVERIFY(!widget.inputInfoText().contains('\n'));

    node->SetInputSegmentationPath("");
    QCOMPARE(widget.inputInfoText(), QString("No volume loaded."));
    QVERIFY(widget.findChild<QLineEdit*>("InputPathLineEdit")->text().isEmpty());

    // A different node replaces the old one, which is no longer observed.
    vtkNew<vtkMRMLReposeParametersNode> other;
    other->SetInputSegmentationPath(seg.toStdString());
    widget.setParameterNode(other);
    QVERIFY(widget.inputInfoText().contains("128 x 128 x 34"));
    node->SetInputSegmentationPath(missing.toStdString());
    QCOMPARE(widget.findChild<QLineEdit*>("InputPathLineEdit")->text(), seg);
  }

  void typingAPathWritesTheNode() {
    vtkNew<vtkSlicerReposeLogic> logic;
    vtkNew<vtkMRMLReposeParametersNode> node;
    qSlicerReposeModuleWidget widget;
    widget.setLogic(logic);
    widget.setParameterNode(node);
    widget.show();
    QVERIFY(QTest::qWaitForWindowExposed(&widget));
    auto* edit = widget.findChild<QLineEdit*>("InputPathLineEdit");
    edit->setFocus();
    const QString path = dataPath("slicer_seg/SegmentationOverlapping.seg.nrrd");
    QTest::keyClicks(edit, path);
    QVERIFY(node->GetInputSegmentationPath().empty());  // nothing is written while typing
    QTest::keyClick(edit, Qt::Key_Return);
    QCOMPARE(QString::fromStdString(node->GetInputSegmentationPath()), path);
    QVERIFY2(widget.inputInfoText().contains("Layers: 2"), qPrintable(widget.inputInfoText()));
  }

  void nodeOutlivesWidget() {
    vtkNew<vtkMRMLReposeParametersNode> node;
    vtkNew<vtkSlicerReposeLogic> logic;
    {
      qSlicerReposeModuleWidget widget;
      widget.setLogic(logic);
      widget.setParameterNode(node);
    }
    // The widget removed its observers: these must not reach a dead widget.
    node->SetInputSegmentationPath(dataPath("slicer_seg/Segmentation.seg.nrrd").toStdString());
    QVERIFY(logic->GetVolumeImageData() != nullptr);
  }
};

QTEST_MAIN(qSlicerReposeModuleWidgetTest)
#include "qSlicerReposeModuleWidgetTest.moc"
