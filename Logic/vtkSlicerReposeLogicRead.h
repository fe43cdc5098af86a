// How the workbench reads a volume: within the memory budget a command line run gets by default
// (half the physical memory), less what the workbench already holds. It has no --memory option,
// so a file whose header claims more than that is refused with the numbers, before anything is
// allocated, instead of being attempted. Shared by file open, adding a segmentation and scenes.
#ifndef vtkSlicerReposeLogicRead_h
#define vtkSlicerReposeLogicRead_h

#include <repose/volume/Volume.h>

#include <string>

namespace vtkSlicerReposeLogicRead {

// Throws repose::Error naming the file, as repose::readVolume does.
repose::Volume ReadVolume(const std::string& path);
// A small text file (a pose, a skeleton, scene.json) whole; repose::Error "path: cannot open".
std::string ReadText(const std::string& path);

}  // namespace vtkSlicerReposeLogicRead

#endif
