#include "vtkSlicerReposeLogicRead.h"

#include <repose/io/VolumeIO.h>
#include <repose/util/Error.h>
#include <repose/util/Memory.h>

#include <fstream>
#include <sstream>

namespace vtkSlicerReposeLogicRead {

repose::Volume ReadVolume(const std::string& path) {
  repose::ReadOptions options;
  options.memoryLimitBytes = repose::memoryLeftWithin();
  options.budgetHint =
      "the workbench reads within half the physical memory; free memory, or use the command "
      "line's --memory";
  return repose::readVolume(path, options);
}

std::string ReadText(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw repose::Error(path + ": cannot open");
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

}  // namespace vtkSlicerReposeLogicRead
