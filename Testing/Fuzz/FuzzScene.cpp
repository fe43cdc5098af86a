// Scene folders: the input is scene.json; the folder also holds a valid cage, transfer mesh and
// pose (written once), so a scene.json that names them reaches every part of readSceneFolder.
#include "FuzzFiles.h"
#include "repose/cage/TriangleMesh.h"
#include "repose/io/MeshIO.h"
#include "repose/mesh/TransferMesh.h"
#include "repose/pose/SceneFolder.h"

namespace {

void writeCompanions(const std::filesystem::path& folder) {
  using namespace repose;
  // A unit cube cage and the five-tet cube as the transfer mesh.
  TriangleMesh cage;
  cage.vertices.resize(8, 3);
  for (int i = 0; i < 8; ++i)
    cage.vertices.row(i) << double(i & 1), double((i >> 1) & 1), double((i >> 2) & 1);
  cage.faces.resize(12, 3);
  cage.faces << 0, 2, 1, 1, 2, 3, 4, 5, 6, 5, 7, 6, 0, 1, 4, 1, 5, 4, 2, 6, 3, 3, 6, 7, 0, 4, 2, 2,
      4, 6, 1, 3, 5, 3, 7, 5;
  writeTriangleMesh(cage, (folder / "cage.vtk").string());
  TransferMesh tm;
  tm.vertices = cage.vertices;
  tm.tets.resize(5, 4);
  tm.tets << 0, 1, 2, 4, 1, 3, 2, 7, 1, 4, 5, 7, 2, 4, 7, 6, 1, 2, 4, 7;
  for (int t = 0; t < 5; ++t)
    if (tetVolume(tm.vertices, tm.tets.row(t)) < 0) std::swap(tm.tets(t, 2), tm.tets(t, 3));
  tm.labels = Eigen::VectorXi::Ones(5);
  writeTransferMesh(tm, (folder / "tm.vtu").string());
  std::filesystem::copy_file(std::string(REPOSE_SOURCE_DIR) + "/bench/poses/elbow90.pose.json",
                             folder / "elbow90.pose.json",
                             std::filesystem::copy_options::overwrite_existing);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace repose;
  static const bool ready = [] {
    const auto folder = fuzz::workFolder() / "scene";
    std::filesystem::create_directories(folder);
    writeCompanions(folder);
    return true;
  }();
  (void)ready;
  fuzz::writeInput("scene/scene.json", data, size);
  try {
    const SceneContents scene = readSceneFolder((fuzz::workFolder() / "scene").string());
    (void)scene.geometry;
  } catch (const Error&) {
  }
  return 0;
}
