// Cage meshes: Wavefront OBJ and legacy VTK polydata (ASCII) through readTriangleMesh. Inputs
// starting with "# vtk" are read as .vtk, the rest as .obj.
#include "FuzzFiles.h"
#include "repose/cage/TriangleMesh.h"
#include "repose/io/MeshIO.h"

#include <cstring>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace repose;
  const bool vtk = size >= 5 && std::memcmp(data, "# vtk", 5) == 0;
  const std::string path = fuzz::writeInput(vtk ? "cage.vtk" : "cage.obj", data, size);
  try {
    const TriangleMesh mesh = readTriangleMesh(path);
    (void)mesh.faces.rows();
  } catch (const Error&) {
  }
  return 0;
}
