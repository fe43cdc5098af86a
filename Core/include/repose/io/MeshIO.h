// Triangle meshes (cages) as Wavefront OBJ or legacy VTK polydata (ASCII), the formats 3D
// Slicer's Models module and most mesh tools open. Coordinates are written in RAS mm.
#pragma once

#include "repose/cage/TriangleMesh.h"

#include <string>

namespace repose {

// By extension: .obj or .vtk. Atomic (temporary file, then rename).
void writeTriangleMesh(const TriangleMesh& mesh, const std::string& path);
// Reads triangles (polygons with more sides are fan-triangulated); errors name the file and line.
// A file whose first comment (.obj) or header line (.vtk) says SPACE=LPS, as 3D Slicer writes
// models, is converted to RAS; any other is read as RAS.
TriangleMesh readTriangleMesh(const std::string& path);

}  // namespace repose
