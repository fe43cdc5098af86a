// Cage files: OBJ and legacy VTK round trips, polygons fan-triangulated, bad files refused.
#include "TestMeshes.h"
#include "TestPaths.h"

#include "repose/io/MeshIO.h"
#include "repose/util/Error.h"

#include <gtest/gtest.h>

#include <fstream>

using namespace repose;
using namespace repose::test;

TEST(MeshIO, RoundTripsObjAndVtk) {
  ScratchDir dir;
  const TriangleMesh m = sphereMesh({1.5, -2.25, 100}, 37.125, 2);
  for (const char* name : {"c.obj", "c.vtk"}) {
    writeTriangleMesh(m, dir.file(name));
    const TriangleMesh r = readTriangleMesh(dir.file(name));
    EXPECT_EQ(r.faces, m.faces) << name;
    EXPECT_LT((r.vertices - m.vertices).cwiseAbs().maxCoeff(), 1e-6) << name;
  }
}

TEST(MeshIO, QuadsAreTriangulatedAndBadFilesRefused) {
  ScratchDir dir;
  std::ofstream(dir.file("quad.obj")) << "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n";
  EXPECT_EQ(readTriangleMesh(dir.file("quad.obj")).faces.rows(), 2);
  std::ofstream(dir.file("badindex.obj")) << "v 0 0 0\nv 1 0 0\nv 1 1 0\nf 1 2 9\n";
  EXPECT_THROW(readTriangleMesh(dir.file("badindex.obj")), Error);
  std::ofstream(dir.file("empty.obj")) << "# nothing\n";
  EXPECT_THROW(readTriangleMesh(dir.file("empty.obj")), Error);
  std::ofstream(dir.file("trunc.vtk"))
      << "# vtk DataFile Version 3.0\nx\nASCII\nDATASET POLYDATA\nPOINTS 3 float\n0 0 0 1";
  EXPECT_THROW(readTriangleMesh(dir.file("trunc.vtk")), Error);
  // Regression (Testing/Fuzz/FuzzMesh): counts are not allocations. These asked for 24 GB and
  // 8 GB before the first value was read; now they fail at the end of the file.
  std::ofstream(dir.file("hugecount.vtk"))
      << "# vtk DataFile Version 3.0\nx\nASCII\nDATASET POLYDATA\nPOINTS 999999995 float\n0 0 0\n";
  EXPECT_THROW(readTriangleMesh(dir.file("hugecount.vtk")), Error);
  std::ofstream(dir.file("hugepolygon.vtk")) << "# vtk DataFile Version 3.0\nx\nASCII\nDATASET "
                                                "POLYDATA\nPOINTS 3 float\n0 0 0 1 0 0 0 1 0\n"
                                             << "POLYGONS 1 4\n2000000000 0 1 2\n";
  EXPECT_THROW(readTriangleMesh(dir.file("hugepolygon.vtk")), Error);
  EXPECT_THROW(readTriangleMesh(dir.file("missing.obj")), Error);
  EXPECT_THROW(writeTriangleMesh(sphereMesh({0, 0, 0}, 1, 0), dir.file("x.stl")), Error);
}
