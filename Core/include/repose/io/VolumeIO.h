// Reading and writing volumes by file name: NIfTI-1/2 (.nii, .nii.gz), NRRD (.nrrd, .nhdr),
// 3D Slicer segmentations (.seg.nrrd), DICOM series (a folder; read only) and DICOM
// segmentations (SEG: a file, or a folder holding one; read only).
#pragma once

#include "repose/util/Progress.h"
#include "repose/volume/Volume.h"

#include <functional>
#include <string>
#include <vector>

namespace repose {

// DicomFile: one DICOM file (.dcm, or any file with DICOM's preamble): a segmentation (SEG).
enum class FileFormat { Nifti, Nrrd, SegNrrd, DicomSeries, DicomFile };

struct ReadOptions {
  ProgressFn progress;
  // Bytes this read may allocate (0: no limit). Each reader estimates its need from the header
  // (the volume, plus staging or the library's own copy) before allocating anything, and above
  // the limit throws repose::Error naming the file with the numbers.
  double memoryLimitBytes = 0;
  // How the caller's user gets a larger budget, ending that error (the command line's option).
  std::string budgetHint = "raise --memory";
  // What a reader decided that its user should know, one line each (a fractional DICOM SEG
  // thresholded, the grid a SEG was placed on). Unset: not said.
  std::function<void(const std::string&)> note;
};

struct WriteOptions {
  int niftiVersion = 1;  // 1 or 2; NIfTI-1 is switched to 2 when a dimension exceeds 32767
  bool compress = true;  // gzip for .nhdr data and .nrrd; .nii.gz/.nii decide by their name
  ProgressFn progress;
  // DICOM SEG (.dcm) only: a DICOM file whose patient and study the SEG takes (DicomSegIO.h).
  std::string sourceDicom;
};

// The format a path names: a folder is a DICOM series (or holds a SEG); otherwise by extension,
// or by content for a DICOM file without one.
// Throws repose::Error naming the path when the extension is unknown.
FileFormat formatForPath(const std::string& path);
const char* formatName(FileFormat f);

// Reads any supported file or DICOM folder. Errors name the file and the problem.
Volume readVolume(const std::string& path, const ReadOptions& options = {});

// Writes atomically (temporary file in the target folder, renamed on success): a failure
// leaves no partial output. Label maps keep their label table (names, colours). A .dcm path is
// written as a DICOM SEG (label maps only).
void writeVolume(const Volume& volume, const std::string& path, const WriteOptions& options = {});

// A DICOM file of an input: the file itself, the SEG a folder holds, else the first DICOM file of a
// series folder; "" when the input is not DICOM. What a DICOM SEG output takes its patient and
// study from (WriteOptions::sourceDicom).
std::string dicomSourceOf(const std::string& path);

// Extensions writeVolume accepts, for help texts.
std::vector<std::string> writableExtensions();

}  // namespace repose
