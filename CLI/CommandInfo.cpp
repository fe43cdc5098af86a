// `repose info FILE [--json]`: geometry, orientation, type and labels of a volume.
#include "ArgParser.h"
#include "Commands.h"
#include "MemoryBudget.h"
#include "TerminalProgress.h"
#include "VolumeReport.h"

#include <iostream>

namespace repose::cli {

int runInfo(const Args& args) {
  ArgParser p("info",
              "Describe a volume: dimensions, spacing, orientation (axis codes, the letter\n"
              "each voxel axis points to), RAS extent, scalar type, and for label maps every\n"
              "label with its name, voxel count and volume. FILE is .nii, .nii.gz, .nrrd,\n"
              ".nhdr, .seg.nrrd or a DICOM series folder.");
  p.positional("FILE", "the volume to describe").flag("json", "print JSON instead of text");
  declareMemoryOption(p, "a volume that would not fit is refused with the numbers");
  if (!p.parse(args)) return 0;
  const std::string path = p.get("FILE");
  const Volume volume = readVolume(path, readOptionsWithin(parseMemoryBudget(p.get("memory"))));
  const nlohmann::json description = describeVolume(volume, path);
  if (p.has("json"))
    std::cout << description.dump(2) << "\n";
  else
    std::cout << formatVolumeText(description);
  return 0;
}

}  // namespace repose::cli
