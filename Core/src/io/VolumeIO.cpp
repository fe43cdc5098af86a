// Format dispatch by file name; every reader and writer below reports one-line errors.
#include "repose/io/VolumeIO.h"

#include "repose/io/DicomSeriesIO.h"
#include "repose/io/NiftiIO.h"
#include "repose/io/NrrdIO.h"

#include <algorithm>
#include <cctype>
#include <filesystem>

namespace repose {
namespace {

bool endsWithNoCase(std::string s, const std::string& suffix) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return std::tolower(c); });
  return s.size() >= suffix.size() &&
         s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

}  // namespace

FileFormat formatForPath(const std::string& path) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) return FileFormat::DicomSeries;
  if (endsWithNoCase(path, ".seg.nrrd")) return FileFormat::SegNrrd;
  if (endsWithNoCase(path, ".nrrd") || endsWithNoCase(path, ".nhdr")) return FileFormat::Nrrd;
  if (endsWithNoCase(path, ".nii") || endsWithNoCase(path, ".nii.gz")) return FileFormat::Nifti;
  throwFileError(path,
                 "unknown file type (expected .nii, .nii.gz, .nrrd, .nhdr, .seg.nrrd or a "
                 "DICOM folder)");
}

const char* formatName(FileFormat f) {
  switch (f) {
    case FileFormat::Nifti:
      return "NIfTI";
    case FileFormat::Nrrd:
      return "NRRD";
    case FileFormat::SegNrrd:
      return "Slicer segmentation (.seg.nrrd)";
    case FileFormat::DicomSeries:
      return "DICOM series";
  }
  return "?";
}

Volume readVolume(const std::string& path, const ReadOptions& options) {
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) throwFileError(path, "file not found");
  switch (formatForPath(path)) {
    case FileFormat::Nifti:
      return readNifti(path, options);
    case FileFormat::Nrrd:
    case FileFormat::SegNrrd:
      return readNrrd(path, options);
    case FileFormat::DicomSeries:
      return readDicomSeries(path, options);
  }
  throwFileError(path, "unknown file type");
}

void writeVolume(const Volume& volume, const std::string& path, const WriteOptions& options) {
  if (std::filesystem::is_directory(path)) throwFileError(path, "is a folder; give a file name");
  switch (formatForPath(path)) {
    case FileFormat::Nifti:
      return writeNifti(volume, path, options);
    case FileFormat::Nrrd:
    case FileFormat::SegNrrd:
      return writeNrrd(volume, path, options);
    case FileFormat::DicomSeries:
      break;
  }
  throwFileError(path, "DICOM output is not supported; write NIfTI or NRRD");
}

std::vector<std::string> writableExtensions() {
  return {".nii", ".nii.gz", ".nrrd", ".nhdr", ".seg.nrrd"};
}

}  // namespace repose
