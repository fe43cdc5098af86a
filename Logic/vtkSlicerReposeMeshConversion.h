// Core <-> VTK conversion of the cage (repose::TriangleMesh <-> vtkPolyData of triangles) and the
// transfer mesh (repose::TransferMesh <-> vtkUnstructuredGrid of tets with the cell array "label"
// and the field array "source_spacing_mm"), exact in both directions.
#pragma once

#include "vtkSlicerReposeModuleLogicExport.h"

#include <repose/cage/TriangleMesh.h>
#include <repose/mesh/TransferMesh.h>

#include <vtkPolyData.h>
#include <vtkSmartPointer.h>
#include <vtkUnstructuredGrid.h>

class VTK_SLICER_REPOSE_MODULE_LOGIC_EXPORT vtkSlicerReposeMeshConversion {
 public:
  static vtkSmartPointer<vtkPolyData> ToPolyData(const repose::TriangleMesh& mesh);
  // Throws repose::Error for a null mesh or a cell that is not a triangle.
  static repose::TriangleMesh FromPolyData(vtkPolyData* mesh);
  static vtkSmartPointer<vtkUnstructuredGrid> ToUnstructuredGrid(const repose::TransferMesh& mesh);
  // Throws repose::Error for a null grid, a cell that is not a tet or a missing "label" array.
  static repose::TransferMesh FromUnstructuredGrid(vtkUnstructuredGrid* grid);
};
