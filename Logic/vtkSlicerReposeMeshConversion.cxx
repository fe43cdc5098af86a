#include "vtkSlicerReposeMeshConversion.h"

#include <repose/util/Error.h>

#include <vtkCellArray.h>
#include <vtkCellData.h>
#include <vtkCellType.h>
#include <vtkDoubleArray.h>
#include <vtkFieldData.h>
#include <vtkIdList.h>
#include <vtkIntArray.h>
#include <vtkPoints.h>

namespace {
vtkSmartPointer<vtkPoints> toPoints(const Eigen::MatrixX3d& v) {
  auto points = vtkSmartPointer<vtkPoints>::New();
  points->SetDataTypeToDouble();
  points->SetNumberOfPoints(v.rows());
  for (Eigen::Index i = 0; i < v.rows(); ++i) points->SetPoint(i, v(i, 0), v(i, 1), v(i, 2));
  return points;
}
Eigen::MatrixX3d fromPoints(vtkPoints* points) {
  Eigen::MatrixX3d v(points ? points->GetNumberOfPoints() : 0, 3);
  for (Eigen::Index i = 0; i < v.rows(); ++i) {
    double p[3];
    points->GetPoint(i, p);
    v.row(i) << p[0], p[1], p[2];
  }
  return v;
}
}  // namespace

vtkSmartPointer<vtkPolyData> vtkSlicerReposeMeshConversion::ToPolyData(
    const repose::TriangleMesh& mesh) {
  auto poly = vtkSmartPointer<vtkPolyData>::New();
  poly->SetPoints(toPoints(mesh.vertices));
  vtkNew<vtkCellArray> triangles;
  for (Eigen::Index f = 0; f < mesh.faces.rows(); ++f) {
    const vtkIdType ids[3] = {mesh.faces(f, 0), mesh.faces(f, 1), mesh.faces(f, 2)};
    triangles->InsertNextCell(3, ids);
  }
  poly->SetPolys(triangles);
  return poly;
}

repose::TriangleMesh vtkSlicerReposeMeshConversion::FromPolyData(vtkPolyData* poly) {
  if (!poly) throw repose::Error("no cage mesh");
  repose::TriangleMesh mesh;
  mesh.vertices = fromPoints(poly->GetPoints());
  vtkCellArray* polys = poly->GetPolys();
  mesh.faces.resize(polys ? polys->GetNumberOfCells() : 0, 3);
  if (poly->GetNumberOfCells() != mesh.faces.rows())
    throw repose::Error("the cage mesh has cells that are not triangles");
  vtkNew<vtkIdList> ids;
  for (Eigen::Index f = 0; f < mesh.faces.rows(); ++f) {
    polys->GetCellAtId(f, ids);
    if (ids->GetNumberOfIds() != 3) throw repose::Error("the cage mesh has a non-triangle face");
    mesh.faces.row(f) << int(ids->GetId(0)), int(ids->GetId(1)), int(ids->GetId(2));
  }
  return mesh;
}

vtkSmartPointer<vtkUnstructuredGrid> vtkSlicerReposeMeshConversion::ToUnstructuredGrid(
    const repose::TransferMesh& mesh) {
  auto grid = vtkSmartPointer<vtkUnstructuredGrid>::New();
  grid->SetPoints(toPoints(mesh.vertices));
  grid->Allocate(mesh.tets.rows());
  for (Eigen::Index t = 0; t < mesh.tets.rows(); ++t) {
    const vtkIdType ids[4] = {mesh.tets(t, 0), mesh.tets(t, 1), mesh.tets(t, 2), mesh.tets(t, 3)};
    grid->InsertNextCell(VTK_TETRA, 4, ids);
  }
  vtkNew<vtkIntArray> labels;
  labels->SetName("label");
  labels->SetNumberOfValues(mesh.labels.size());
  for (Eigen::Index t = 0; t < mesh.labels.size(); ++t) labels->SetValue(t, mesh.labels[t]);
  grid->GetCellData()->SetScalars(labels);
  if (!mesh.rigid.empty()) {  // whole pieces (bones, organs): their label of G, else 0
    vtkNew<vtkIntArray> rigid;
    rigid->SetName("rigid");
    rigid->SetNumberOfValues(vtkIdType(mesh.rigid.size()));
    for (std::size_t t = 0; t < mesh.rigid.size(); ++t)
      rigid->SetValue(vtkIdType(t), mesh.rigid[t]);
    grid->GetCellData()->AddArray(rigid);
  }
  vtkNew<vtkDoubleArray> spacing;
  spacing->SetName("source_spacing_mm");
  spacing->InsertNextValue(mesh.sourceSpacingMm);
  grid->GetFieldData()->AddArray(spacing);
  return grid;
}

repose::TransferMesh vtkSlicerReposeMeshConversion::FromUnstructuredGrid(
    vtkUnstructuredGrid* grid) {
  if (!grid) throw repose::Error("no transfer mesh");
  repose::TransferMesh mesh;
  mesh.vertices = fromPoints(grid->GetPoints());
  const vtkIdType n = grid->GetNumberOfCells();
  mesh.tets.resize(n, 4);
  vtkDataArray* labels = grid->GetCellData()->GetArray("label");
  if (!labels || labels->GetNumberOfTuples() != n)
    throw repose::Error("the transfer mesh has no cell array 'label'");
  mesh.labels.resize(n);
  vtkNew<vtkIdList> ids;
  for (vtkIdType t = 0; t < n; ++t) {
    if (grid->GetCellType(t) != VTK_TETRA)
      throw repose::Error("the transfer mesh has a non-tet cell");
    grid->GetCellPoints(t, ids);
    for (int k = 0; k < 4; ++k) mesh.tets(t, k) = int(ids->GetId(k));
    mesh.labels[t] = int(labels->GetTuple1(t));
  }
  if (vtkDataArray* rigid = grid->GetCellData()->GetArray("rigid")) {
    if (rigid->GetNumberOfTuples() != n)
      throw repose::Error("the transfer mesh's cell array 'rigid' does not match its cells");
    mesh.rigid.resize(std::size_t(n));
    for (vtkIdType t = 0; t < n; ++t) mesh.rigid[std::size_t(t)] = int(rigid->GetTuple1(t));
  }
  if (vtkDataArray* s = grid->GetFieldData()->GetArray("source_spacing_mm"))
    if (s->GetNumberOfTuples() > 0) mesh.sourceSpacingMm = s->GetTuple1(0);
  return mesh;
}
