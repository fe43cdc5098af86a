// DICOM SEG in: DCMTK parses the file (dcmdata); the segments, frames and geometry are read from
// the dataset here, and the packed bits are unpacked here too, since DCMTK 3.6.7's dcmseg
// unpacks frames whose size is not a multiple of 8 wrongly, leaks the object when a read fails
// and indexes past its frames when a file declares none (found reading its source).
#include "repose/io/DicomSegIO.h"

#include "repose/io/DicomSeriesIO.h"
#include "repose/util/Error.h"
#include "repose/volume/SegmentTerminology.h"

#include "DcmtkCommon.h"
#include "DicomScreen.h"
#include "DicomSegPrivate.h"
#include "ReaderCommon.h"

// clang-format off
#include <dcmtk/config/osconfig.h>  // first, as DCMTK requires
// clang-format on
#include <dcmtk/dcmdata/dcdeftag.h>
#include <dcmtk/dcmdata/dcfilefo.h>
#include <dcmtk/dcmdata/dcitem.h>
#include <dcmtk/dcmdata/dcxfer.h>
#include <dcmtk/dcmiod/cielabutil.h>

#include "DcmtkAttributes.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <set>
#include <type_traits>

namespace repose {
namespace {

using Vec3 = Eigen::Vector3d;

using io::dicomInteger;
using io::dicomItem;
using io::dicomNumbers;
using io::dicomText;

// A functional group macro of a frame: its own, else the shared one.
DcmItem* groupOf(DcmItem* perFrame, DcmItem* shared, const DcmTagKey& macro) {
  if (DcmItem* g = dicomItem(perFrame, macro)) return g;
  return dicomItem(shared, macro);
}

TerminologyCode codeOf(DcmItem* parent, const DcmTagKey& sequence) {
  DcmItem* c = dicomItem(parent, sequence);
  if (!c) return {};
  TerminologyCode code{dicomText(c, DCM_CodingSchemeDesignator), dicomText(c, DCM_CodeValue),
                       dicomText(c, DCM_CodeMeaning)};
  if (code.value.empty()) code.value = dicomText(c, DCM_LongCodeValue);
  if (code.value.empty()) code.value = dicomText(c, DCM_URNCodeValue);
  return code;
}

// The segment's colour from RecommendedDisplayCIELabValue (DICOM's scaled CIELab, PS3.3
// C.10.7.1.1), clamped to the RGB cube; nothing when the segment has none.
std::optional<std::array<double, 3>> colourOf(DcmItem* segment) {
  Uint16 lab[3];
  for (unsigned long i = 0; i < 3; ++i)
    if (segment->findAndGetUint16(DCM_RecommendedDisplayCIELabValue, lab[i], i).bad())
      return std::nullopt;
  double r = 0, g = 0, b = 0;
  IODCIELabUtil::dicomLab2RGB(r, g, b, lab[0], lab[1], lab[2]);
  std::array<double, 3> rgb{r, g, b};
  for (double& c : rgb) c = std::clamp(std::isfinite(c) ? c : 0.0, 0.0, 1.0);
  return rgb;
}

struct Segment {
  int number = 0;
  Label label;              // label.value: the voxels' value
  int preferredLayer = -1;  // Repose's private block: the layer it had
  std::vector<long> frames;
};

// What the frames say about their plane: orientation (LPS unit vectors), spacing, position.
struct FramePlane {
  Vec3 rowDir, colDir;    // along a row (columns increase), along a column (rows increase)
  double rowStep = 0;     // mm between rows (PixelSpacing[0])
  double columnStep = 0;  // mm between columns (PixelSpacing[1])
  double sliceSpacing = 0, thickness = 0;
};

// Where each frame goes in the output grid: column, row and slice of its first pixel.
struct Placement {
  std::int64_t i0 = 0, j0 = 0, k = 0;
};

// The frames placed on `grid` (RAS), or nothing when they do not all fall on it: same axes and
// spacing, whole-voxel offsets, inside.
std::optional<std::vector<Placement>> placeFrames(const VolumeGeometry& grid,
                                                  const FramePlane& plane,
                                                  const std::vector<Vec3>& positions,
                                                  std::int64_t rows, std::int64_t columns) {
  const Eigen::Matrix4d lpsToRas = flipLpsRas(Eigen::Matrix4d::Identity());
  const Eigen::Matrix3d flip = lpsToRas.block<3, 3>(0, 0);
  const Vec3 iAxis = flip * plane.rowDir * plane.columnStep;
  const Vec3 jAxis = flip * plane.colDir * plane.rowStep;
  const double tolerance = 1e-3 * std::min(plane.rowStep, plane.columnStep);
  if ((grid.ijkToRas.block<3, 1>(0, 0) - iAxis).norm() > tolerance ||
      (grid.ijkToRas.block<3, 1>(0, 1) - jAxis).norm() > tolerance)
    return std::nullopt;
  std::vector<Placement> out;
  out.reserve(positions.size());
  for (const Vec3& p : positions) {
    const Vec3 v = grid.rasToVoxel(flip * p);
    Placement at;
    std::int64_t* c[3] = {&at.i0, &at.j0, &at.k};
    for (int a = 0; a < 3; ++a) {
      const double r = std::round(v[a]);
      if (std::fabs(v[a] - r) > 0.05 || std::fabs(r) > 1e9) return std::nullopt;
      *c[a] = static_cast<std::int64_t>(r);
    }
    if (at.i0 < 0 || at.j0 < 0 || at.k < 0 || at.i0 + columns > grid.dims[0] ||
        at.j0 + rows > grid.dims[1] || at.k >= grid.dims[2])
      return std::nullopt;
    out.push_back(at);
  }
  return out;
}

// The grid the frames span: their plane's rows and columns, and slices from the lowest frame to
// the highest along the normal, SpacingBetweenSlices apart (else the smallest gap between them).
VolumeGeometry ownGrid(const std::string& path, const FramePlane& plane,
                       const std::vector<Vec3>& positions, std::int64_t rows,
                       std::int64_t columns) {
  const Vec3 normal = plane.rowDir.cross(plane.colDir);
  std::vector<double> along;
  for (const Vec3& p : positions) along.push_back(p.dot(normal));
  const auto lowest = std::min_element(along.begin(), along.end()) - along.begin();
  std::vector<double> levels = along;
  std::sort(levels.begin(), levels.end());
  const double merge = 1e-3 + 1e-4 * std::min(plane.rowStep, plane.columnStep);
  levels.erase(std::unique(levels.begin(), levels.end(),
                           [&](double a, double b) { return std::fabs(a - b) < merge; }),
               levels.end());
  double step = plane.sliceSpacing;
  if (!(step > 0)) {
    step = levels.size() > 1 ? levels[1] - levels[0] : 0;
    for (std::size_t s = 2; s < levels.size(); ++s)
      step = std::min(step, levels[s] - levels[s - 1]);
    if (!(step > 0)) step = plane.thickness > 0 ? plane.thickness : 1.0;
  }
  const double span = (levels.back() - levels.front()) / step;
  if (span > 1e6)
    throwFileError(path, "frames span " + std::to_string(levels.back() - levels.front()) +
                             " mm at a slice spacing of " + std::to_string(step) +
                             " mm: more than a million slices");
  VolumeGeometry g;
  g.dims = {columns, rows, static_cast<std::int64_t>(std::llround(span)) + 1};
  Eigen::Matrix4d lps = Eigen::Matrix4d::Identity();
  lps.block<3, 1>(0, 0) = plane.rowDir * plane.columnStep;
  lps.block<3, 1>(0, 1) = plane.colDir * plane.rowStep;
  lps.block<3, 1>(0, 2) = normal * step;
  lps.block<3, 1>(0, 3) = positions[lowest];
  g.ijkToRas = flipLpsRas(lps);
  g.validate(path);
  return g;
}

// The grid of the series the SEG references, when that series is in the SEG's folder or one of
// its subfolders (where dcmqi's examples and PACS exports keep it).
std::optional<VolumeGeometry> referencedGrid(const std::string& path, const std::string& seriesUid,
                                             const ReadOptions& options) {
  namespace fs = std::filesystem;
  if (seriesUid.empty()) return std::nullopt;
  const fs::path folder =
      fs::path(path).parent_path().empty() ? fs::path(".") : fs::path(path).parent_path();
  std::vector<fs::path> candidates{folder};
  std::error_code ec;
  std::vector<fs::path> subfolders;
  for (fs::directory_iterator it(folder, ec), end; !ec && it != end; it.increment(ec))
    if (it->is_directory(ec)) subfolders.push_back(it->path());
  std::sort(subfolders.begin(), subfolders.end());
  candidates.insert(candidates.end(), subfolders.begin(), subfolders.end());
  for (const fs::path& f : candidates) {
    try {
      if (auto g = findDicomSeriesGeometry(f.string(), seriesUid)) {
        if (options.note)
          options.note(path + ": placed on the grid of its referenced series in " + f.string());
        return g;
      }
    } catch (const Error& e) {
      if (options.note)
        options.note(path + ": its referenced series cannot give the grid (" + e.what() +
                     "); the frames' own grid is used");
      return std::nullopt;
    }
  }
  return std::nullopt;
}

// Calls fn(p) for each pixel p (row-major in the frame) that belongs to the segment.
template <class Fn>
void forEachSetPixel(const Uint8* pixels, bool fractional, long maxValue, long frame,
                     std::int64_t framePixels, Fn&& fn) {
  if (fractional) {
    const Uint8* f = pixels + frame * framePixels;
    for (std::int64_t p = 0; p < framePixels; ++p)
      if (2 * long(f[p]) >= maxValue && f[p] != 0) fn(p);
    return;
  }
  const std::int64_t base = frame * framePixels;  // frames are packed with no padding between
  for (std::int64_t p = 0; p < framePixels;) {
    const std::int64_t bit = base + p;
    if ((bit & 7) == 0 && p + 8 <= framePixels && pixels[bit >> 3] == 0) {
      p += 8;
      continue;
    }
    if ((pixels[bit >> 3] >> (bit & 7)) & 1) fn(p);
    ++p;
  }
}

}  // namespace

bool isDicomSegFile(const std::string& path) {
  return io::dicomSopClassOf(path) == io::kSegmentationStorageUid;
}

std::optional<std::string> findDicomSegInFolder(const std::string& folder) {
  namespace fs = std::filesystem;
  std::vector<std::string> found;
  std::error_code ec;
  for (fs::directory_iterator it(folder, ec), end; !ec && it != end; it.increment(ec))
    if (it->is_regular_file(ec) && isDicomSegFile(it->path().string()))
      found.push_back(it->path().string());
  if (found.empty()) return std::nullopt;
  std::sort(found.begin(), found.end());
  if (found.size() > 1)
    throwFileError(folder, "holds " + std::to_string(found.size()) + " DICOM segmentations (" +
                               fs::path(found[0]).filename().string() + ", " +
                               fs::path(found[1]).filename().string() +
                               (found.size() > 2 ? ", ..." : "") + "); give the file of one");
  return found.front();
}

Volume readDicomSeg(const std::string& path, const ReadOptions& options) {
  DcmFileFormat file;
  DcmDataset* ds =
      &io::loadDicomOfClass(file, path, io::kSegmentationStorageUid, "a DICOM segmentation");

  // Pixel layout.
  const long rows = dicomInteger(ds, DCM_Rows, 0), columns = dicomInteger(ds, DCM_Columns, 0);
  if (rows <= 0 || columns <= 0) throwFileError(path, "missing or zero Rows/Columns");
  const std::string type = dicomText(ds, DCM_SegmentationType);
  const bool fractional = type == "FRACTIONAL";
  if (!fractional && type != "BINARY")
    throwFileError(path, "SegmentationType is '" + type + "' (expected BINARY or FRACTIONAL)");
  const long bits = dicomInteger(ds, DCM_BitsAllocated, 0);
  if (bits != (fractional ? 8 : 1))
    throwFileError(path, "BitsAllocated is " + std::to_string(bits) + " for a " + type +
                             " segmentation (expected " + (fractional ? "8)" : "1)"));
  const long maxFraction = fractional ? dicomInteger(ds, DCM_MaximumFractionalValue, 0) : 1;
  if (fractional && (maxFraction < 1 || maxFraction > 255))
    throwFileError(path, "missing or invalid MaximumFractionalValue");
  const long frames = dicomInteger(ds, DCM_NumberOfFrames, 0);
  if (frames < 1) throwFileError(path, "NumberOfFrames is missing or zero");
  DcmSequenceOfItems* perFrame = nullptr;
  if (ds->findAndGetSequence(DCM_PerFrameFunctionalGroupsSequence, perFrame).bad() || !perFrame ||
      long(perFrame->card()) != frames)
    throwFileError(path, "the per-frame functional groups (" +
                             std::to_string(perFrame ? perFrame->card() : 0) +
                             ") do not match NumberOfFrames (" + std::to_string(frames) + ")");
  DcmItem* shared = dicomItem(ds, DCM_SharedFunctionalGroupsSequence);

  // Segments, by their SegmentNumber.
  std::map<int, Segment> segments;
  DcmSequenceOfItems* segmentItems = nullptr;
  if (ds->findAndGetSequence(DCM_SegmentSequence, segmentItems).bad() || !segmentItems ||
      segmentItems->card() == 0)
    throwFileError(path, "no SegmentSequence");
  for (unsigned long s = 0; s < segmentItems->card(); ++s) {
    DcmItem* item = segmentItems->getItem(s);
    const long number = dicomInteger(item, DCM_SegmentNumber, 0);
    if (number < 1 || number > 65535)
      throwFileError(path, "segment " + std::to_string(s + 1) + " has no valid SegmentNumber");
    if (segments.count(int(number)))
      throwFileError(path, "two segments numbered " + std::to_string(number));
    Segment seg;
    seg.number = int(number);
    Label& l = seg.label;
    l.value = seg.number;
    l.name = dicomText(item, DCM_SegmentLabel);
    if (l.name.empty()) l.name = "Segment " + std::to_string(number);
    if (auto rgb = colourOf(item)) {
      l.color = *rgb;
    } else {
      l.color = LabelTable::defaultColor(l.value, l.name);
      l.colorGenerated = true;
    }
    SegmentTerminology t;
    t.category = codeOf(item, DCM_SegmentedPropertyCategoryCodeSequence);
    t.type = codeOf(item, DCM_SegmentedPropertyTypeCodeSequence);
    // The type modifier sits in the type's code item (current standard) or beside it (older).
    t.typeModifier = codeOf(dicomItem(item, DCM_SegmentedPropertyTypeCodeSequence),
                            DCM_SegmentedPropertyTypeModifierCodeSequence);
    if (t.typeModifier.empty())
      t.typeModifier = codeOf(item, DCM_SegmentedPropertyTypeModifierCodeSequence);
    t.region = codeOf(item, DCM_AnatomicRegionSequence);
    t.regionModifier =
        codeOf(dicomItem(item, DCM_AnatomicRegionSequence), DCM_AnatomicRegionModifierSequence);
    if (!t.category.empty() && !t.type.empty()) l.tags = terminologyTag(t);
    segments.emplace(seg.number, std::move(seg));
  }

  // A SEG Repose wrote gives each segment its label value and layer back, when every segment
  // has them and no two share a (value, layer).
  {
    std::map<int, std::pair<int, int>> own;
    std::set<std::pair<int, int>> seen;
    for (unsigned long s = 0; s < segmentItems->card(); ++s) {
      DcmItem* item = segmentItems->getItem(s);
      int value = 0, layer = 0;
      if (!io::getReposeLabel(*item, value, layer) || value < 1 || layer < 0 ||
          layer >= int(segments.size()) || !seen.insert({value, layer}).second)
        break;
      own[int(dicomInteger(item, DCM_SegmentNumber, 0))] = {value, layer};
    }
    if (own.size() == segments.size())
      for (auto& entry : segments) {
        entry.second.label.value = own[entry.first].first;
        entry.second.preferredLayer = own[entry.first].second;
      }
  }

  // Frames: segment, plane position; one orientation and spacing for all.
  FramePlane plane;
  std::vector<Vec3> positions(static_cast<std::size_t>(frames));
  std::vector<double> orientation0;
  for (long f = 0; f < frames; ++f) {
    DcmItem* item = perFrame->getItem(static_cast<unsigned long>(f));
    const std::string which = "frame " + std::to_string(f + 1);
    const std::vector<double> ipp =
        dicomNumbers(groupOf(item, shared, DCM_PlanePositionSequence), DCM_ImagePositionPatient);
    if (ipp.size() != 3)
      throwFileError(path, which + " has no plane position (ImagePositionPatient)");
    positions[std::size_t(f)] = Vec3(ipp[0], ipp[1], ipp[2]);
    const std::vector<double> iop = dicomNumbers(
        groupOf(item, shared, DCM_PlaneOrientationSequence), DCM_ImageOrientationPatient);
    if (iop.size() != 6)
      throwFileError(path, which + " has no plane orientation (ImageOrientationPatient)");
    if (f == 0) {
      orientation0 = iop;
      plane.rowDir = Vec3(iop[0], iop[1], iop[2]);
      plane.colDir = Vec3(iop[3], iop[4], iop[5]);
      if (plane.rowDir.norm() < 1e-6 || plane.colDir.norm() < 1e-6 ||
          std::fabs(plane.rowDir.normalized().dot(plane.colDir.normalized())) > 1e-3)
        throwFileError(path, which + ": ImageOrientationPatient is not two orthogonal directions");
      plane.rowDir.normalize();
      plane.colDir.normalize();
      DcmItem* measures = groupOf(item, shared, DCM_PixelMeasuresSequence);
      const std::vector<double> spacing = dicomNumbers(measures, DCM_PixelSpacing);
      if (spacing.size() != 2 || !(spacing[0] > 0) || !(spacing[1] > 0))
        throwFileError(path, which + " has no valid PixelSpacing");
      plane.rowStep = spacing[0];
      plane.columnStep = spacing[1];
      const std::vector<double> between = dicomNumbers(measures, DCM_SpacingBetweenSlices);
      if (between.size() == 1 && between[0] > 0) plane.sliceSpacing = between[0];
      const std::vector<double> thick = dicomNumbers(measures, DCM_SliceThickness);
      if (thick.size() == 1 && thick[0] > 0) plane.thickness = thick[0];
    } else {
      for (int c = 0; c < 6; ++c)
        if (std::fabs(iop[c] - orientation0[c]) > 1e-4)
          throwFileError(path, which + " has another orientation than frame 1");
      const std::vector<double> spacing =
          dicomNumbers(groupOf(item, shared, DCM_PixelMeasuresSequence), DCM_PixelSpacing);
      if (spacing.size() != 2 || std::fabs(spacing[0] - plane.rowStep) > 1e-4 * plane.rowStep ||
          std::fabs(spacing[1] - plane.columnStep) > 1e-4 * plane.columnStep)
        throwFileError(path, which + " has another PixelSpacing than frame 1");
    }
    long number = dicomInteger(groupOf(item, shared, DCM_SegmentIdentificationSequence),
                               DCM_ReferencedSegmentNumber, -1);
    if (number == -1 && segments.size() == 1) number = segments.begin()->first;
    auto seg = segments.find(int(number));
    if (number < 0 || seg == segments.end())
      throwFileError(path, which + (number < 0 ? " names no segment (ReferencedSegmentNumber)"
                                               : " refers to segment " + std::to_string(number) +
                                                     ", which the file does not define"));
    seg->second.frames.push_back(f);
  }

  // The pixels: packed bits (BINARY) or a byte each (FRACTIONAL), frame after frame.
  E_TransferSyntax xfer = ds->getOriginalXfer();
  if (DcmXfer(xfer).isEncapsulated()) {
    if (ds->chooseRepresentation(EXS_LittleEndianExplicit, nullptr).bad() ||
        !ds->canWriteXfer(EXS_LittleEndianExplicit))
      throwFileError(
          path, std::string("pixel data in a compressed transfer syntax Repose cannot decode (") +
                    DcmXfer(xfer).getXferName() + ")");
  }
  DcmElement* pixelElement = nullptr;
  Uint8* pixels = nullptr;
  if (ds->findAndGetElement(DCM_PixelData, pixelElement).bad() || !pixelElement ||
      pixelElement->getUint8Array(pixels).bad() || !pixels)
    throwFileError(path, "no PixelData");
  const std::int64_t framePixels = std::int64_t(rows) * columns;
  const std::int64_t needed = fractional ? frames * framePixels : (frames * framePixels + 7) / 8;
  if (std::int64_t(pixelElement->getLength()) < needed)
    throwFileError(path, "pixel data is truncated (" + std::to_string(pixelElement->getLength()) +
                             " bytes for " + std::to_string(frames) + " frames of " +
                             std::to_string(columns) + "x" + std::to_string(rows) + ", " +
                             std::to_string(needed) + " expected)");

  // The grid: the referenced series' when the frames fall on it, else their own.
  std::vector<Placement> placements;
  VolumeGeometry grid;
  const std::string referenced =
      dicomText(dicomItem(ds, DCM_ReferencedSeriesSequence), DCM_SeriesInstanceUID);
  if (auto reference = referencedGrid(path, referenced, options)) {
    if (auto placed = placeFrames(*reference, plane, positions, rows, columns)) {
      grid = *reference;
      placements = std::move(*placed);
    } else if (options.note) {
      options.note(path +
                   ": its frames are not on the grid of the referenced series; the frames' own "
                   "grid is used");
    }
  }
  if (placements.empty()) {
    grid = ownGrid(path, plane, positions, rows, columns);
    auto placed = placeFrames(grid, plane, positions, rows, columns);
    if (!placed && plane.sliceSpacing > 0) {
      // A SpacingBetweenSlices the frames do not keep (copied from another series, rounded):
      // the frames' own spacing, said.
      FramePlane measured = plane;
      measured.sliceSpacing = 0;
      VolumeGeometry own = ownGrid(path, measured, positions, rows, columns);
      if (auto fits = placeFrames(own, plane, positions, rows, columns)) {
        if (options.note)
          options.note(path + ": its frames are not " + std::to_string(plane.sliceSpacing) +
                       " mm apart as SpacingBetweenSlices says; their own spacing of " +
                       std::to_string(own.spacing()[2]) + " mm is used");
        grid = own;
        placed = std::move(fits);
      }
    }
    if (!placed) {
      // Name the first frame that does not fit, for the user.
      for (long f = 0; f < frames; ++f)
        if (!placeFrames(grid, plane, {positions[std::size_t(f)]}, rows, columns))
          throwFileError(path, "frame " + std::to_string(f + 1) +
                                   " is not on the grid of the other frames (same plane rows and "
                                   "columns, slices " +
                                   std::to_string(grid.spacing()[2]) + " mm apart)");
      throwFileError(path, "frames are not on one grid");
    }
    placements = std::move(*placed);
  }

  // Layers: each segment in the layer Repose gave it, when it overlaps nothing there; else in the
  // first layer where it overlaps no segment placed before it.
  const std::int64_t voxels = grid.numVoxels();
  int maxValue = 0;
  for (const auto& entry : segments) maxValue = std::max(maxValue, entry.second.label.value);
  const ScalarType scalar = maxValue <= 255     ? ScalarType::UInt8
                            : maxValue <= 65535 ? ScalarType::UInt16
                                                : ScalarType::Int32;
  io::checkReadMemory(path, voxels, double(scalarSize(scalar)) + 0.125, options);
  const std::int64_t dim0 = grid.dims[0], dim1 = grid.dims[1];
  auto voxelOf = [&](const Placement& at, std::int64_t p) {
    return (at.i0 + p % columns) + dim0 * ((at.j0 + p / columns) + dim1 * at.k);
  };
  std::vector<std::vector<std::uint64_t>> occupied;
  auto addLayer = [&] {
    io::checkReadMemory(
        path, voxels, (double(scalarSize(scalar)) + 0.125) * double(occupied.size() + 1), options);
    occupied.emplace_back(std::size_t((voxels + 63) / 64), 0);
  };
  auto clashes = [&](const Segment& seg, int layer) {
    bool clash = false;
    const std::vector<std::uint64_t>& bitsOfLayer = occupied[std::size_t(layer)];
    for (long f : seg.frames) {
      const Placement& at = placements[std::size_t(f)];
      forEachSetPixel(pixels, fractional, maxFraction, f, framePixels, [&](std::int64_t p) {
        const std::int64_t v = voxelOf(at, p);
        clash = clash || ((bitsOfLayer[std::size_t(v >> 6)] >> (v & 63)) & 1);
      });
      if (clash) break;
    }
    return clash;
  };
  std::map<int, int> layerOf;
  for (auto& entry : segments) {
    const int number = entry.first;  // not a structured binding: lambdas below capture it
    Segment& seg = entry.second;
    int layer = seg.preferredLayer;
    while (layer >= 0 && int(occupied.size()) <= layer) addLayer();
    if (layer < 0 || clashes(seg, layer))
      for (layer = 0;; ++layer) {
        if (layer == int(occupied.size())) {
          addLayer();
          break;
        }
        if (!clashes(seg, layer)) break;
      }
    std::vector<std::uint64_t>& bitsOfLayer = occupied[std::size_t(layer)];
    for (long f : seg.frames)
      forEachSetPixel(pixels, fractional, maxFraction, f, framePixels, [&](std::int64_t p) {
        const std::int64_t v = voxelOf(placements[std::size_t(f)], p);
        bitsOfLayer[std::size_t(v >> 6)] |= std::uint64_t(1) << (v & 63);
      });
    layerOf[number] = layer;
  }

  Volume volume(grid, scalar, int(occupied.size()));
  occupied.clear();
  occupied.shrink_to_fit();
  std::size_t done = 0;
  for (auto& entry : segments) {
    const int number = entry.first;  // not a structured binding: lambdas below capture it
    Segment& seg = entry.second;
    const int layer = layerOf[number];
    const int value = seg.label.value;
    for (long f : seg.frames) {
      const Placement& at = placements[std::size_t(f)];
      auto write = [&](auto* out) {
        forEachSetPixel(pixels, fractional, maxFraction, f, framePixels, [&](std::int64_t p) {
          out[voxelOf(at, p)] = std::remove_reference_t<decltype(*out)>(value);
        });
      };
      if (scalar == ScalarType::UInt8)
        write(volume.data<std::uint8_t>(layer));
      else if (scalar == ScalarType::UInt16)
        write(volume.data<std::uint16_t>(layer));
      else
        write(volume.data<std::int32_t>(layer));
    }
    seg.label.layer = layer;
    volume.labels().set(seg.label);
    reportProgress(options.progress, double(++done) / segments.size(), "reading DICOM SEG");
  }
  volume.setLabelMap(true);
  if (fractional && options.note)
    options.note(path + ": FRACTIONAL segmentation (" +
                 dicomText(ds, DCM_SegmentationFractionalType) + ", maximum " +
                 std::to_string(maxFraction) + ") thresholded at 0.5");
  return volume;
}

}  // namespace repose
