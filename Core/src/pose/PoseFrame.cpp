// poseFrame: the one sequence every caller of a full-resolution frame runs (frame, grid, labels,
// field, pockets, report), so the command line, the module and Python write the same files.
#include "repose/pose/PoseFrame.h"

#include "PoseFrameSteps.h"

#include "repose/io/AtomicOutput.h"
#include "repose/io/ColorTableIO.h"
#include "repose/io/FolderLock.h"
#include "repose/io/NrrdIO.h"
#include "repose/io/VolumeIO.h"
#include "repose/mesh/VolumePrediction.h"
#include "repose/pose/PoseReport.h"
#include "repose/pose/SlicerSceneMrml.h"
#include "repose/raster/PieceOverlap.h"
#include "repose/raster/PocketFilling.h"
#include "repose/raster/Rasterizer.h"
#include "repose/util/Error.h"
#include "repose/util/Interrupt.h"
#include "repose/util/Memory.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <optional>
#include <limits>
#include <map>
#include <stdlib.h>
#include <set>
#include <sstream>

namespace repose {

LabelMapFiles labelMapFilesFor(const std::string& choice, const std::string& inputPath) {
  if (choice == "nii.gz") return LabelMapFiles::Nifti;
  if (choice == "seg.nrrd") return LabelMapFiles::SegNrrd;
  if (choice == "both") return LabelMapFiles::Both;
  if (choice == "dcmseg") return LabelMapFiles::DicomSeg;
  if (choice == "auto")
    return !inputPath.empty() && formatForPath(inputPath) == FileFormat::SegNrrd
               ? LabelMapFiles::SegNrrd
               : LabelMapFiles::Nifti;
  throw Error("output format '" + choice + "' is not one of auto, nii.gz, seg.nrrd, both, dcmseg");
}

std::vector<std::string> labelMapFileNames(LabelMapFiles files) {
  std::vector<std::string> names;
  const nlohmann::json outputs = frame::outputFiles(files, false);  // held: items() refers to it
  for (const auto& [key, value] : outputs.items()) {
    if (key == "transform") continue;
    if (value.is_string()) names.push_back(value.get<std::string>());
    for (const auto& v : value)
      if (value.is_array() && v.is_string()) names.push_back(v.get<std::string>());
  }
  std::sort(names.begin(), names.end());
  names.erase(std::unique(names.begin(), names.end()), names.end());
  return names;
}

double posedBytesPerVoxel(const Volume& organs, const Volume& parts, const Volume* image) {
  return double(scalarSize(organs.scalarType())) + double(scalarSize(parts.scalarType())) + 12 +
         (image ? double(scalarSize(image->scalarType())) : 0);
}

bool frameFitsMemory(const VolumeGeometry& grid, double bytesPerVoxel, double budget) {
  if (budget <= 0) budget = memoryBudgetByDefault();
  if (budget <= 0) return true;
  return residentBytes() + double(grid.numVoxels()) * bytesPerVoxel <= budget;
}

void checkFrameMemory(const VolumeGeometry& grid, double bytesPerVoxel, double budget,
                      const std::string& what, const std::string& hint) {
  if (budget <= 0) budget = memoryBudgetByDefault();
  if (budget <= 0) return;  // physical memory unknown: no limit rather than refusing every job
  const double need = double(grid.numVoxels()) * bytesPerVoxel, inUse = residentBytes();
  if (inUse + need <= budget) return;
  throw Error(what + " needs " + gib(need) + " for " + std::to_string(grid.numVoxels()) +
              " output voxels beyond the " + gib(inUse) +
              " in use, more than the memory budget of " + gib(budget) + " (" + hint + ")");
}

double imageBackground(const Volume& image) {
  // NaN voxels (a float image's "no data") are not a background: the comparison skips them.
  double lowest = std::numeric_limits<double>::infinity();
  for (int layer = 0; layer < image.layers(); ++layer)
    dispatchScalar(image.scalarType(), [&](auto* tag) {
      using T = std::remove_pointer_t<decltype(tag)>;
      const T* v = image.data<T>(layer);
      for (std::int64_t i = 0, n = image.numVoxels(); i < n; ++i)
        if (double(v[i]) < lowest) lowest = double(v[i]);
    });
  return std::isfinite(lowest) ? lowest : 0.0;
}

PosedFrame poseFrame(const PoseRig& rig, std::size_t index, const Volume& organs,
                     const Volume& parts, const PoseFrameOptions& options) {
  frame::FrameStart start = frame::startFrame(rig, index, organs, parts, options);
  if (options.checkGrid) options.checkGrid(start.grid);
  return frame::poseFrameFrom(start, rig, organs, parts, options);
}

PosedFrame frame::poseFrameFrom(FrameStart& start, const PoseRig& rig, const Volume& organs,
                                const Volume& parts, const PoseFrameOptions& options) {
  const TransferMesh& mesh = rig.mesh();
  const Eigen::MatrixX3d& deformed = start.frame.deformed;
  PosedFrame out;
  out.name = start.frame.name;
  out.grid = start.grid;
  out.labelMapFiles = options.labelMapFiles;
  RasterOptions ro = frame::rasterOptions(start, organs, parts, options);
  ro.progress = options.progress;
  ro.preserveLabelVolumes = options.preserveLabelVolumes;
  RasterReport raster;
  out.organs = rasterizeLabels(organs, mesh, deformed, out.grid, ro, &raster);
  ro.progress = {};
  ro.preserveLabelVolumes = false;  // S's parts are as sampled: they only name where G's tissue is
  out.parts = rasterizeLabels(parts, mesh, deformed, out.grid, ro);
  out.field = rasterizeDisplacement(mesh, deformed, organs.geometry(), out.grid, ro);
  const std::vector<int> rigid = frame::rigidLabels(mesh, options);
  PocketReport pockets;
  if (options.fillPockets)
    pockets = fillPosePockets(out.organs, organs, out.field, &out.parts, rigid);
  if (options.image)
    out.image = rasterizeImage(
        *options.image, mesh, deformed, out.grid,
        options.background ? *options.background : imageBackground(*options.image), ro);
  PosedTally posed(organs, parts, &start.frame.handles, out.grid, options.threads);
  posed.countCollisions(rigid);
  posed.addWhole(out.organs, out.parts);
  out.reportJson = frame::frameReport(start, rig, organs, parts, options, raster, pockets, posed,
                                      out.image.has_value());
  return out;
}

std::string writePosedFrame(const PosedFrame& frame, const std::string& folder) {
  FrameWriteOptions options;
  options.labelMapFiles = frame.labelMapFiles;
  return writePosedFrame(frame, folder, options);
}

std::string writePosedFrame(const PosedFrame& frame, const std::string& folder,
                            const FrameWriteOptions& options) {
  const LabelMapFiles files = options.labelMapFiles;
  frame::FrameFolder out(folder, options.lockFolder);
  const std::filesystem::path& temp = out.temp();
  const bool nifti = files == LabelMapFiles::Nifti || files == LabelMapFiles::Both;
  const bool seg = files == LabelMapFiles::SegNrrd || files == LabelMapFiles::Both;
  const bool dcm = files == LabelMapFiles::DicomSeg;
  try {
    for (const auto& [map, stem] :
         {std::pair{&frame.organs, "posed_G"}, {&frame.parts, "posed_S"}}) {
      if (nifti) {
        writeVolume(*map, (temp / (std::string(stem) + ".nii.gz")).string());
        writeColorTable(*map, (temp / (std::string(stem) + ".ctbl")).string());
      }
      if (seg) writeVolume(*map, (temp / (std::string(stem) + ".seg.nrrd")).string());
      if (dcm) {
        WriteOptions w;
        w.sourceDicom = options.sourceDicom;
        writeVolume(*map, (temp / (std::string(stem) + ".dcm")).string(), w);
      }
    }
    if (frame.image) writeVolume(*frame.image, (temp / "posed_image.nii.gz").string());
    writeDisplacementFieldNrrd(frame.field, frame.grid, (temp / "transform.nrrd").string());
  } catch (const Cancelled&) {
    throw;
  } catch (const Error& e) {
    throw out.named(e);
  }
  return out.commit(nlohmann::json::parse(frame.reportJson), options, frame.image.has_value());
}

}  // namespace repose
