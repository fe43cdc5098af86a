// qSlicerAbstractReposeModule: the interface a loadable module plugin implements, as Slicer's
// qSlicerAbstractCoreModule; the host finds plugins by module.json and casts them to this.
#pragma once

#include <QIcon>
#include <QString>
#include <QStringList>
#include <QtPlugin>

class QWidget;

class qSlicerAbstractReposeModule {
 public:
  virtual ~qSlicerAbstractReposeModule() = default;

  // Metadata; must agree with the module's module.json (the host checks).
  virtual QString name() const = 0;
  virtual QString title() const = 0;
  virtual QString category() const = 0;
  virtual QStringList contributors() const = 0;
  virtual QString helpText() const = 0;
  virtual QString acknowledgementText() const = 0;
  virtual QIcon icon() const = 0;

  // Called once after loading, before any other use: create logic and parameter node.
  virtual void setup() = 0;
  // The module panel; the caller owns it (through `parent`). May be called more than once.
  virtual QWidget* createWidgetRepresentation(QWidget* parent) = 0;

  // Files the module opens (File > Open...), as QFileDialog filters, and opening one (a file,
  // or a folder the module knows, such as a scene folder).
  virtual QStringList fileFilters() const = 0;
  virtual bool openFile(const QString& path, QString* errorMessage) = 0;

  // The module's views (Slicer's layout area: slice and 3D views), shown in the window's centre
  // while the module is current; the caller owns it. Null: the module has none.
  virtual QWidget* createViewRepresentation(QWidget* parent) = 0;
  // Saving the module's state as a scene folder (File > Save Scene).
  virtual bool saveScene(const QString& folder, QString* errorMessage) = 0;
  // True while the module runs background work (the host waits for it before a screenshot).
  virtual bool isBusy() const = 0;
  // File > Export: the module's results written to a folder (for Repose, the posed volumes and
  // the transform), in the background with the panel's progress bar and Cancel. False with a
  // message when it cannot start.
  virtual bool exportResults(const QString& folder, QString* errorMessage) = 0;
};

#define qSlicerAbstractReposeModule_iid "org.repose.qSlicerAbstractReposeModule/1.2"
Q_DECLARE_INTERFACE(qSlicerAbstractReposeModule, qSlicerAbstractReposeModule_iid)
