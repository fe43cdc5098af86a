// qSlicerReposeSliceView: turns a one-slice label image (and image) into an RGB QImage once per
// update, and scales it into the widget with its aspect kept.
#include "qSlicerReposeSliceView.h"

#include <vtkDataArray.h>
#include <vtkImageData.h>
#include <vtkLookupTable.h>
#include <vtkPointData.h>

#include <QPainter>
#include <QMouseEvent>
#include <QWheelEvent>

#include <algorithm>
#include <cmath>
#include <set>

qSlicerReposeSliceView::qSlicerReposeSliceView(int orientation, QWidget* parent)
    : QWidget(parent), Orientation(std::clamp(orientation, 0, 2)) {
  this->setObjectName(this->viewName() + "SliceView");
  this->setMinimumSize(120, 120);
  this->setAttribute(Qt::WA_OpaquePaintEvent);
  this->setMouseTracking(true);  // the data probe follows the pointer without a button down
}

QString qSlicerReposeSliceView::viewName() const {
  return this->Orientation == 0 ? "Red" : this->Orientation == 1 ? "Green" : "Yellow";
}

QColor qSlicerReposeSliceView::viewColor() const {
  // Slicer's slice view colours.
  return this->Orientation == 0   ? QColor(0xf3, 0x4a, 0x33)
         : this->Orientation == 1 ? QColor(0x6e, 0xb0, 0x4b)
                                  : QColor(0xed, 0xd5, 0x4c);
}

QString qSlicerReposeSliceView::orientationName() const {
  return this->Orientation == 0 ? "Axial" : this->Orientation == 1 ? "Coronal" : "Sagittal";
}

void qSlicerReposeSliceView::setPositionMm(double position) {
  this->PositionMm = position;
  this->update();
}

void qSlicerReposeSliceView::setLabelOpacity(double opacity) {
  this->LabelOpacity = std::clamp(opacity, 0.0, 1.0);
}

void qSlicerReposeSliceView::setWindowLevel(double window, double level) {
  this->Window = window;
  this->Level = level;
}

void qSlicerReposeSliceView::mouseMoveEvent(QMouseEvent* event) {
  double ras[3];
  if (this->rasAtWidgetPoint(event->localPos(), ras))
    emit this->probed(ras[0], ras[1], ras[2]);
  else
    emit this->probeLeft();
  QWidget::mouseMoveEvent(event);
}

void qSlicerReposeSliceView::leaveEvent(QEvent* event) {
  emit this->probeLeft();
  QWidget::leaveEvent(event);
}

QRectF qSlicerReposeSliceView::imageRect() const {
  if (this->Image.isNull()) return {};
  // Fit the slice with its physical aspect into the area below the bar.
  const QRect area = this->rect().adjusted(2, BarHeight + 2, -2, -2);
  const double w = this->Width, h = this->Height * this->AspectMm;
  const double scale = std::min(area.width() / w, area.height() / h);
  const QSizeF size(w * scale, h * scale);
  return {area.x() + (area.width() - size.width()) / 2,
          area.y() + (area.height() - size.height()) / 2, size.width(), size.height()};
}

bool qSlicerReposeSliceView::rasAtWidgetPoint(const QPointF& at, double ras[3]) const {
  const QRectF target = this->imageRect();
  if (target.isEmpty() || !target.contains(at)) return false;
  // Image pixel (x, y) covers [x, x+1) x [y, y+1) of the drawn rectangle; its centre is the
  // slice's voxel (w-1-x, h-1-y) (the image is drawn mirrored, see setSlice).
  const double x = (at.x() - target.x()) / target.width() * this->Width - 0.5;
  const double y = (at.y() - target.y()) / target.height() * this->Height - 0.5;
  const double ijk[3] = {this->Width - 1 - x, this->Height - 1 - y, 0};
  this->Shown->TransformContinuousIndexToPhysicalPoint(ijk, ras);
  return true;
}

