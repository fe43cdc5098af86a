#!/usr/bin/python3
"""Baseline for the preprocessing figure of bench/run_bench.py: the 3D surface 3D Slicer builds
to show a segmentation ("Show 3D": discrete flying edges over every label, windowed-sinc
smoothing at Slicer's default smoothing factor 0.5, normals), with VTK's own filters, on the
same label map file. Prints one JSON line: labels, triangles, seconds (reading included, as the
Repose side includes reading its input)."""
import json
import sys
import time

import numpy as np
from vtkmodules.util.numpy_support import vtk_to_numpy
from vtkmodules.vtkFiltersCore import vtkPolyDataNormals, vtkWindowedSincPolyDataFilter
from vtkmodules.vtkFiltersGeneral import vtkDiscreteFlyingEdges3D
from vtkmodules.vtkIOImage import vtkNIFTIImageReader


def main(path):
    start = time.perf_counter()
    reader = vtkNIFTIImageReader()
    reader.SetFileName(path)
    reader.Update()
    scalars = vtk_to_numpy(reader.GetOutput().GetPointData().GetScalars())
    labels = [int(v) for v in np.flatnonzero(np.bincount(scalars.ravel())) if v != 0]
    surface = vtkDiscreteFlyingEdges3D()
    surface.SetInputConnection(reader.GetOutputPort())
    for i, label in enumerate(labels):
        surface.SetValue(i, label)
    surface.ComputeNormalsOff()
    surface.ComputeGradientsOff()
    # Slicer's vtkBinaryLabelmapToClosedSurfaceConversionRule with smoothing factor 0.5.
    smoother = vtkWindowedSincPolyDataFilter()
    smoother.SetInputConnection(surface.GetOutputPort())
    smoother.SetNumberOfIterations(20)
    smoother.SetPassBand(10.0 ** (-4.0 * 0.5))
    smoother.BoundarySmoothingOff()
    smoother.FeatureEdgeSmoothingOff()
    smoother.NonManifoldSmoothingOn()
    smoother.NormalizeCoordinatesOn()
    normals = vtkPolyDataNormals()
    normals.SetInputConnection(smoother.GetOutputPort())
    normals.ConsistencyOn()
    normals.SplittingOff()
    normals.Update()
    seconds = time.perf_counter() - start
    print(json.dumps({"labels": len(labels),
                      "triangles": normals.GetOutput().GetNumberOfPolys(),
                      "seconds": seconds}))


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit("usage: slicer_surface_baseline.py LABELMAP.nii[.gz]")
    main(sys.argv[1])
