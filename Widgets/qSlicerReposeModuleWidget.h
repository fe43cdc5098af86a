// qSlicerReposeModuleWidget: the Repose module panel. Rebuilds itself from the parameter node
// and the logic on every Modified (updateWidgetFromMRML) and writes user edits to the node.
#pragma once

#include "qSlicerReposeModuleWidgetsExport.h"

#include <QScopedPointer>
#include <QWidget>

class qSlicerReposeModuleWidgetPrivate;
class vtkMRMLReposeParametersNode;
class vtkSlicerReposeLogic;

class QSLICER_REPOSE_MODULE_WIDGETS_EXPORT qSlicerReposeModuleWidget : public QWidget {
  Q_OBJECT
 public:
  explicit qSlicerReposeModuleWidget(QWidget* parent = nullptr);
  ~qSlicerReposeModuleWidget() override;

  // The logic loads what the node names; the widget hands it its parameter node.
  void setLogic(vtkSlicerReposeLogic* logic);
  vtkSlicerReposeLogic* logic() const;
  // The widget shows and edits this node; without one the panel is disabled.
  void setParameterNode(vtkMRMLReposeParametersNode* node);
  vtkMRMLReposeParametersNode* parameterNode() const;

  // What a user does by typing a path and pressing Enter: the node gets the path, the logic
  // loads it. True if the volume loaded.
  bool setInputPath(const QString& path);
  // The info box text: the loaded volume's summary, an error line, or a hint.
  QString inputInfoText() const;

  // File dialog filters for the input (also used by the module's File > Open).
  static QStringList inputFileFilters();

  void updateWidgetFromMRML();

 private:
  void onInputPathEditingFinished();
  void onBrowseClicked();

  QScopedPointer<qSlicerReposeModuleWidgetPrivate> d_ptr;
  Q_DECLARE_PRIVATE(qSlicerReposeModuleWidget)
  Q_DISABLE_COPY(qSlicerReposeModuleWidget)
};
