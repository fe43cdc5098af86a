// OBJ and legacy-VTK triangle meshes. Hand-written because both are a few lines of text and Core
// does not link VTK; the VTK file carries a "RAS" header comment (Slicer reads legacy files as
// LPS unless told, so the cage files say which convention they use).
#include "repose/io/MeshIO.h"

#include "repose/io/AtomicOutput.h"
#include "repose/util/Error.h"

#include <algorithm>
#include <fstream>
#include <iomanip>
#include <sstream>
#include <vector>

namespace repose {
namespace {

bool endsWith(const std::string& s, const std::string& suffix) {
  return s.size() >= suffix.size() &&
         s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

TriangleMesh assemble(const std::vector<Eigen::Vector3d>& v, const std::vector<Eigen::Vector3i>& f,
                      const std::string& path) {
  if (v.empty() || f.empty()) throwFileError(path, "no triangles");
  TriangleMesh m;
  m.vertices.resize(v.size(), 3);
  for (std::size_t i = 0; i < v.size(); ++i) m.vertices.row(i) = v[i];
  m.faces.resize(f.size(), 3);
  for (std::size_t i = 0; i < f.size(); ++i) {
    if (f[i].minCoeff() < 0 || f[i].maxCoeff() >= static_cast<int>(v.size()))
      throwFileError(path, "face " + std::to_string(i) + " uses a vertex that does not exist");
    m.faces.row(i) = f[i];
  }
  if (!m.vertices.allFinite()) throwFileError(path, "vertex coordinates are not finite");
  return m;
}

// 3D Slicer's rule for a model file (vtkMRMLModelStorageNode::GetCoordinateSystemFromFileHeader):
// the header or first comment says SPACE=RAS or SPACE=LPS. Slicer writes LPS by default (so does
// every model it hands a CLI module); files without the tag are read as RAS, Repose's own
// convention (docs/FORMATS.md).
bool saysLps(const std::string& header) {
  return header.find("SPACE=LPS") != std::string::npos;
}

TriangleMesh toRas(TriangleMesh mesh, bool lps) {
  if (lps) mesh.vertices.leftCols(2) *= -1.0;
  return mesh;
}

TriangleMesh readObj(const std::string& path, std::istream& in) {
  std::vector<Eigen::Vector3d> v;
  std::vector<Eigen::Vector3i> f;
  std::string line;
  bool lps = false, firstComment = true;
  for (int number = 1; std::getline(in, line); ++number) {
    std::istringstream s(line);
    std::string tag;
    s >> tag;
    if (!tag.empty() && tag[0] == '#' && firstComment) {  // vtkOBJReader::GetComment: the first
      lps = saysLps(line);
      firstComment = false;
    }
    if (tag == "v") {
      Eigen::Vector3d p;
      if (!(s >> p.x() >> p.y() >> p.z()))
        throwFileError(path, "line " + std::to_string(number) + ": bad vertex");
      v.push_back(p);
    } else if (tag == "f") {
      std::vector<int> idx;
      std::string item;
      while (s >> item) {
        const int i = std::atoi(item.c_str());  // "7", "7/1", "7//3": the vertex index comes first
        if (i == 0)
          throwFileError(path,
                         "line " + std::to_string(number) + ": bad face index '" + item + "'");
        idx.push_back(i > 0 ? i - 1 : static_cast<int>(v.size()) + i);
      }
      if (idx.size() < 3)
        throwFileError(path, "line " + std::to_string(number) + ": a face needs 3 vertices");
      for (std::size_t k = 1; k + 1 < idx.size(); ++k) f.emplace_back(idx[0], idx[k], idx[k + 1]);
    }
  }
  return toRas(assemble(v, f, path), lps);
}

TriangleMesh readVtk(const std::string& path, std::istream& in) {
  std::vector<Eigen::Vector3d> v;
  std::vector<Eigen::Vector3i> f;
  // The header line (the second) carries the coordinate system (vtkPolyDataReader::GetHeader).
  std::string version, header;
  std::getline(in, version);
  std::getline(in, header);
  const bool lps = saysLps(header);
  std::string word;
  bool ascii = false;
  while (in >> word) {
    if (word == "ASCII") ascii = true;
    if (word == "BINARY")
      throwFileError(path, "binary legacy VTK is not supported; save as ASCII or OBJ");
    if (word == "POINTS") {
      std::size_t n;
      std::string type;
      if (!(in >> n >> type)) throwFileError(path, "bad POINTS header");
      // Counts come from the file: grow with what is actually read, never allocate by them
      // (a corrupt count of 1e9 asked for 24 GB: found by Testing/Fuzz/FuzzMesh).
      v.clear();
      v.reserve(std::min<std::size_t>(n, 1 << 16));
      for (std::size_t i = 0; i < n; ++i) {
        Eigen::Vector3d p;
        if (!(in >> p.x() >> p.y() >> p.z())) throwFileError(path, "truncated POINTS");
        v.push_back(p);
      }
    } else if (word == "POLYGONS") {
      std::size_t n, total;
      if (!(in >> n >> total)) throwFileError(path, "bad POLYGONS header");
      for (std::size_t c = 0; c < n; ++c) {
        int k;
        if (!(in >> k) || k < 3) throwFileError(path, "bad polygon " + std::to_string(c));
        std::vector<int> idx;
        for (int j = 0; j < k; ++j) {
          int i;
          if (!(in >> i)) throwFileError(path, "truncated POLYGONS");
          idx.push_back(i);
        }
        for (int t = 1; t + 1 < k; ++t) f.emplace_back(idx[0], idx[t], idx[t + 1]);
      }
    }
  }
  if (!ascii) throwFileError(path, "not an ASCII legacy VTK file");
  return toRas(assemble(v, f, path), lps);
}

}  // namespace

void writeTriangleMesh(const TriangleMesh& mesh, const std::string& path) {
  const bool obj = endsWith(path, ".obj"), vtk = endsWith(path, ".vtk");
  if (!obj && !vtk) throwFileError(path, "unknown mesh file type (expected .obj or .vtk)");
  AtomicOutput output(path);
  {
    std::ofstream out(output.tempPath());
    if (!out) throwFileError(path, "cannot create the file");
    out << std::setprecision(17);
    if (obj) {
      // 3D Slicer takes a model's coordinate system from the first comment of an .obj
      // (vtkMRMLModelStorageNode::GetCoordinateSystemFromFileHeader: "SPACE=RAS"); else LPS.
      out << "# Repose cage, SPACE=RAS, millimetres, outward faces\n";
      for (Eigen::Index i = 0; i < mesh.vertices.rows(); ++i)
        out << "v " << mesh.vertices(i, 0) << " " << mesh.vertices(i, 1) << " "
            << mesh.vertices(i, 2) << "\n";
      for (Eigen::Index i = 0; i < mesh.faces.rows(); ++i)
        out << "f " << mesh.faces(i, 0) + 1 << " " << mesh.faces(i, 1) + 1 << " "
            << mesh.faces(i, 2) + 1 << "\n";
    } else {
      out << "# vtk DataFile Version 3.0\nRepose cage, SPACE=RAS, millimetres\nASCII\nDATASET "
             "POLYDATA\n";
      out << "POINTS " << mesh.vertices.rows() << " double\n";
      for (Eigen::Index i = 0; i < mesh.vertices.rows(); ++i)
        out << mesh.vertices(i, 0) << " " << mesh.vertices(i, 1) << " " << mesh.vertices(i, 2)
            << "\n";
      out << "POLYGONS " << mesh.faces.rows() << " " << 4 * mesh.faces.rows() << "\n";
      for (Eigen::Index i = 0; i < mesh.faces.rows(); ++i)
        out << "3 " << mesh.faces(i, 0) << " " << mesh.faces(i, 1) << " " << mesh.faces(i, 2)
            << "\n";
    }
    if (!out.flush()) throwFileError(path, "write failed (disk full?)");
  }
  output.commit();
}

TriangleMesh readTriangleMesh(const std::string& path) {
  std::ifstream in(path);
  if (!in) throwFileError(path, "file not found or unreadable");
  if (endsWith(path, ".obj")) return readObj(path, in);
  if (endsWith(path, ".vtk")) return readVtk(path, in);
  throwFileError(path, "unknown mesh file type (expected .obj or .vtk)");
}

}  // namespace repose
