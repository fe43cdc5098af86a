// How the workbench reads a volume: within the memory budget a command line run gets by default
// (half the physical memory), less what the workbench already holds. It has no --memory option,
// so a file whose header claims more than that is refused with the numbers, before anything is
// allocated, instead of being attempted. Shared by file open, adding a segmentation and scenes.
#ifndef vtkSlicerReposeLogicRead_h
#define vtkSlicerReposeLogicRead_h

#include <repose/volume/LabelStatistics.h>
#include <repose/volume/Volume.h>

#include <string>
#include <vector>

namespace vtkSlicerReposeLogicRead {

// Throws repose::Error naming the file, as repose::readVolume does.
// `notes`, when given, gets what the reader decided that the user should know (ReadOptions::note).
repose::Volume ReadVolume(const std::string& path, std::vector<std::string>* notes = nullptr);
// Names and colours for G's labels the file left without (repose::completeLabelNamesAndColors),
// the names from the tissue table at `tissuesPath` when one is set and reads, else from the label
// convention G follows. Returns the one-line note ("" when the file named every label).
// `counts`: the map's label counts when the caller has them, so it is not read again.
std::string NameLabels(repose::Volume& labels, const std::string& tissuesPath,
                       const std::string& source,
                       const std::vector<repose::LabelCount>* counts = nullptr);
// A small text file (a pose, a skeleton, scene.json) whole; repose::Error "path: cannot open".
std::string ReadText(const std::string& path);
// Which files `paths` are now, to tell later whether a read of them is still current: each path
// with its size and modification time (a folder, such as a DICOM series: of every file in it).
// "" when a non-empty path does not exist; empty paths stand for themselves.
std::string FilesStamp(const std::vector<std::string>& paths);
// A file's name without its folder and its volume, mesh or pose extension ("G" of
// "/d/G.nii.gz"): what nodes read from it are named.
std::string FileStem(const std::string& path);

}  // namespace vtkSlicerReposeLogicRead

#endif
