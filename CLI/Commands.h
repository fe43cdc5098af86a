// The `repose` subcommands. Each lives in its own Command<Name>.cpp and returns the exit code;
// errors are thrown (repose::Error, UsageError) and turned into one line by main.
#pragma once

#include <string>
#include <vector>

namespace repose::cli {

using Args = std::vector<std::string>;

int runInfo(const Args& args);
int runConvert(const Args& args);
int runPhantom(const Args& args);
int runCage(const Args& args);
int runMesh(const Args& args);
int runWarp(const Args& args);
int runPose(const Args& args);
int runRig(const Args& args);
int runExportFdtd(const Args& args);
int runSweep(const Args& args);

struct Command {
  const char* name;
  const char* summary;
  int (*run)(const Args&);
};

// In the order `repose --help` lists them.
inline const Command kCommands[] = {
    {"info", "describe a volume: geometry, orientation, type, labels", runInfo},
    {"convert", "convert a volume between NIfTI, NRRD and .seg.nrrd (or from DICOM)", runConvert},
    {"phantom", "generate the synthetic whole-body mannequin (organs G, parts S, skeleton)",
     runPhantom},
    {"rig", "make S, the skeleton and the tissue table of a segmentation from its bones", runRig},
    {"cage", "build the control cage around the body (optionally separating two parts)", runCage},
    {"mesh", "build the transfer mesh and embed it in the cage", runMesh},
    {"warp", "pose a label map (and image) at full resolution from a posed cage", runWarp},
    {"pose", "the whole job: label maps + pose file -> posed maps, transform, report", runPose},
    {"sweep", "many subjects in many poses, in one process or over MPI ranks", runSweep},
    {"export-fdtd", "a (posed) label map as an openEMS FDTD model: tissues at a frequency",
     runExportFdtd},
};

}  // namespace repose::cli