QPointF qSlicerReposeSliceView::widgetPointOfRas(double r, double a, double s) const {
  const QRectF target = this->imageRect();
  if (target.isEmpty() || !this->Shown) return {-1, -1};
  const double ras[3] = {r, a, s};
  double ijk[3];
  this->Shown->TransformPhysicalPointToContinuousIndex(ras, ijk);
  const double x = this->Width - 1 - ijk[0] + 0.5, y = this->Height - 1 - ijk[1] + 0.5;
  return {target.x() + x / this->Width * target.width(),
          target.y() + y / this->Height * target.height()};
}

void qSlicerReposeSliceView::wheelEvent(QWheelEvent* event) {
  const int steps = event->angleDelta().y() / 120;
  if (steps != 0) emit this->scrolled(steps);
  event->accept();
}

void qSlicerReposeSliceView::setPartsOverlay(vtkImageData* parts,
                                             const QHash<int, QColor>& colors) {
  this->Parts = parts;
  this->PartColors = colors;
}

void qSlicerReposeSliceView::setSlice(vtkImageData* labels, vtkLookupTable* lut,
                                      vtkImageData* image) {
  this->Image = QImage();
  this->Labels.clear();
  this->PartPixels.clear();
  this->OutlinePixels.clear();
  this->Shown = labels;
  this->Width = this->Height = 0;
  vtkDataArray* values = labels ? labels->GetPointData()->GetScalars() : nullptr;
  if (!values) {
    this->update();
    return;
  }
  int dims[3];
  labels->GetDimensions(dims);
  // The Logic's slices are (u, v, 1): u and v the plane's RAS axes, increasing to the patient's
  // right/anterior and anterior/superior. Drawn as Slicer does: patient's right on the screen's
  // left, anterior on the left in sagittal views, superior (anterior in axial views) up.
  const int w = dims[0], h = dims[1];
  double spacing[3];
  labels->GetSpacing(spacing);
  this->AspectMm = spacing[0] > 0 ? spacing[1] / spacing[0] : 1;
  vtkDataArray* grey = image ? image->GetPointData()->GetScalars() : nullptr;
  if (grey && grey->GetNumberOfTuples() != values->GetNumberOfTuples()) grey = nullptr;
  double range[2] = {0, 1};
  if (grey && this->Window > 0) {
    range[0] = this->Level - this->Window / 2;
    range[1] = this->Level + this->Window / 2;
  } else if (grey) {
    grey->GetRange(range);
  }
  const double span = range[1] > range[0] ? range[1] - range[0] : 1;
  this->Image = QImage(w, h, QImage::Format_RGB32);
  this->Labels.assign(std::size_t(w) * std::size_t(h), 0);
  this->Width = w, this->Height = h;
  for (int j = 0; j < h; ++j)
    for (int i = 0; i < w; ++i) {
      const vtkIdType at = vtkIdType(i) + vtkIdType(w) * j;
      const int label = int(values->GetTuple1(at));
      const double g = grey ? std::clamp((grey->GetTuple1(at) - range[0]) / span, 0.0, 1.0) : 0.0;
      double rgb[3] = {g, g, g};
      if (label != 0 && lut) {
        double c[3];
        lut->GetColor(label, c);
        for (int k = 0; k < 3; ++k)
          rgb[k] = (1 - this->LabelOpacity) * rgb[k] + this->LabelOpacity * c[k];
      }
      const int x = w - 1 - i, y = h - 1 - j;
      this->Labels[std::size_t(x) + std::size_t(w) * std::size_t(y)] = label;
      this->Image.setPixel(x, y,
                           qRgb(int(std::lround(255 * std::clamp(rgb[0], 0.0, 1.0))),
                                int(std::lround(255 * std::clamp(rgb[1], 0.0, 1.0))),
                                int(std::lround(255 * std::clamp(rgb[2], 0.0, 1.0)))));
    }
  this->drawPartsOutline();
  this->update();
}

