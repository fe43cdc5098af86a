#include "vtkSlicerReposeLogicRead.h"

#include <repose/io/VolumeIO.h>
#include <repose/rig/LabelConvention.h>
#include <repose/util/Error.h>
#include <repose/util/Memory.h>

#include <fstream>
#include <optional>
#include <sstream>

namespace vtkSlicerReposeLogicRead {

repose::Volume ReadVolume(const std::string& path, std::vector<std::string>* notes) {
  repose::ReadOptions options;
  if (notes) options.note = [notes](const std::string& n) { notes->push_back(n); };
  options.memoryLimitBytes = repose::memoryLeftWithin();
  options.budgetHint =
      "the workbench reads within half the physical memory; free memory, or use the command "
      "line's --memory";
  return repose::readVolume(path, options);
}

std::string NameLabels(repose::Volume& labels, const std::string& tissuesPath,
                       const std::string& source, const std::vector<repose::LabelCount>* counts) {
  std::optional<repose::TissueTable> tissues;
  if (!tissuesPath.empty()) {
    try {
      tissues = repose::readTissueTable(tissuesPath);
    } catch (const repose::Error&) {
      // The pose job reports a broken table; names then come from the convention.
    }
  }
  return repose::completeLabelNamesAndColors(labels, tissues ? &*tissues : nullptr, source, counts);
}

std::string ReadText(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw repose::Error(path + ": cannot open");
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

}  // namespace vtkSlicerReposeLogicRead
