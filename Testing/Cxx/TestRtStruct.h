// Small DICOM RT Structure Sets written attribute by attribute with DCMTK's dcmdata, for the
// tests of the RTSTRUCT reader (and the seed of its fuzz target).
#pragma once

// clang-format off
#include <dcmtk/config/osconfig.h>
// clang-format on
#include <dcmtk/dcmdata/dcdeftag.h>
#include <dcmtk/dcmdata/dcfilefo.h>
#include <dcmtk/dcmdata/dcuid.h>

#include <array>
#include <cstdio>
#include <string>
#include <vector>

namespace repose::test {

struct TinyContour {
  std::vector<std::array<double, 3>> points;  // LPS mm
  std::string type = "CLOSED_PLANAR";
  int declaredPoints = -1;  // NumberOfContourPoints when not the real count
};

struct TinyRoi {
  int number = 1;
  int referencedNumber = -1;  // the ROI contour's ReferencedROINumber when not `number`
  std::string name;
  std::array<int, 3> color{255, 0, 0};
  std::vector<TinyContour> contours;
};

// An axis-aligned square contour on plane z (LPS), corners (x0, y0) and (x1, y1).
inline TinyContour square(double x0, double y0, double x1, double y1, double z) {
  return {{{x0, y0, z}, {x1, y0, z}, {x1, y1, z}, {x0, y1, z}}};
}

inline void writeTinyRtStruct(const std::vector<TinyRoi>& rois, const std::string& path,
                              const std::string& referencedSeries = "") {
  DcmFileFormat file;
  DcmDataset* d = file.getDataset();
  d->putAndInsertString(DCM_SOPClassUID, UID_RTStructureSetStorage);
  d->putAndInsertString(DCM_SOPInstanceUID, "1.2.826.0.1.3680043.2.1125.2");
  d->putAndInsertString(DCM_Modality, "RTSTRUCT");
  d->putAndInsertString(DCM_StructureSetLabel, "TEST");
  if (!referencedSeries.empty()) {
    DcmItem *frame = nullptr, *study = nullptr, *series = nullptr;
    d->findOrCreateSequenceItem(DCM_ReferencedFrameOfReferenceSequence, frame, 0);
    frame->findOrCreateSequenceItem(DCM_RTReferencedStudySequence, study, 0);
    study->findOrCreateSequenceItem(DCM_RTReferencedSeriesSequence, series, 0);
    series->putAndInsertString(DCM_SeriesInstanceUID, referencedSeries.c_str());
  }
  for (std::size_t r = 0; r < rois.size(); ++r) {
    const TinyRoi& roi = rois[r];
    DcmItem* item = nullptr;
    d->findOrCreateSequenceItem(DCM_StructureSetROISequence, item, long(r));
    item->putAndInsertString(DCM_ROINumber, std::to_string(roi.number).c_str());
    item->putAndInsertString(DCM_ROIName, roi.name.c_str());
    DcmItem* contourItem = nullptr;
    d->findOrCreateSequenceItem(DCM_ROIContourSequence, contourItem, long(r));
    contourItem->putAndInsertString(
        DCM_ReferencedROINumber,
        std::to_string(roi.referencedNumber >= 0 ? roi.referencedNumber : roi.number).c_str());
    const std::string colour = std::to_string(roi.color[0]) + "\\" + std::to_string(roi.color[1]) +
                               "\\" + std::to_string(roi.color[2]);
    contourItem->putAndInsertString(DCM_ROIDisplayColor, colour.c_str());
    for (std::size_t c = 0; c < roi.contours.size(); ++c) {
      const TinyContour& contour = roi.contours[c];
      DcmItem* ci = nullptr;
      contourItem->findOrCreateSequenceItem(DCM_ContourSequence, ci, long(c));
      ci->putAndInsertString(DCM_ContourGeometricType, contour.type.c_str());
      const int n =
          contour.declaredPoints >= 0 ? contour.declaredPoints : int(contour.points.size());
      ci->putAndInsertString(DCM_NumberOfContourPoints, std::to_string(n).c_str());
      std::string data;
      for (const auto& p : contour.points)
        for (double v : p) {
          char b[32];
          std::snprintf(b, sizeof b, "%.6g", v);
          data += (data.empty() ? "" : "\\") + std::string(b);
        }
      ci->putAndInsertString(DCM_ContourData, data.c_str());
    }
  }
  file.saveFile(path.c_str(), EXS_LittleEndianExplicit);
}

}  // namespace repose::test
