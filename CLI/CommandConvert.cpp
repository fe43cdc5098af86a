// `repose convert IN OUT`: between NIfTI, NRRD, .seg.nrrd and DICOM SEG (and from DICOM series
// and RT Structure Sets), keeping the geometry in RAS and the label names; the output appears
// only when complete.
#include "ArgParser.h"
#include "Commands.h"
#include "MemoryBudget.h"
#include "TerminalProgress.h"
#include "VolumeReport.h"

#include "repose/io/AtomicOutput.h"
#include "repose/io/RtStructIO.h"

#include <iostream>

namespace repose::cli {

int runConvert(const Args& args) {
  ArgParser p("convert",
              "Convert a volume between formats, keeping its geometry and label names.\n"
              "Readable: .nii .nii.gz .nrrd .nhdr .seg.nrrd, DICOM series folders, DICOM SEG,\n"
              "and DICOM RT Structure Sets (rasterized onto --reference's grid, or a grid of\n"
              "--spacing-mm voxels spanning the contours).\n"
              "Writable: .nii .nii.gz .nrrd .nhdr .seg.nrrd .dcm (DICOM SEG), chosen by OUT's\n"
              "extension.");
  p.positional("IN", "input volume")
      .positional("OUT", "output file")
      .option("nifti-version", "1|2", "NIfTI header version for .nii/.nii.gz outputs", "1")
      .flag("no-compress", "write .nrrd/.nhdr data uncompressed (raw)")
      .flag("json", "print a JSON description of the written volume")
      .option("reference", "IMAGE",
              "an RT Structure Set's grid: this image's (a DICOM folder must hold the series the "
              "structure set references)")
      .option("spacing-mm", "MM",
              "an RT Structure Set's grid: voxels of this size spanning its contours");
  declareMemoryOption(p, "a volume that would not fit is refused with the numbers");
  if (!p.parse(args)) return 0;
  const std::string in = p.get("IN"), out = p.get("OUT");
  WriteOptions w;
  w.niftiVersion = static_cast<int>(p.getInt("nifti-version"));
  if (w.niftiVersion != 1 && w.niftiVersion != 2) throw UsageError{"--nifti-version is 1 or 2"};
  w.compress = !p.has("no-compress");
  formatForPath(out);  // an unknown output type fails before the input is read
  refuseOverwritingInput(in, out);
  const ReadOptions r = readOptionsWithin(parseMemoryBudget(p.get("memory")));
  w.progress = terminalProgress();
  const bool contours = isRtStructFile(in);
  if (!contours && (p.has("reference") || p.has("spacing-mm")))
    throw UsageError{"--reference and --spacing-mm are for RT Structure Sets; " + in +
                     " is not one"};
  if (contours && p.has("reference") == p.has("spacing-mm"))
    throw UsageError{
        in + " is an RT Structure Set: give its grid with --reference IMAGE or --spacing-mm MM"};
  Volume volume;
  if (contours) {
    RtStructOptions o;
    if (p.has("reference")) o.reference = p.get("reference");
    if (p.has("spacing-mm")) {
      o.spacingMm = p.getDouble("spacing-mm");
      if (!(o.spacingMm > 0)) throw UsageError{"--spacing-mm must be positive"};
    }
    o.progress = r.progress;
    o.memoryLimitBytes = r.memoryLimitBytes;
    o.note = r.note;
    volume = readRtStruct(in, o);
  } else {
    volume = readVolume(in, r);
  }
  if (formatForPath(out) == FileFormat::DicomFile) w.sourceDicom = dicomSourceOf(in);
  writeVolume(volume, out, w);
  const nlohmann::json description = describeVolume(volume, out);
  if (p.has("json"))
    std::cout << description.dump(2) << "\n";
  else
    std::cout << "wrote " << out << " (" << description["format"].get<std::string>() << ", "
              << description["orientation"].get<std::string>() << " "
              << description["scalar_type"].get<std::string>() << ", "
              << description.value("labels_present", 0) << " labels)\n";
  return 0;
}

}  // namespace repose::cli
