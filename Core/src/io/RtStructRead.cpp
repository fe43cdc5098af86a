// RT Structure Set in: the ROIs and their contours read from the dataset (dcmdata), each ROI
// rasterized slice by slice with an even-odd scanline fill at voxel centres, and overlapping ROIs
// put in layers.
#include "repose/io/RtStructIO.h"

#include "repose/io/DicomSeriesIO.h"
#include "repose/util/Error.h"

#include "DcmtkCommon.h"
#include "DicomScreen.h"
#include "ReaderCommon.h"

// clang-format off
#include <dcmtk/config/osconfig.h>  // first, as DCMTK requires
// clang-format on
#include <dcmtk/dcmdata/dcdeftag.h>
#include <dcmtk/dcmdata/dcfilefo.h>

#include "DcmtkAttributes.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <set>

namespace repose {
namespace {

using Vec3 = Eigen::Vector3d;
using io::dicomInteger;
using io::dicomItem;
using io::dicomNumbers;
using io::dicomText;

struct Contour {
  std::vector<Vec3> points;  // LPS mm
};

struct Roi {
  int number = 0;
  Label label;
  std::vector<Contour> contours;
};

// The unit normal of a closed polygon (Newell's method); zero when it is degenerate.
Vec3 normalOf(const std::vector<Vec3>& p) {
  Vec3 n = Vec3::Zero();
  for (std::size_t i = 0; i < p.size(); ++i) {
    const Vec3& a = p[i];
    const Vec3& b = p[(i + 1) % p.size()];
    n += Vec3((a.y() - b.y()) * (a.z() + b.z()), (a.z() - b.z()) * (a.x() + b.x()),
              (a.x() - b.x()) * (a.y() + b.y()));
  }
  return n.norm() > 1e-12 ? Vec3(n.normalized()) : Vec3(Vec3::Zero());
}

// The grid spanning every contour point: voxels of `spacing` mm, rows and columns in the
// contours' plane, slices along its normal from the lowest contour plane.
VolumeGeometry spanningGrid(const std::string& path, const std::vector<Roi>& rois, double spacing) {
  Vec3 normal = Vec3::Zero();
  for (const Roi& r : rois)
    for (const Contour& c : r.contours)
      if (normal.isZero()) normal = normalOf(c.points);
  if (normal.isZero()) throwFileError(path, "no closed contour to span a grid with");
  int largest = 0;
  normal.cwiseAbs().maxCoeff(&largest);
  if (normal[largest] < 0) normal = -normal;
  // In-plane axes: patient x (LPS) projected on the plane, unless the plane is nearly across it.
  Vec3 u = Vec3::UnitX() - normal * normal.x();
  if (u.norm() < 0.1) u = Vec3::UnitY() - normal * normal.y();
  u.normalize();
  const Vec3 v = normal.cross(u);
  Vec3 lo = Vec3::Constant(1e300), hi = Vec3::Constant(-1e300);
  for (const Roi& r : rois)
    for (const Contour& c : r.contours)
      for (const Vec3& p : c.points) {
        const Vec3 q(p.dot(u), p.dot(v), p.dot(normal));
        lo = lo.cwiseMin(q);
        hi = hi.cwiseMax(q);
      }
  const Vec3 extent = (hi - lo) / spacing;
  if (extent.maxCoeff() > 1e5)
    throwFileError(path, "contours span " + std::to_string((hi - lo).maxCoeff()) +
                             " mm: over 100000 voxels of " + std::to_string(spacing) + " mm");
  VolumeGeometry g;
  // Half a voxel of margin in the plane, so boundary voxels' centres are not on the grid's edge.
  g.dims = {static_cast<std::int64_t>(std::ceil(extent.x())) + 2,
            static_cast<std::int64_t>(std::ceil(extent.y())) + 2,
            static_cast<std::int64_t>(std::llround(extent.z())) + 1};
  Eigen::Matrix4d lps = Eigen::Matrix4d::Identity();
  lps.block<3, 1>(0, 0) = u * spacing;
  lps.block<3, 1>(0, 1) = v * spacing;
  lps.block<3, 1>(0, 2) = normal * spacing;
  lps.block<3, 1>(0, 3) =
      u * (lo.x() - 0.5 * spacing) + v * (lo.y() - 0.5 * spacing) + normal * lo.z();
  g.ijkToRas = flipLpsRas(lps);
  g.validate(path);
  return g;
}

// The integer index at or above (ceil) or below (floor) x, clamped to [lo, hi] before the
// conversion: a contour far off the grid must not overflow an integer (undefined behaviour).
std::int64_t clampedCeil(double x, std::int64_t lo, std::int64_t hi) {
  if (std::isnan(x)) return lo;
  return static_cast<std::int64_t>(std::clamp(std::ceil(x), double(lo), double(hi)));
}
std::int64_t clampedFloor(double x, std::int64_t lo, std::int64_t hi) {
  if (std::isnan(x)) return lo;
  return static_cast<std::int64_t>(std::clamp(std::floor(x), double(lo), double(hi)));
}

// A run of voxels of one row: [start, start + length) in volume index order.
struct Run {
  std::int64_t start;
  std::int64_t length;
};

// The ROI's voxels on `grid`, as runs.
std::vector<Run> rasterize(const std::string& path, const Roi& roi, const VolumeGeometry& grid,
                           double planeGap) {
  std::vector<Run> runs;
  if (roi.contours.empty()) return runs;
  const Eigen::Matrix4d lpsToRas = flipLpsRas(Eigen::Matrix4d::Identity());
  const Eigen::Matrix3d flip = lpsToRas.block<3, 3>(0, 0);
  const Vec3 kAxis = grid.directions().col(2);
  const double kStep = grid.spacing()[2];
  // Each contour in voxel coordinates, with its slice position (continuous k).
  struct Polygon {
    std::vector<Eigen::Vector2d> points;
    double k;
  };
  std::vector<Polygon> polygons;
  for (std::size_t c = 0; c < roi.contours.size(); ++c) {
    const Contour& contour = roi.contours[c];
    Polygon poly;
    double kMin = 1e300, kMax = -1e300;
    for (const Vec3& p : contour.points) {
      const Vec3 ijk = grid.rasToVoxel(flip * p);
      poly.points.emplace_back(ijk.x(), ijk.y());
      kMin = std::min(kMin, ijk.z());
      kMax = std::max(kMax, ijk.z());
    }
    const Vec3 n = normalOf(contour.points);
    if (kMax - kMin > 0.01 ||
        (!n.isZero() && std::fabs(std::fabs((flip * n).dot(kAxis)) - 1) > 1e-3))
      throwFileError(path, "ROI '" + roi.label.name + "' contour " + std::to_string(c + 1) +
                               " is not in a plane of the grid's slices");
    poly.k = 0.5 * (kMin + kMax);
    polygons.push_back(std::move(poly));
  }
  // The contour planes of this ROI, and each slice's nearest one within half the plane gap.
  std::vector<double> planes;
  for (const Polygon& p : polygons) planes.push_back(p.k);
  std::sort(planes.begin(), planes.end());
  planes.erase(std::unique(planes.begin(), planes.end(),
                           [](double a, double b) { return std::fabs(a - b) < 1e-3; }),
               planes.end());
  const double reach = 0.5 * planeGap / kStep + 1e-6;  // in slices
  const std::int64_t d0 = grid.dims[0], d1 = grid.dims[1];
  std::vector<double> crossings;
  for (std::int64_t k = clampedFloor(planes.front() - reach, 0, grid.dims[2]);
       k < grid.dims[2] && double(k) <= planes.back() + reach; ++k) {
    const auto nearest = std::min_element(planes.begin(), planes.end(), [&](double a, double b) {
      return std::fabs(a - double(k)) < std::fabs(b - double(k));
    });
    if (std::fabs(*nearest - double(k)) > reach) continue;
    std::vector<const Polygon*> onPlane;
    double yMin = 1e300, yMax = -1e300;
    for (const Polygon& p : polygons)
      if (std::fabs(p.k - *nearest) < 1e-3) {
        onPlane.push_back(&p);
        for (const auto& q : p.points) {
          yMin = std::min(yMin, q.y());
          yMax = std::max(yMax, q.y());
        }
      }
    for (std::int64_t j = clampedCeil(yMin, 0, d1); j < d1 && double(j) <= yMax; ++j) {
      // Even-odd: every edge that crosses the row's centre line toggles inside and outside; a
      // vertex exactly on the line counts for the edge above it only (half-open).
      crossings.clear();
      const double y = double(j);
      for (const Polygon* p : onPlane) {
        const auto& pts = p->points;
        for (std::size_t a = 0, b = pts.size() - 1; a < pts.size(); b = a++) {
          const auto& pa = pts[a];
          const auto& pb = pts[b];
          if ((pa.y() <= y) != (pb.y() <= y))
            crossings.push_back(pa.x() + (y - pa.y()) * (pb.x() - pa.x()) / (pb.y() - pa.y()));
        }
      }
      std::sort(crossings.begin(), crossings.end());
      for (std::size_t c = 0; c + 1 < crossings.size(); c += 2) {
        const std::int64_t i0 = clampedCeil(crossings[c], 0, d0);
        const std::int64_t i1 = clampedCeil(crossings[c + 1], 0, d0);
        if (i1 > i0) runs.push_back({i0 + d0 * (j + d1 * k), i1 - i0});
      }
    }
  }
  return runs;
}

}  // namespace

bool isRtStructFile(const std::string& path) {
  return io::dicomSopClassOf(path) == io::kRtStructureSetStorageUid;
}

Volume readRtStruct(const std::string& path, const RtStructOptions& options) {
  DcmFileFormat file;
  DcmDataset* ds =
      &io::loadDicomOfClass(file, path, io::kRtStructureSetStorageUid, "an RT Structure Set");

  // ROIs by number, in the order of StructureSetROISequence.
  DcmSequenceOfItems* roiItems = nullptr;
  if (ds->findAndGetSequence(DCM_StructureSetROISequence, roiItems).bad() || !roiItems)
    throwFileError(path, "no StructureSetROISequence");
  std::vector<Roi> rois;
  std::map<long, std::size_t> byNumber;
  for (unsigned long r = 0; r < roiItems->card(); ++r) {
    DcmItem* item = roiItems->getItem(r);
    const long number = dicomInteger(item, DCM_ROINumber, -1);
    if (number < 0) throwFileError(path, "ROI " + std::to_string(r + 1) + " has no ROI Number");
    if (byNumber.count(number)) throwFileError(path, "two ROIs numbered " + std::to_string(number));
    Roi roi;
    roi.number = int(number);
    roi.label.name = dicomText(item, DCM_ROIName);
    if (roi.label.name.empty()) roi.label.name = "ROI " + std::to_string(number);
    byNumber[number] = rois.size();
    rois.push_back(std::move(roi));
  }
  if (rois.empty()) throwFileError(path, "the structure set has no ROI");

  // Contours and colours.
  DcmSequenceOfItems* contourItems = nullptr;
  ds->findAndGetSequence(DCM_ROIContourSequence, contourItems);
  std::set<long> coloured;
  std::int64_t skipped = 0;
  for (unsigned long r = 0; contourItems && r < contourItems->card(); ++r) {
    DcmItem* item = contourItems->getItem(r);
    const long number = dicomInteger(item, DCM_ReferencedROINumber, -1);
    const auto it = byNumber.find(number);
    if (it == byNumber.end())
      throwFileError(path, "ROI contour " + std::to_string(r + 1) + " names ROI " +
                               std::to_string(number) +
                               ", which the structure set does not define");
    Roi& roi = rois[it->second];
    const std::vector<double> colour = dicomNumbers(item, DCM_ROIDisplayColor);
    if (colour.size() == 3) {
      for (int c = 0; c < 3; ++c)
        roi.label.color[std::size_t(c)] = std::clamp(colour[std::size_t(c)] / 255.0, 0.0, 1.0);
      coloured.insert(number);
    }
    DcmSequenceOfItems* contours = nullptr;
    if (item->findAndGetSequence(DCM_ContourSequence, contours).bad() || !contours) continue;
    for (unsigned long c = 0; c < contours->card(); ++c) {
      DcmItem* contour = contours->getItem(c);
      const std::string where = "ROI '" + roi.label.name + "' contour " + std::to_string(c + 1);
      const std::string type = dicomText(contour, DCM_ContourGeometricType);
      if (type != "CLOSED_PLANAR") {  // points and open lines enclose nothing
        ++skipped;
        continue;
      }
      const std::vector<double> data = dicomNumbers(contour, DCM_ContourData);
      const long declared = dicomInteger(contour, DCM_NumberOfContourPoints, -1);
      if (data.size() % 3 != 0 || (declared >= 0 && std::size_t(declared) * 3 != data.size()))
        throwFileError(path, where + ": ContourData holds " + std::to_string(data.size()) +
                                 " numbers for " + std::to_string(declared) + " points");
      if (data.size() < 9)
        throwFileError(path, where + " has " + std::to_string(data.size() / 3) +
                                 " points (a closed contour needs at least 3)");
      Contour out;
      for (std::size_t p = 0; p + 2 < data.size(); p += 3)
        out.points.emplace_back(data[p], data[p + 1], data[p + 2]);
      roi.contours.push_back(std::move(out));
    }
  }
  for (Roi& roi : rois)
    if (!coloured.count(roi.number)) {
      roi.label.color = LabelTable::defaultColor(roi.number, roi.label.name);
      roi.label.colorGenerated = true;
    }
  if (skipped && options.note)
    options.note(path + ": " + std::to_string(skipped) +
                 " contours that are not CLOSED_PLANAR (points, open lines) enclose no voxel and "
                 "are left out");

  // The grid.
  VolumeGeometry grid;
  if (!options.reference.empty()) {
    const std::string series =
        dicomText(dicomItem(dicomItem(dicomItem(ds, DCM_ReferencedFrameOfReferenceSequence),
                                      DCM_RTReferencedStudySequence),
                            DCM_RTReferencedSeriesSequence),
                  DCM_SeriesInstanceUID);
    std::error_code ec;
    if (std::filesystem::is_directory(options.reference, ec) && !series.empty()) {
      const auto g = findDicomSeriesGeometry(options.reference, series);
      if (!g)
        throwFileError(path, "references series " + series + ", which " + options.reference +
                                 " does not hold");
      grid = *g;
    } else {
      ReadOptions r;
      r.memoryLimitBytes = options.memoryLimitBytes;
      grid = readVolume(options.reference, r).geometry();
    }
  } else {
    if (!(options.spacingMm > 0))
      throwFileError(path, "a structure set needs a reference image or a voxel size");
    grid = spanningGrid(path, rois, options.spacingMm);
  }

  // The distance between contour planes (all ROIs): how far a plane's contours reach.
  const Vec3 kAxis =
      flipLpsRas(Eigen::Matrix4d::Identity()).block<3, 3>(0, 0) * grid.directions().col(2);
  std::vector<double> along;
  for (const Roi& r : rois)
    for (const Contour& c : r.contours) along.push_back(c.points.front().dot(kAxis));
  std::sort(along.begin(), along.end());
  double planeGap = 0;
  for (std::size_t a = 1; a < along.size(); ++a)
    if (along[a] - along[a - 1] > 1e-3 && (planeGap == 0 || along[a] - along[a - 1] < planeGap))
      planeGap = along[a] - along[a - 1];
  if (planeGap == 0) planeGap = grid.spacing()[2];

  // Values: the ROI numbers when they fit, else positions.
  bool numbersFit = true;
  for (const Roi& r : rois) numbersFit = numbersFit && r.number >= 1 && r.number <= 65535;
  for (std::size_t r = 0; r < rois.size(); ++r)
    rois[r].label.value = numbersFit ? rois[r].number : int(r + 1);
  int maxValue = 0;
  for (const Roi& r : rois) maxValue = std::max(maxValue, r.label.value);
  const ScalarType scalar = maxValue <= 255 ? ScalarType::UInt8 : ScalarType::UInt16;
  const std::int64_t voxels = grid.numVoxels();
  ReadOptions budget;
  budget.memoryLimitBytes = options.memoryLimitBytes;
  io::checkReadMemory(path, voxels, double(scalarSize(scalar)) + 0.125, budget);

  // Rasterize; each ROI in the first layer where it overlaps none before it.
  std::vector<std::vector<std::uint64_t>> occupied;
  std::vector<std::vector<Run>> runsOf(rois.size());
  for (std::size_t r = 0; r < rois.size(); ++r) {
    runsOf[r] = rasterize(path, rois[r], grid, planeGap);
    auto clashes = [&](const std::vector<std::uint64_t>& bits) {
      for (const Run& run : runsOf[r])
        for (std::int64_t v = run.start; v < run.start + run.length; ++v)
          if ((bits[std::size_t(v >> 6)] >> (v & 63)) & 1) return true;
      return false;
    };
    int layer = 0;
    while (layer < int(occupied.size()) && clashes(occupied[std::size_t(layer)])) ++layer;
    if (layer == int(occupied.size())) {
      io::checkReadMemory(path, voxels, (double(scalarSize(scalar)) + 0.125) * double(layer + 1),
                          budget);
      occupied.emplace_back(std::size_t((voxels + 63) / 64), 0);
    }
    for (const Run& run : runsOf[r])
      for (std::int64_t v = run.start; v < run.start + run.length; ++v)
        occupied[std::size_t(layer)][std::size_t(v >> 6)] |= std::uint64_t(1) << (v & 63);
    rois[r].label.layer = layer;
    reportProgress(options.progress, 0.9 * double(r + 1) / double(rois.size()),
                   "rasterizing contours");
  }
  Volume volume(grid, scalar, std::max<int>(1, int(occupied.size())));
  occupied.clear();
  for (std::size_t r = 0; r < rois.size(); ++r) {
    const Label& l = rois[r].label;
    for (const Run& run : runsOf[r]) {
      if (scalar == ScalarType::UInt8)
        std::fill_n(volume.data<std::uint8_t>(l.layer) + run.start, run.length,
                    std::uint8_t(l.value));
      else
        std::fill_n(volume.data<std::uint16_t>(l.layer) + run.start, run.length,
                    std::uint16_t(l.value));
    }
    volume.labels().set(l);
  }
  volume.setLabelMap(true);
  reportProgress(options.progress, 1.0, "rasterizing contours");
  return volume;
}

}  // namespace repose
