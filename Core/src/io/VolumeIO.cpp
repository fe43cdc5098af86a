// Format dispatch by file name; every reader and writer below reports one-line errors.
#include "repose/io/VolumeIO.h"

#include "repose/io/DicomSegIO.h"
#include "repose/io/DicomSeriesIO.h"
#include "repose/io/NiftiIO.h"
#include "repose/io/NrrdIO.h"
#include "repose/util/Error.h"

#include "DcmtkCommon.h"
#include "DicomScreen.h"

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
  if (endsWithNoCase(path, ".dcm")) return FileFormat::DicomFile;
  // DICOM files often have no extension at all: known by their content.
  if (std::filesystem::is_regular_file(path, ec)) {
    bool dicom = false;
    try {
      dicom = io::screenDicomFile(path);
    } catch (const Error&) {
      dicom = true;  // DICOM, but corrupt: its reader says how
    }
    if (dicom) return FileFormat::DicomFile;
  }
  throwFileError(path,
                 "unknown file type (expected .nii, .nii.gz, .nrrd, .nhdr, .seg.nrrd, a DICOM "
                 "SEG file or a DICOM folder)");
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
    case FileFormat::DicomFile:
      return "DICOM file";
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
      if (const auto seg = findDicomSegInFolder(path)) return readDicomSeg(*seg, options);
      return readDicomSeries(path, options);
    case FileFormat::DicomFile: {
      const std::string sop = io::dicomSopClassOf(path);
      if (sop == io::kRtStructureSetStorageUid)
        throwFileError(path,
                       "an RT Structure Set (contours), not a volume: rasterize it with `repose "
                       "convert` and --reference IMAGE or --spacing-mm MM");
      if (sop.empty() || sop == io::kSegmentationStorageUid) return readDicomSeg(path, options);
      throwFileError(path, "a DICOM image file: give the folder of its series, or a DICOM SEG");
    }
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
    case FileFormat::DicomFile: {
      DicomSegWriteOptions o;
      o.progress = options.progress;
      o.sourceDicom = options.sourceDicom;
      return writeDicomSeg(volume, path, o);
    }
    case FileFormat::DicomSeries:
      break;
  }
  throwFileError(path, "is a DICOM series folder; write a DICOM SEG (.dcm), NIfTI or NRRD");
}

std::string dicomSourceOf(const std::string& path) {
  try {
    switch (formatForPath(path)) {
      case FileFormat::DicomFile:
        return path;
      case FileFormat::DicomSeries: {
        if (const auto seg = findDicomSegInFolder(path)) return *seg;
        std::vector<std::string> files;
        std::error_code ec;
        for (std::filesystem::directory_iterator it(path, ec), end; !ec && it != end;
             it.increment(ec))
          if (it->is_regular_file(ec)) files.push_back(it->path().string());
        std::sort(files.begin(), files.end());
        for (const std::string& f : files)
          if (!io::dicomSopClassOf(f).empty()) return f;
        return "";
      }
      default:
        return "";
    }
  } catch (const Error&) {
    return "";
  }
}

std::vector<std::string> writableExtensions() {
  return {".nii", ".nii.gz", ".nrrd", ".nhdr", ".seg.nrrd", ".dcm"};
}

}  // namespace repose
