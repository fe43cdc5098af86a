// poseFrame: the one sequence every caller of a full-resolution frame runs (frame, grid, labels,
// field, pockets, report), so the command line, the module and Python write the same files.
#include "repose/pose/PoseFrame.h"

#include "repose/io/AtomicOutput.h"
#include "repose/io/NrrdIO.h"
#include "repose/io/VolumeIO.h"
#include "repose/pose/PoseReport.h"
#include "repose/raster/PocketFilling.h"
#include "repose/raster/Rasterizer.h"
#include "repose/util/Error.h"
#include "repose/util/Interrupt.h"

#include <nlohmann/json.hpp>

#include <cstdlib>
#include <filesystem>
#include <stdlib.h>
#include <set>

namespace repose {

double posedBytesPerVoxel(const Volume& organs, const Volume& parts, const Volume* image) {
  return double(scalarSize(organs.scalarType())) + double(scalarSize(parts.scalarType())) + 12 +
         (image ? double(scalarSize(image->scalarType())) : 0);
}

PosedFrame poseFrame(const PoseRig& rig, std::size_t index, const Volume& organs,
                     const Volume& parts, const PoseFrameOptions& options) {
  if (parts.dims() != organs.dims())
    throw Error("the body-part map is not on the organ map's grid");
  if (options.image && options.image->dims() != organs.dims())
    throw Error("the image is not on the organ map's grid");
  if (!(options.spacingMm >= 0)) throw Error("the output voxel size must be >= 0 mm");
  const PoseRig::Frame frame = rig.frame(index);
  const TransferMesh& mesh = rig.mesh();
  PosedFrame out;
  out.name = frame.name;
  out.grid = deformedGrid(organs.geometry(), frame.deformed, options.spacingMm);
  if (options.checkGrid) options.checkGrid(out.grid);
  const std::vector<std::uint8_t> outer = outerFaces(mesh);
  RasterOptions ro;
  ro.threads = options.threads;
  ro.progress = options.progress;
  ro.outerFaces = &outer;
  ro.restParts = &parts;
  ro.pieceLabels = &organs;
  RasterReport raster;
  out.organs = rasterizeLabels(organs, mesh, frame.deformed, out.grid, ro, &raster);
  ro.progress = {};
  out.parts = rasterizeLabels(parts, mesh, frame.deformed, out.grid, ro);
  out.field = rasterizeDisplacement(mesh, frame.deformed, organs.geometry(), out.grid, ro);
  PocketReport pockets;
  if (options.fillPockets) pockets = fillPosePockets(out.organs, organs, out.field, &out.parts);
  if (options.image)
    out.image =
        rasterizeImage(*options.image, mesh, frame.deformed, out.grid, options.background, ro);

  std::set<int> pieceLabels;
  std::int64_t pieceTets = 0;
  for (const int label : mesh.rigid)
    if (label != 0) pieceLabels.insert(label), ++pieceTets;
  std::vector<std::string> groupNames;
  for (const PoseGroup& g : rig.pose().groups) groupNames.push_back(g.name);
  PoseReportInput ri;
  ri.organs = &organs, ri.parts = &parts;
  ri.posedOrgans = &out.organs, ri.posedParts = &out.parts;
  ri.mesh = &mesh, ri.tetMaps = &frame.tetMaps, ri.handles = &frame.handles;
  ri.groupNames = groupNames;
  ri.tissues = options.tissues;
  ri.outlierVertices = rig.deformation().embedding().outliers();
  ri.unreachableVertices = rig.deformation().solver().unconstrainedVertices();
  ri.rigidVertices = rig.influence().rigidVertices();
  const Eigen::Vector3d spacing = out.grid.spacing();
  nlohmann::json outputs = {{"posed_labels", "posed_G.nii.gz"},
                            {"posed_parts", "posed_S.nii.gz"},
                            {"transform", "transform.nrrd"}};
  if (out.image) outputs["posed_image"] = "posed_image.nii.gz";
  nlohmann::json report = {
      {"pose", rig.pose().name},
      {"frame", out.name},
      {"outputs", outputs},
      {"grid",
       {{"dims", {out.grid.dims[0], out.grid.dims[1], out.grid.dims[2]}},
        {"spacing_mm", {spacing[0], spacing[1], spacing[2]}}}},
      {"cage_vertices", rig.cage().vertices.rows()},
      {"whole_pieces", {{"labels", pieceLabels}, {"tets", pieceTets}}},
      {"tissue_table", options.tissues ? options.tissueTableName : std::string("none")},
      {"voxels_in_shell", raster.shellVoxels},
      {"raster_inverted_tets", raster.invertedTets},
      {"pockets",
       {{"filled_voxels", pockets.filled},
        {"kept_cavity_voxels", pockets.keptCavities},
        {"filled", options.fillPockets}}}};
  report.update(nlohmann::json::parse(poseReportJson(ri)));
  out.reportJson = report.dump();
  return out;
}

void writePosedFrame(const PosedFrame& frame, const std::string& folder) {
  namespace fs = std::filesystem;
  fs::path dir = fs::absolute(fs::path(folder)).lexically_normal();
  if (!dir.has_filename()) dir = dir.parent_path();  // "OUT/frame/"
  if (!fs::exists(dir.parent_path())) throw Error(folder + ": its parent folder does not exist");
  // The frame's files are one result: written into a hidden folder beside `folder` and moved in
  // together at the end, so an error, a Cancel or an interrupt never leaves half a frame.
  std::string pattern = (dir.parent_path() / ".repose-tmp-XXXXXX").string();
  if (!::mkdtemp(pattern.data()))
    throwFileError(folder, "cannot write in the output folder's parent");
  const fs::path temp(pattern);
  struct RemoveOnExit {
    fs::path path;
    ~RemoveOnExit() {
      std::error_code ignored;
      fs::remove_all(path, ignored);
    }
  } cleanup{temp};
  writeVolume(frame.organs, (temp / "posed_G.nii.gz").string());
  writeVolume(frame.parts, (temp / "posed_S.nii.gz").string());
  if (frame.image) writeVolume(*frame.image, (temp / "posed_image.nii.gz").string());
  writeDisplacementFieldNrrd(frame.field, frame.grid, (temp / "transform.nrrd").string());
  writeTextFileAtomically((temp / "report.json").string(),
                          nlohmann::json::parse(frame.reportJson).dump(2) + "\n");
  throwIfInterrupted();
  std::error_code ec;
  if (!fs::exists(dir)) {
    fs::rename(temp, dir, ec);
    if (ec) throwFileError(folder, "cannot move the frame into place: " + ec.message());
    return;
  }
  // An existing folder (a re-run): its files are replaced one by one, the report last.
  for (const char* name :
       {"posed_G.nii.gz", "posed_S.nii.gz", "posed_image.nii.gz", "transform.nrrd", "report.json"})
    if (fs::exists(temp / name)) {
      fs::rename(temp / name, dir / name, ec);
      if (ec) throwFileError((dir / name).string(), "cannot move into place: " + ec.message());
    }
}

}  // namespace repose
