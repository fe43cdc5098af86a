// Reading and writing volumes by file name: NIfTI-1/2 (.nii, .nii.gz), NRRD (.nrrd, .nhdr),
// 3D Slicer segmentations (.seg.nrrd) and DICOM series (a folder; read only).
#pragma once

#include "repose/util/Progress.h"
#include "repose/volume/Volume.h"

#include <string>
#include <vector>

namespace repose {

enum class FileFormat { Nifti, Nrrd, SegNrrd, DicomSeries };

struct ReadOptions {
  ProgressFn progress;
  // Bytes this read may allocate (0: no limit). Each reader estimates its need from the header
  // (the volume, plus staging or the library's own copy) before allocating anything, and above
  // the limit throws repose::Error naming the file with the numbers.
  double memoryLimitBytes = 0;
  // How the caller's user gets a larger budget, ending that error (the command line's option).
  std::string budgetHint = "raise --memory";
};

struct WriteOptions {
  int niftiVersion = 1;  // 1 or 2; NIfTI-1 is switched to 2 when a dimension exceeds 32767
  bool compress = true;  // gzip for .nhdr data and .nrrd; .nii.gz/.nii decide by their name
  ProgressFn progress;
};

// The format a path names: a folder is a DICOM series; otherwise by extension.
// Throws repose::Error naming the path when the extension is unknown.
FileFormat formatForPath(const std::string& path);
const char* formatName(FileFormat f);

// Reads any supported file or DICOM folder. Errors name the file and the problem.
Volume readVolume(const std::string& path, const ReadOptions& options = {});

// Writes atomically (temporary file in the target folder, renamed on success): a failure
// leaves no partial output. Label maps keep their label table (names, colours).
void writeVolume(const Volume& volume, const std::string& path, const WriteOptions& options = {});

// Extensions writeVolume accepts, for help texts.
std::vector<std::string> writableExtensions();

}  // namespace repose