void qSlicerReposeSliceView::drawPartsOutline() {
  vtkDataArray* parts = this->Parts ? this->Parts->GetPointData()->GetScalars() : nullptr;
  const int w = this->Width, h = this->Height;
  if (!parts || parts->GetNumberOfTuples() != vtkIdType(w) * h) return;
  this->PartPixels.assign(std::size_t(w) * std::size_t(h), 0);
  for (int j = 0; j < h; ++j)
    for (int i = 0; i < w; ++i)
      this->PartPixels[std::size_t(w - 1 - i) + std::size_t(w) * std::size_t(h - 1 - j)] =
          int(parts->GetTuple1(vtkIdType(i) + vtkIdType(w) * j));
  // A part's pixel is on its outline where a 4-neighbour is another part or nothing (the slice's
  // edge counts as nothing), so touching parts are each outlined along their border.
  this->OutlinePixels.assign(this->PartPixels.size(), 0);
  auto part = [&](int x, int y) {
    return x < 0 || y < 0 || x >= w || y >= h
               ? 0
               : this->PartPixels[std::size_t(x) + std::size_t(w) * std::size_t(y)];
  };
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const int p = part(x, y);
      if (p == 0) continue;
      if (part(x - 1, y) == p && part(x + 1, y) == p && part(x, y - 1) == p && part(x, y + 1) == p)
        continue;
      this->OutlinePixels[std::size_t(x) + std::size_t(w) * std::size_t(y)] = 1;
      this->Image.setPixel(x, y, this->PartColors.value(p, QColor(Qt::white)).rgb());
    }
}

int qSlicerReposeSliceView::partAt(int x, int y) const {
  if (this->PartPixels.empty() || x < 0 || y < 0 || x >= this->Width || y >= this->Height)
    return -1;
  return this->PartPixels[std::size_t(x) + std::size_t(this->Width) * std::size_t(y)];
}

bool qSlicerReposeSliceView::isPartOutline(int x, int y) const {
  return this->partAt(x, y) > 0 &&
         this->OutlinePixels[std::size_t(x) + std::size_t(this->Width) * std::size_t(y)];
}

int qSlicerReposeSliceView::partAtRas(double r, double a, double s) const {
  int x, y;
  if (!this->pixelOfRas(r, a, s, x, y)) return -1;
  return this->partAt(x, y);
}

bool qSlicerReposeSliceView::pixelOfRas(double r, double a, double s, int& x, int& y) const {
  if (!this->Shown || this->Image.isNull()) return false;
  const double ras[3] = {r, a, s};
  double ijk[3];
  this->Shown->TransformPhysicalPointToContinuousIndex(ras, ijk);
  const int i = int(std::lround(ijk[0])), j = int(std::lround(ijk[1]));
  if (i < 0 || j < 0 || i >= this->Width || j >= this->Height || std::fabs(ijk[2]) > 0.5)
    return false;
  x = this->Width - 1 - i, y = this->Height - 1 - j;
  return true;
}

int qSlicerReposeSliceView::labelAt(int x, int y) const {
  if (x < 0 || y < 0 || x >= this->Width || y >= this->Height) return -1;
  return this->Labels[std::size_t(x) + std::size_t(this->Width) * std::size_t(y)];
}

int qSlicerReposeSliceView::labelAtRas(double r, double a, double s) const {
  int x, y;
  if (!this->pixelOfRas(r, a, s, x, y)) return -1;
  return this->labelAt(x, y);
}

int qSlicerReposeSliceView::labelsShown() const {
  std::set<int> shown(this->Labels.begin(), this->Labels.end());
  shown.erase(0);
  return int(shown.size());
}

void qSlicerReposeSliceView::paintEvent(QPaintEvent*) {
  QPainter painter(this);
  painter.fillRect(this->rect(), Qt::black);
  const int bar = BarHeight;
  painter.fillRect(QRect(0, 0, this->width(), bar), this->viewColor());
  painter.setPen(Qt::black);
  painter.drawText(QRect(6, 0, this->width() - 12, bar), Qt::AlignVCenter | Qt::AlignLeft,
                   QString("%1  %2  %3 mm")
                       .arg(this->viewName(), this->orientationName())
                       .arg(this->PositionMm, 0, 'f', 1));
  if (this->Image.isNull()) {
    painter.setPen(Qt::gray);
    painter.drawText(this->rect().adjusted(0, bar, 0, 0), Qt::AlignCenter, "no live pose");
    return;
  }
  const QRectF target = this->imageRect();
  painter.setRenderHint(QPainter::SmoothPixmapTransform, false);  // labels stay crisp
  painter.drawImage(target, this->Image);
  painter.setPen(this->viewColor());
  painter.drawRect(target);
}
