// qSlicerReposeSliceView: one slice view of the module (Slicer's red, yellow or green view): the
// label map on that plane drawn with its colour table at an opacity over the image (grey), with
// the view's colour bar and name. Pure Qt painting of a QImage, so it draws the same on screen,
// under xvfb and with the offscreen platform.
#pragma once

#include "qSlicerReposeModuleWidgetsExport.h"

#include <QColor>
#include <QHash>
#include <QImage>
#include <QWidget>

#include <vtkImageData.h>
#include <vtkSmartPointer.h>

class vtkLookupTable;

class QSLICER_REPOSE_MODULE_WIDGETS_EXPORT qSlicerReposeSliceView : public QWidget {
  Q_OBJECT
 public:
  // orientation: 0 axial (Red), 1 coronal (Green), 2 sagittal (Yellow), as Slicer names them.
  explicit qSlicerReposeSliceView(int orientation, QWidget* parent = nullptr);

  int orientation() const { return this->Orientation; }
  QString viewName() const;         // "Red", "Green", "Yellow"
  QColor viewColor() const;         // Slicer's view colours
  QString orientationName() const;  // "Axial", "Coronal", "Sagittal"

  // The labels on the plane (one voxel thick, RAS-aligned, as the Logic's live slices) and an
  // optional image on the same grid; the lookup table maps label values to colours.
  void setSlice(vtkImageData* labels, vtkLookupTable* lut, vtkImageData* image = nullptr);
  // The body-part map on the same grid, drawn over the labels as outlines (each part's border
  // pixels in its colour, opaque), as Slicer outlines a segmentation; null: none. Takes effect
  // at the next setSlice.
  void setPartsOverlay(vtkImageData* parts, const QHash<int, QColor>& colors);
  void setPositionMm(double position);
  double positionMm() const { return this->PositionMm; }
  void setLabelOpacity(double opacity);
  double labelOpacity() const { return this->LabelOpacity; }
  // The image's grey mapping (Slicer's window/level); window <= 0: the slice's own range.
  void setWindowLevel(double window, double level);

  // What is drawn, at the slice's own resolution (screen right = patient left for axial and
  // coronal views, as radiologists read them; superior up).
  const QImage& sliceImage() const { return this->Image; }
  // The label value shown at a pixel of sliceImage() (-1 outside).
  int labelAt(int x, int y) const;
  // Distinct non-zero labels on the slice.
  int labelsShown() const;
  // The overlay's body part at a pixel of sliceImage() (0 none, -1 outside or no overlay), and
  // whether that pixel is drawn as the part's outline.
  int partAt(int x, int y) const;
  bool isPartOutline(int x, int y) const;
  int partAtRas(double r, double a, double s) const;
  // The label shown at a RAS point of the plane (nearest pixel; -1 off the slice).
  int labelAtRas(double r, double a, double s) const;
  // The RAS point under a widget position (false off the drawn slice), and the widget position
  // where a RAS point of the plane is drawn (what the data probe and its tests use).
  bool rasAtWidgetPoint(const QPointF& at, double ras[3]) const;
  QPointF widgetPointOfRas(double r, double a, double s) const;

  QSize sizeHint() const override { return {320, 320}; }

 signals:
  // The pointer moved over the drawn slice, to this RAS point (mouse tracking: no button
  // needed), or left it.
  void probed(double r, double a, double s);
  void probeLeft();

  // The mouse wheel turned over the view: this many slices on (positive: towards superior,
  // anterior or the patient's left... as the plane's normal axis increases).
  void scrolled(int steps);

 protected:
  void paintEvent(QPaintEvent* event) override;
  void wheelEvent(QWheelEvent* event) override;
  void mouseMoveEvent(QMouseEvent* event) override;
  void leaveEvent(QEvent* event) override;

 private:
  QRectF imageRect() const;  // where the slice is drawn in the widget (aspect kept)
  // The pixel of sliceImage() a RAS point of the plane falls in (false off the slice).
  bool pixelOfRas(double r, double a, double s, int& x, int& y) const;
  void drawPartsOutline();  // the overlay over Image, after the labels
  static constexpr int BarHeight = 18;

  int Orientation;
  double PositionMm = 0;
  double LabelOpacity = 0.8;
  double Window = 0, Level = 0;
  QImage Image;                         // RGB of the slice, rows top = superior (or anterior)
  std::vector<int> Labels;              // label per pixel of Image
  vtkSmartPointer<vtkImageData> Parts;  // the overlay's body parts (null: none)
  QHash<int, QColor> PartColors;
  std::vector<int> PartPixels;          // part per pixel of Image (empty: no overlay)
  std::vector<char> OutlinePixels;      // drawn as a part's outline
  vtkSmartPointer<vtkImageData> Shown;  // the slice drawn (its geometry maps RAS to pixels)
  int Width = 0, Height = 0;
  double AspectMm = 1;  // pixel height / width in mm
};
