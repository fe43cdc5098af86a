// DICOM series with GDCM: files grouped by SeriesInstanceUID, slices ordered by their position
// along the slice normal (not by file name or InstanceNumber), geometry from IPP/IOP in LPS.
#include "repose/io/DicomSeriesIO.h"

#include "repose/util/Error.h"

#include "DicomSandbox.h"
#include "DicomScreen.h"
#include "ReaderCommon.h"

#include <gdcmDirectory.h>
#include <gdcmImageReader.h>
#include <gdcmScanner.h>
#include <gdcmTrace.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <map>
#include <optional>
#include <sstream>

namespace repose {
namespace {

const gdcm::Tag kSeriesUid(0x0020, 0x000e);
const gdcm::Tag kPosition(0x0020, 0x0032);
const gdcm::Tag kOrientation(0x0020, 0x0037);
const gdcm::Tag kPixelSpacing(0x0028, 0x0030);
const gdcm::Tag kFrames(0x0028, 0x0008);

std::vector<double> parseNumbers(const char* text) {
  std::vector<double> out;
  if (!text) return out;
  std::string s(text);
  std::replace(s.begin(), s.end(), '\\', ' ');
  std::istringstream in(s);
  double v;
  while (in >> v) out.push_back(v);
  return out;
}

struct Slice {
  std::string file;
  Eigen::Vector3d position;
  double along = 0;  // position projected on the slice normal
};

// Voxels of one file as doubles after rescale; also checks it matches the first slice's layout.
void readPixels(const std::string& file, std::int64_t columns, std::int64_t rows,
                std::vector<double>& out, double& slope, double& intercept) {
  gdcm::ImageReader reader;
  reader.SetFileName(file.c_str());
  if (!reader.Read()) throwFileError(file, "not a readable DICOM image");
  const gdcm::Image& image = reader.GetImage();
  if (image.GetNumberOfDimensions() != 2 &&
      !(image.GetNumberOfDimensions() == 3 && image.GetDimension(2) == 1))
    throwFileError(file, "multi-frame DICOM images are not supported");
  if (image.GetDimension(0) != columns || image.GetDimension(1) != rows)
    throwFileError(file, "slice size differs from the rest of the series");
  const gdcm::PixelFormat& pf = image.GetPixelFormat();
  if (pf.GetSamplesPerPixel() != 1) throwFileError(file, "colour DICOM images are not supported");
  std::vector<char> buffer(image.GetBufferLength());
  if (!image.GetBuffer(buffer.data()))
    throwFileError(file, "cannot decode the pixel data (unsupported or corrupt compression)");
  slope = image.GetSlope();
  intercept = image.GetIntercept();
  const std::size_t n = static_cast<std::size_t>(columns * rows);
  out.resize(n);
  auto convert = [&](auto* typed) {
    if (buffer.size() < n * sizeof(*typed)) throwFileError(file, "pixel data is truncated");
    for (std::size_t i = 0; i < n; ++i) out[i] = typed[i] * slope + intercept;
  };
  switch (pf.GetScalarType()) {
    case gdcm::PixelFormat::UINT8:
      convert(reinterpret_cast<const std::uint8_t*>(buffer.data()));
      break;
    case gdcm::PixelFormat::INT8:
      convert(reinterpret_cast<const std::int8_t*>(buffer.data()));
      break;
    case gdcm::PixelFormat::UINT16:
      convert(reinterpret_cast<const std::uint16_t*>(buffer.data()));
      break;
    case gdcm::PixelFormat::INT16:
      convert(reinterpret_cast<const std::int16_t*>(buffer.data()));
      break;
    case gdcm::PixelFormat::UINT32:
      convert(reinterpret_cast<const std::uint32_t*>(buffer.data()));
      break;
    case gdcm::PixelFormat::INT32:
      convert(reinterpret_cast<const std::int32_t*>(buffer.data()));
      break;
    case gdcm::PixelFormat::FLOAT32:
      convert(reinterpret_cast<const float*>(buffer.data()));
      break;
    case gdcm::PixelFormat::FLOAT64:
      convert(reinterpret_cast<const double*>(buffer.data()));
      break;
    default:
      throwFileError(file, std::string("unsupported pixel format ") + pf.GetScalarTypeAsString());
  }
}

// The slices of one series sorted along their normal, and the grid they make (checked: one
// orientation, no two slices at one place, even spacing).
struct SeriesLayout {
  std::vector<Slice> slices;
  VolumeGeometry geometry;
};

SeriesLayout layoutSeries(const std::string& folder, const gdcm::Scanner& scanner,
                          const std::vector<std::string>& files) {
  namespace fs = std::filesystem;
  // Orientation and ordering along the normal, checked for consistency across slices.
  const std::string& first = files.front();
  const std::vector<double> iop = parseNumbers(scanner.GetValue(first.c_str(), kOrientation));
  if (iop.size() != 6) throwFileError(first, "missing or malformed ImageOrientationPatient");
  const Eigen::Vector3d rowDir = Eigen::Vector3d(iop[0], iop[1], iop[2]).normalized();
  const Eigen::Vector3d colDir = Eigen::Vector3d(iop[3], iop[4], iop[5]).normalized();
  const Eigen::Vector3d normal = rowDir.cross(colDir);
  SeriesLayout layout;
  std::vector<Slice>& slices = layout.slices;
  for (const std::string& f : files) {
    const std::vector<double> p = parseNumbers(scanner.GetValue(f.c_str(), kPosition));
    const std::vector<double> o = parseNumbers(scanner.GetValue(f.c_str(), kOrientation));
    if (p.size() != 3) throwFileError(f, "malformed ImagePositionPatient");
    if (o.size() != 6 ||
        Eigen::Map<const Eigen::Matrix<double, 6, 1>>(o.data()).isApprox(
            Eigen::Map<const Eigen::Matrix<double, 6, 1>>(iop.data()), 1e-4) == false)
      throwFileError(f, "slice orientation differs from the rest of the series");
    Slice s{f, Eigen::Vector3d(p[0], p[1], p[2]), 0};
    s.along = s.position.dot(normal);
    slices.push_back(s);
  }
  std::sort(slices.begin(), slices.end(),
            [](const Slice& a, const Slice& b) { return a.along < b.along; });
  for (std::size_t s = 1; s < slices.size(); ++s)
    if (std::fabs(slices[s].along - slices[s - 1].along) < 1e-4)
      throwFileError(slices[s].file, "two slices at the same position (" +
                                         fs::path(slices[s - 1].file).filename().string() + ")");

  const std::vector<double> spacing = parseNumbers(scanner.GetValue(first.c_str(), kPixelSpacing));
  if (spacing.size() != 2 || spacing[0] <= 0 || spacing[1] <= 0)
    throwFileError(first, "missing or malformed PixelSpacing");
  Eigen::Vector3d sliceStep = normal;  // a single slice gets unit thickness along the normal
  if (slices.size() > 1) {
    sliceStep = (slices.back().position - slices.front().position) / double(slices.size() - 1);
    const double step = (slices.back().along - slices.front().along) / double(slices.size() - 1);
    for (std::size_t s = 1; s < slices.size(); ++s) {
      const double gap = slices[s].along - slices[s - 1].along;
      if (std::fabs(gap - step) > 0.01 * std::fabs(step) + 1e-3)
        throwFileError(folder, "slices are not evenly spaced (gap of " + std::to_string(gap) +
                                   " mm before " + fs::path(slices[s].file).filename().string() +
                                   ", expected " + std::to_string(step) + " mm)");
    }
  }

  // First slice fixes the in-plane size; pixels are read slice by slice.
  gdcm::ImageReader probe;
  probe.SetFileName(slices.front().file.c_str());
  if (!probe.Read()) throwFileError(slices.front().file, "not a readable DICOM image");
  const std::int64_t columns = probe.GetImage().GetDimension(0);
  const std::int64_t rows = probe.GetImage().GetDimension(1);

  VolumeGeometry& g = layout.geometry;
  g.dims = {columns, rows, static_cast<std::int64_t>(slices.size())};
  Eigen::Matrix4d lps = Eigen::Matrix4d::Identity();
  lps.block<3, 1>(0, 0) = rowDir * spacing[1];  // column index i moves along the row direction
  lps.block<3, 1>(0, 1) = colDir * spacing[0];  // row index j moves along the column direction
  lps.block<3, 1>(0, 2) = sliceStep;
  lps.block<3, 1>(0, 3) = slices.front().position;
  g.ijkToRas = flipLpsRas(lps);
  g.validate(folder);
  return layout;
}

// The DICOM files of a folder (not its subfolders) that pass the screen, probed in a child, and
// scanned for the tags above. Throws naming the folder when it holds none.
std::vector<std::string> scanFolder(const std::string& folder, gdcm::Scanner& scanner) {
  gdcm::Trace::SetDebug(false);
  gdcm::Trace::SetWarning(false);
  gdcm::Trace::SetError(false);
  std::error_code ec;
  if (!std::filesystem::is_directory(folder, ec)) throwFileError(folder, "not a folder");
  gdcm::Directory directory;
  directory.Load(folder, false);
  const auto& files = directory.GetFilenames();
  if (files.empty()) throwFileError(folder, "folder holds no files");

  std::vector<std::string> dicomFiles;
  for (const std::string& f : files)
    if (io::screenDicomFile(f)) dicomFiles.push_back(f);
  if (dicomFiles.empty()) throwFileError(folder, "no DICOM image slices found");
  io::probeDicomFilesInChild(dicomFiles);
  for (const gdcm::Tag& t : {kSeriesUid, kPosition, kOrientation, kPixelSpacing, kFrames})
    scanner.AddTag(t);
  if (!scanner.Scan(dicomFiles)) throwFileError(folder, "cannot scan the DICOM files");
  return dicomFiles;
}

// Image slices (files with a position) by SeriesInstanceUID.
std::map<std::string, std::vector<std::string>> seriesOf(const gdcm::Scanner& scanner,
                                                         const std::vector<std::string>& files) {
  std::map<std::string, std::vector<std::string>> series;
  for (const std::string& f : files) {
    if (!scanner.IsKey(f.c_str())) continue;  // not DICOM (e.g. a DICOMDIR-less README)
    const char* uid = scanner.GetValue(f.c_str(), kSeriesUid);
    const char* ipp = scanner.GetValue(f.c_str(), kPosition);
    if (!ipp) continue;  // not an image slice (SR, presentation state, segmentation, ...)
    series[uid ? uid : ""].push_back(f);
  }
  return series;
}

}  // namespace

std::optional<VolumeGeometry> findDicomSeriesGeometry(const std::string& folder,
                                                      const std::string& seriesUid) {
  gdcm::Scanner scanner;
  std::vector<std::string> files;
  try {
    files = scanFolder(folder, scanner);
  } catch (const Error&) {
    return std::nullopt;  // no DICOM files here: the series is not in this folder
  }
  auto series = seriesOf(scanner, files);
  // GDCM keeps the UID's padding (a trailing NUL or space of an odd-length value).
  for (auto& [uid, slices] : series) {
    std::string trimmed = uid;
    while (!trimmed.empty() && (trimmed.back() == '\0' || trimmed.back() == ' '))
      trimmed.pop_back();
    if (trimmed == seriesUid) return layoutSeries(folder, scanner, slices).geometry;
  }
  return std::nullopt;
}

Volume readDicomSeries(const std::string& folder, const ReadOptions& options) {
  gdcm::Scanner scanner;
  const std::vector<std::string> dicomFiles = scanFolder(folder, scanner);
  const auto series = seriesOf(scanner, dicomFiles);
  if (series.empty()) throwFileError(folder, "no DICOM image slices found");
  auto chosen = std::max_element(series.begin(), series.end(), [](const auto& a, const auto& b) {
    return a.second.size() < b.second.size();
  });
  for (auto it = series.begin(); it != series.end(); ++it)
    if (it != chosen && it->second.size() == chosen->second.size())
      throwFileError(folder, "holds several series of " + std::to_string(it->second.size()) +
                                 " slices; give the folder of one series");
  const SeriesLayout layout = layoutSeries(folder, scanner, chosen->second);
  const std::vector<Slice>& slices = layout.slices;
  const VolumeGeometry& g = layout.geometry;
  const std::int64_t columns = g.dims[0], rows = g.dims[1];

  // float32 holds every int16 exactly, so it can stage the values until the type is known: 4 bytes
  // a voxel staged, then up to 4 in the volume.
  io::checkReadMemory(folder, g.numVoxels(), 8, options);
  std::vector<float> all(static_cast<std::size_t>(g.numVoxels()));
  std::vector<double> pixels;
  bool integral = true;
  for (std::size_t s = 0; s < slices.size(); ++s) {
    double slope = 1, intercept = 0;
    readPixels(slices[s].file, columns, rows, pixels, slope, intercept);
    integral = integral && slope == std::floor(slope) && intercept == std::floor(intercept);
    std::transform(pixels.begin(), pixels.end(), all.begin() + s * pixels.size(),
                   [](double v) { return static_cast<float>(v); });
    reportProgress(options.progress, double(s + 1) / slices.size(), "reading DICOM");
  }
  const auto [lo, hi] = std::minmax_element(all.begin(), all.end());
  const bool fitsInt16 = integral && *lo >= std::numeric_limits<std::int16_t>::min() &&
                         *hi <= std::numeric_limits<std::int16_t>::max();
  Volume volume(g, fitsInt16 ? ScalarType::Int16 : ScalarType::Float32);
  if (fitsInt16) {
    std::int16_t* out = volume.data<std::int16_t>();
    for (std::size_t i = 0; i < all.size(); ++i) out[i] = static_cast<std::int16_t>(all[i]);
  } else {
    float* out = volume.data<float>();
    std::copy(all.begin(), all.end(), out);
  }
  volume.setLabelMap(false);
  return volume;
}

}  // namespace repose
