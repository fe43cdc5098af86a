// The bars are scaled to the larger of the largest change and twice the target, so the target
// lines stay in view and a label far past them still fits.
#include "qSlicerReposeVolumeChangePlot.h"

#include <QPainter>

#include <algorithm>
#include <cmath>

namespace {
constexpr double kTargetPercent = 1.0;  // docs/QUALITY.md: every label within +-1 %
constexpr int kRow = 16;
}  // namespace

qSlicerReposeVolumeChangePlot::qSlicerReposeVolumeChangePlot(QWidget* parent) : QWidget(parent) {
  this->setObjectName("VolumeChangePlot");
  this->setToolTip("Volume change per label beyond resampling; the lines are the +-1 % target");
}

void qSlicerReposeVolumeChangePlot::setChanges(
    const std::vector<std::pair<QString, double>>& changes) {
  this->Changes.assign(changes.begin(),
                       changes.begin() + std::min<std::ptrdiff_t>(maxBars, changes.size()));
  this->setMinimumHeight(this->sizeHint().height());
  this->updateGeometry();
  this->update();
}

QSize qSlicerReposeVolumeChangePlot::sizeHint() const {
  return {260, kRow * (int(this->Changes.size()) + 1) + 4};
}

void qSlicerReposeVolumeChangePlot::paintEvent(QPaintEvent*) {
  QPainter painter(this);
  painter.fillRect(this->rect(), this->palette().base());
  if (this->Changes.empty()) return;
  const QFontMetrics metrics = painter.fontMetrics();
  int nameWidth = 0;
  for (const auto& [name, change] : this->Changes)
    nameWidth = std::max(nameWidth, metrics.horizontalAdvance(name));
  nameWidth = std::min(nameWidth + 6, this->width() / 2);
  const int valueWidth = metrics.horizontalAdvance("+99.99 %") + 4;
  const int left = nameWidth, right = this->width() - valueWidth;
  const int centre = (left + right) / 2;
  double scale = 2 * kTargetPercent;
  for (const auto& [name, change] : this->Changes) scale = std::max(scale, std::fabs(change));
  const double pixelsPerPercent = (right - left) / 2.0 / scale;
  for (std::size_t i = 0; i < this->Changes.size(); ++i) {
    const auto& [name, change] = this->Changes[i];
    const int y = 2 + int(i) * kRow;
    painter.setPen(this->palette().text().color());
    painter.drawText(QRect(0, y, nameWidth - 4, kRow), Qt::AlignRight | Qt::AlignVCenter,
                     metrics.elidedText(name, Qt::ElideRight, nameWidth - 4));
    const int length = int(std::lround(change * pixelsPerPercent));
    const QRect bar = length >= 0 ? QRect(centre, y + 3, length, kRow - 6)
                                  : QRect(centre + length, y + 3, -length, kRow - 6);
    painter.fillRect(
        bar, std::fabs(change) <= kTargetPercent ? QColor(80, 160, 90) : QColor(200, 60, 50));
    painter.drawText(QRect(right + 4, y, valueWidth, kRow), Qt::AlignLeft | Qt::AlignVCenter,
                     QString("%1%2 %").arg(change >= 0 ? "+" : "").arg(change, 0, 'f', 2));
  }
  const int bottom = 2 + int(this->Changes.size()) * kRow;
  painter.setPen(QPen(this->palette().text().color(), 1, Qt::DashLine));
  for (const double t : {-kTargetPercent, kTargetPercent}) {
    const int x = centre + int(std::lround(t * pixelsPerPercent));
    painter.drawLine(x, 0, x, bottom);
  }
  painter.setPen(this->palette().mid().color());
  painter.drawLine(centre, 0, centre, bottom);
  painter.drawText(QRect(left, bottom, right - left, kRow), Qt::AlignCenter,
                   QString("volume change per label (target ±%1 %)").arg(kTargetPercent));
}
