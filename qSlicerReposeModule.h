// qSlicerReposeModule: the Repose loadable module, a Qt plugin the workbench finds through
// module.json. Owns the module's logic and parameter node and creates its panel.
#pragma once

#include "qSlicerAbstractReposeModule.h"

#include <vtkSmartPointer.h>

#include <QObject>
#include <QPointer>

class vtkMRMLReposeParametersNode;
class qSlicerReposeModuleWidget;
class vtkSlicerReposeLogic;

class qSlicerReposeModule : public QObject, public qSlicerAbstractReposeModule {
  Q_OBJECT
  // module.json is compiled into the plugin so the host can compare it with the installed copy.
  Q_PLUGIN_METADATA(IID qSlicerAbstractReposeModule_iid FILE "module.json")
  Q_INTERFACES(qSlicerAbstractReposeModule)
 public:
  explicit qSlicerReposeModule(QObject* parent = nullptr);
  ~qSlicerReposeModule() override;

  QString name() const override;
  QString title() const override;
  QString category() const override;
  QStringList contributors() const override;
  QString helpText() const override;
  QString acknowledgementText() const override;
  QIcon icon() const override;

  void setup() override;
  QWidget* createWidgetRepresentation(QWidget* parent) override;
  QStringList fileFilters() const override;
  bool openFile(const QString& path, QString* errorMessage) override;
  QWidget* createViewRepresentation(QWidget* parent) override;
  bool saveScene(const QString& folder, QString* errorMessage) override;
  bool isBusy() const override;
  bool exportResults(const QString& folder, QString* errorMessage) override;

  vtkSlicerReposeLogic* logic() const;
  vtkMRMLReposeParametersNode* parameterNode() const;

 private:
  bool openScene(const QString& folder, QString* errorMessage);
  vtkSmartPointer<vtkSlicerReposeLogic> Logic;
  vtkSmartPointer<vtkMRMLReposeParametersNode> ParameterNode;
  QPointer<qSlicerReposeModuleWidget> Panel;  // the last panel made: File actions go through it
};
