#include "vtkSlicerReposeLogicRead.h"

#include <repose/io/VolumeIO.h>
#include <repose/util/Memory.h>

namespace vtkSlicerReposeLogicRead {

repose::Volume ReadVolume(const std::string& path) {
  repose::ReadOptions options;
  options.memoryLimitBytes = repose::memoryLeftWithin();
  options.budgetHint =
      "the workbench reads within half the physical memory; free memory, or use the command "
      "line's --memory";
  return repose::readVolume(path, options);
}

}  // namespace vtkSlicerReposeLogicRead
