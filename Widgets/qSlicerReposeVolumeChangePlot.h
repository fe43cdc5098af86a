// qSlicerReposeVolumeChangePlot: the last export's per-label volume changes as horizontal bars
// (the labels that changed most first, beyond resampling as the quality check counts them), with
// the +-1 % target drawn as two lines: a bar past a line is a label that missed it. Pure Qt
// painting, so it draws the same on screen and under the offscreen platform.
#pragma once

#include "qSlicerReposeModuleWidgetsExport.h"

#include <QString>
#include <QWidget>

#include <utility>
#include <vector>

class QSLICER_REPOSE_MODULE_WIDGETS_EXPORT qSlicerReposeVolumeChangePlot : public QWidget {
  Q_OBJECT
 public:
  explicit qSlicerReposeVolumeChangePlot(QWidget* parent = nullptr);

  // (label text, change in %), largest first; the plot keeps the first `maxBars`.
  void setChanges(const std::vector<std::pair<QString, double>>& changes);
  int barCount() const { return int(this->Changes.size()); }
  static constexpr int maxBars = 12;

  QSize sizeHint() const override;

 protected:
  void paintEvent(QPaintEvent* event) override;

 private:
  std::vector<std::pair<QString, double>> Changes;
};
