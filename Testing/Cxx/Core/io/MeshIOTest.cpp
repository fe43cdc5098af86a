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

// vtkMRMLModelStorageNode.cxx: Slicer writes a model in LPS by default with "SPACE=LPS" in the
// .obj's first comment (vtkOBJExporter::SetOBJFileComment) or the legacy .vtk's header line, and
// reads that tag back; a CLI module gets its models that way. Read as RAS: x and y negated.
TEST(MeshIO, SlicersLpsModelsAreReadInRas) {
  ScratchDir dir;
  // As vtkOBJExporter writes it: comment, material library, object, vertices, normals, faces.
  std::ofstream(dir.file("lps.obj"))
      << "# 3D Slicer output. SPACE=LPS\n\nmtllib lps.mtl\no mesh1\nv 10 -20 30\nv 11 -20 30\n"
         "v 10 -19 30\nvn 0 0 1\nvn 0 0 1\nvn 0 0 1\nusemtl mtl1\nf 1//1 2//2 3//3\n";
  const TriangleMesh obj = readTriangleMesh(dir.file("lps.obj"));
  EXPECT_EQ(obj.vertices.row(0), Eigen::RowVector3d(-10, 20, 30));
  EXPECT_EQ(obj.vertices.row(1), Eigen::RowVector3d(-11, 20, 30));
  std::ofstream(dir.file("lps.vtk"))
      << "# vtk DataFile Version 3.0\n3D Slicer output. SPACE=LPS\nASCII\nDATASET POLYDATA\n"
         "POINTS 3 float\n10 -20 30 11 -20 30 10 -19 30\nPOLYGONS 1 4\n3 0 1 2\n";
  EXPECT_EQ(readTriangleMesh(dir.file("lps.vtk")).vertices.row(2), Eigen::RowVector3d(-10, 19, 30));
  // RAS said, or nothing said: as written.
  std::ofstream(dir.file("ras.obj"))
      << "# SPACE=RAS\nv 10 -20 30\nv 11 -20 30\nv 10 -19 30\nf 1 2 3\n";
  EXPECT_EQ(readTriangleMesh(dir.file("ras.obj")).vertices.row(0), Eigen::RowVector3d(10, -20, 30));
  // Only the first comment counts (vtkOBJReader::GetComment).
  std::ofstream(dir.file("later.obj"))
      << "# a cage\n# SPACE=LPS\nv 10 -20 30\nv 11 -20 30\nv 10 -19 30\nf 1 2 3\n";
  EXPECT_EQ(readTriangleMesh(dir.file("later.obj")).vertices.row(0),
            Eigen::RowVector3d(10, -20, 30));
}
