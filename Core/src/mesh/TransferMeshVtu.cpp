// The transfer mesh as a VTK XML unstructured grid (ASCII), readable by ParaView, 3D Slicer and
// VTK's vtkXMLUnstructuredGridReader; the reader here reads this layout back, not every VTU.
#include "repose/io/AtomicOutput.h"
#include "repose/mesh/TransferMesh.h"
#include "repose/util/Error.h"

#include <cmath>
#include <fstream>
#include <iomanip>
#include <sstream>

namespace repose {
namespace {

// The whitespace-separated numbers inside the <DataArray ... Name="name"> element.
std::istringstream dataArray(const std::string& xml, const std::string& name,
                             const std::string& path) {
  const std::size_t tag = xml.find("Name=\"" + name + "\"");
  if (tag == std::string::npos) throwFileError(path, "no DataArray named " + name);
  const std::size_t open = xml.rfind("<DataArray", tag), start = xml.find('>', tag),
                    end = xml.find("</DataArray>", tag);
  if (open == std::string::npos || start == std::string::npos || end == std::string::npos ||
      start > end)
    throwFileError(path, "malformed DataArray " + name);
  const std::string header = xml.substr(open, start - open);
  if (header.find("format=\"ascii\"") == std::string::npos)
    throwFileError(
        path, "DataArray " + name + " is not ASCII (binary and appended VTU are not supported)");
  return std::istringstream(xml.substr(start + 1, end - start - 1));
}

long attribute(const std::string& xml, const std::string& name, const std::string& path) {
  const std::size_t at = xml.find(name + "=\"");
  if (at == std::string::npos) throwFileError(path, "missing " + name);
  return std::strtol(xml.c_str() + at + name.size() + 2, nullptr, 10);
}

}  // namespace

void writeTransferMesh(const TransferMesh& mesh, const std::string& path) {
  AtomicOutput output(path);
  {
    std::ofstream out(output.tempPath());
    if (!out) throwFileError(path, "cannot create the file");
    out << std::setprecision(17);
    out << "<?xml version=\"1.0\"?>\n<!-- Repose transfer mesh: RAS millimetres, cell arrays "
           "'label' (body part) and 'rigid' (bone label or 0) -->\n"
        << "<VTKFile type=\"UnstructuredGrid\" version=\"0.1\" "
           "byte_order=\"LittleEndian\">\n<UnstructuredGrid>\n"
        << "<FieldData>\n<DataArray type=\"Float64\" Name=\"source_spacing_mm\" "
           "NumberOfTuples=\"1\" format=\"ascii\">\n"
        << mesh.sourceSpacingMm
        << "\n</DataArray>\n"
        // 3D Slicer reads a .vtu's coordinate system from the field-data string array "SPACE"
        // (vtkMRMLModelStorageNode::GetCoordinateSystemFromFieldData; without it: LPS). VTK's
        // ASCII string arrays hold character codes, each string ending in 0.
        << "<Array type=\"String\" Name=\"SPACE\" NumberOfTuples=\"1\" format=\"ascii\">\n"
           "82 65 83 0\n</Array>\n</FieldData>\n"
        << "<Piece NumberOfPoints=\"" << mesh.vertices.rows() << "\" NumberOfCells=\""
        << mesh.tets.rows() << "\">\n"
        << "<Points>\n<DataArray type=\"Float64\" Name=\"Points\" NumberOfComponents=\"3\" "
           "format=\"ascii\">\n";
    for (Eigen::Index v = 0; v < mesh.vertices.rows(); ++v)
      out << mesh.vertices(v, 0) << " " << mesh.vertices(v, 1) << " " << mesh.vertices(v, 2)
          << "\n";
    out << "</DataArray>\n</Points>\n<Cells>\n<DataArray type=\"Int64\" Name=\"connectivity\" "
           "format=\"ascii\">\n";
    for (Eigen::Index t = 0; t < mesh.tets.rows(); ++t)
      out << mesh.tets(t, 0) << " " << mesh.tets(t, 1) << " " << mesh.tets(t, 2) << " "
          << mesh.tets(t, 3) << "\n";
    out << "</DataArray>\n<DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">\n";
    for (Eigen::Index t = 0; t < mesh.tets.rows(); ++t) out << 4 * (t + 1) << "\n";
    out << "</DataArray>\n<DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">\n";
    for (Eigen::Index t = 0; t < mesh.tets.rows(); ++t) out << "10\n";  // VTK_TETRA
    out << "</DataArray>\n</Cells>\n<CellData Scalars=\"label\">\n<DataArray type=\"Int32\" "
           "Name=\"label\" format=\"ascii\">\n";
    for (Eigen::Index t = 0; t < mesh.labels.size(); ++t) out << mesh.labels[t] << "\n";
    if (!mesh.rigid.empty()) {
      out << "</DataArray>\n<DataArray type=\"Int32\" Name=\"rigid\" format=\"ascii\">\n";
      for (const int r : mesh.rigid) out << r << "\n";
    }
    out << "</DataArray>\n</CellData>\n</Piece>\n</UnstructuredGrid>\n</VTKFile>\n";
    if (!out.flush()) throwFileError(path, "write failed (disk full?)");
  }
  output.commit();
}

TransferMesh readTransferMesh(const std::string& path) {
  std::ifstream in(path);
  if (!in) throwFileError(path, "file not found or unreadable");
  const std::string xml((std::istreambuf_iterator<char>(in)), {});
  if (xml.find("<VTKFile") == std::string::npos ||
      xml.find("UnstructuredGrid") == std::string::npos)
    throwFileError(path, "not a VTK XML unstructured grid (.vtu)");
  const long points = attribute(xml, "NumberOfPoints", path),
             cells = attribute(xml, "NumberOfCells", path);
  if (points <= 0 || cells <= 0) throwFileError(path, "no points or no cells");
  TransferMesh mesh;
  mesh.vertices.resize(points, 3);
  auto p = dataArray(xml, "Points", path);
  for (long v = 0; v < points; ++v)
    if (!(p >> mesh.vertices(v, 0) >> mesh.vertices(v, 1) >> mesh.vertices(v, 2)))
      throwFileError(path, "truncated Points");
  mesh.tets.resize(cells, 4);
  auto c = dataArray(xml, "connectivity", path);
  for (long t = 0; t < cells; ++t)
    for (int k = 0; k < 4; ++k)
      if (!(c >> mesh.tets(t, k)))
        throwFileError(path, "truncated connectivity (only tetrahedra are supported)");
  auto types = dataArray(xml, "types", path);
  for (long t = 0; t < cells; ++t) {
    int type = 0;
    if (!(types >> type) || type != 10)
      throwFileError(path, "cell " + std::to_string(t) + " is not a tetrahedron");
  }
  mesh.labels.resize(cells);
  auto l = dataArray(xml, "label", path);
  for (long t = 0; t < cells; ++t)
    if (!(l >> mesh.labels[t])) throwFileError(path, "truncated label array");
  if (xml.find("Name=\"rigid\"") != std::string::npos) {  // optional: meshes with bone subdomains
    mesh.rigid.resize(static_cast<std::size_t>(cells));
    auto r = dataArray(xml, "rigid", path);
    for (long t = 0; t < cells; ++t) {
      if (!(r >> mesh.rigid[static_cast<std::size_t>(t)]) || mesh.rigid[std::size_t(t)] < 0)
        throwFileError(path, "truncated or negative rigid array");
    }
  }
  if (xml.find("Name=\"source_spacing_mm\"") != std::string::npos) {  // optional (older files)
    auto f = dataArray(xml, "source_spacing_mm", path);
    if (!(f >> mesh.sourceSpacingMm) || !(mesh.sourceSpacingMm >= 0))
      throwFileError(path, "bad source_spacing_mm");
  }
  if (mesh.tets.minCoeff() < 0 || mesh.tets.maxCoeff() >= points)
    throwFileError(path, "a cell uses a point that does not exist");
  if (!mesh.vertices.allFinite()) throwFileError(path, "point coordinates are not finite");
  // The solver needs every tet's rest shape invertible and the rasterizer its orientation: a flat
  // or inside-out tet (a hand-edited or foreign file; `repose mesh` removes and reorients them) is
  // refused here, naming it, rather than deep in a solve. Flat: below 1e-9 of the mean volume.
  double mean = 0;
  for (Eigen::Index t = 0; t < mesh.tets.rows(); ++t)
    mean += std::fabs(tetVolume(mesh.vertices, mesh.tets.row(t))) / double(mesh.tets.rows());
  for (Eigen::Index t = 0; t < mesh.tets.rows(); ++t) {
    const double v = tetVolume(mesh.vertices, mesh.tets.row(t));
    if (!(v > 1e-9 * mean)) {
      std::ostringstream m;
      m.precision(3);
      m << "tet " << t << (v < 0 ? " is inside out" : " is flat") << " (volume " << v
        << " mm3); rebuild the mesh with `repose mesh`";
      throwFileError(path, m.str());
    }
  }
  return mesh;
}

}  // namespace repose
