"""What 3D Slicer needs to open Repose's files as their users expect (issue 22), checked with the
readers Slicer itself builds on (VTK's, from Debian's python3-vtk9) and against the rules of
Slicer's own source (Slicer/Slicer, named in each test):

- transform.nrrd opens as a transform, not a vector volume, in the direction Repose means;
- cage (.obj, .vtk) and transfer-mesh (.vtu) files say they are in RAS, so they do not open
  mirrored (Slicer's default for a model file without the tag is LPS).
"""
import gzip
import json
import pathlib

import numpy as np
import pytest
import vtk

REPO = pathlib.Path(__file__).resolve().parents[2]


def nrrd_header(path):
    raw = path.read_bytes()
    return raw[:raw.index(b"\n\n")].decode()


@pytest.fixture(scope="module")
def posed(tmp_path_factory, bin_dir):
    """An 8 mm phantom, its cage and mesh, and the left elbow flexed 90 degrees."""
    import subprocess
    out = tmp_path_factory.mktemp("slicer")

    def run(*args):
        r = subprocess.run([str(bin_dir / "repose"), *map(str, args)], capture_output=True,
                           text=True)
        assert r.returncode == 0, r.stderr

    run("phantom", "--voxel", "8", "--out", out)
    run("cage", "--parts", out / "S.nii.gz", "--out", out / "cage.obj")
    run("cage", "--parts", out / "S.nii.gz", "--out", out / "cage.vtk")
    run("mesh", "--parts", out / "S.nii.gz", "--cage", out / "cage.obj", "--out", out / "tm.vtu")
    run("pose", "--input", out / "G.nii.gz", "--parts", out / "S.nii.gz", "--pose",
        REPO / "bench" / "poses" / "elbow90.pose.json", "--out", out / "elbow90")
    return out


def test_the_field_opens_as_a_resampling_transform(posed):
    # Modules/Loadable/Transforms/qSlicerTransformsReader.cxx: a 3D vector image is a transform
    # (confidence 0.6, above the volumes reader's 0.55) only when its `intent_code` is "1006".
    # Libs/MRML/Core/vtkMRMLTransformStorageNode.cxx: "displacement field type" resampling is a
    # transform from parent (output -> input), read without inverting; a measurement frame
    # other than the identity is refused.
    header = nrrd_header(posed / "elbow90" / "transform.nrrd").splitlines()
    assert "intent_code:=1006" in header
    assert "displacement field type:=resampling" in header
    assert "measurement frame: (1,0,0) (0,1,0) (0,0,1)" in header
    assert "space: left-posterior-superior" in header
    assert "kinds: vector domain domain domain" in header


def test_the_field_stays_within_the_input_grid_size(posed):
    # vtkITKTransformConverter.h sets a grid read from a file to cubic interpolation: a vector
    # that jumps metres beside the skin throws tissue far away between voxel centres. Voxels
    # outside the body point just past the input grid instead (the exact rule:
    # Rasterizer.UncoveredVoxelsPointJustPastTheInputGrid).
    import nibabel as nib
    header = nrrd_header(posed / "elbow90" / "transform.nrrd")
    fields = dict(line.split(": ", 1) for line in header.splitlines()[1:] if ": " in line)
    raw = (posed / "elbow90" / "transform.nrrd").read_bytes()
    data = raw[raw.index(b"\n\n") + 2:]
    if fields["encoding"] == "gzip":
        data = gzip.decompress(data)
    sizes = [int(x) for x in fields["sizes"].split()]
    vectors = np.frombuffer(data, dtype="<f4").reshape(-1, 3).astype(np.float64)
    posed_g = nib.load(posed / "elbow90" / "posed_G.nii.gz")
    assert list(posed_g.shape) == sizes[1:]
    nx, ny, nz = posed_g.shape
    k, j, i = np.meshgrid(np.arange(nz), np.arange(ny), np.arange(nx), indexing="ij")
    ijk = np.stack([i, j, k], axis=-1).reshape(-1, 3).astype(np.float64)
    ras = ijk @ posed_g.affine[:3, :3].T + posed_g.affine[:3, 3]
    target = ras + vectors * np.array([-1.0, -1.0, 1.0])  # LPS vectors
    g = nib.load(posed / "G.nii.gz")
    src = (target - g.affine[:3, 3]) @ np.linalg.inv(g.affine[:3, :3]).T
    r = np.floor(src + 0.5)
    off = np.any((r < 0) | (r >= np.array(g.shape)), axis=1)
    body = np.asarray(posed_g.dataobj).transpose(2, 1, 0).reshape(-1) != 0
    # Off the grid: the outside, and the pockets a bend traps, which are filled afterwards.
    report = json.loads((posed / "elbow90" / "report.json").read_text())
    assert off.sum() > 0 and np.sum(off & body) <= report["pockets"]["filled_voxels"]
    # Every vector within the two grids' size (it was ten diagonals and a metre), and a target
    # off the grid at most one voxel centre past it (unless it stays put, a voxel beyond already).
    diagonal = lambda img: np.linalg.norm(np.array(img.shape) * np.linalg.norm(img.affine[:3, :3],
                                                                                axis=0))
    longest = np.linalg.norm(vectors, axis=1).max()
    assert longest <= diagonal(g) + diagonal(posed_g), longest
    beyond = np.maximum(-1 - src, src - np.array(g.shape)).max(axis=1)
    moved = off & (np.linalg.norm(vectors, axis=1) > 0)
    assert np.all(beyond[moved] <= 1e-3), beyond[moved].max()
    assert np.all(beyond[off & ~moved] >= 0)


def test_cage_files_say_ras(posed):
    # Libs/MRML/Core/vtkMRMLModelStorageNode.cxx, GetCoordinateSystemFromFileHeader: "SPACE=RAS"
    # in vtkOBJReader's comment (the file's first comment) or vtkPolyDataReader's header line;
    # without it a model file is read as LPS and the cage opens mirrored.
    obj = vtk.vtkOBJReader()
    obj.SetFileName(str(posed / "cage.obj"))
    obj.Update()
    assert "SPACE=RAS" in obj.GetComment()
    assert obj.GetOutput().GetNumberOfPoints() > 0
    legacy = vtk.vtkPolyDataReader()
    legacy.SetFileName(str(posed / "cage.vtk"))
    legacy.Update()
    assert "SPACE=RAS" in legacy.GetHeader()
    assert legacy.GetOutput().GetNumberOfPoints() == obj.GetOutput().GetNumberOfPoints()


def test_transfer_mesh_says_ras(posed):
    # vtkMRMLModelStorageNode.cxx, GetCoordinateSystemFromFieldData: a .vtu's coordinate system
    # is the field-data string array named "SPACE" (its first value holding "RAS" or "LPS").
    reader = vtk.vtkXMLUnstructuredGridReader()
    reader.SetFileName(str(posed / "tm.vtu"))
    reader.Update()
    grid = reader.GetOutput()
    space = grid.GetFieldData().GetAbstractArray("SPACE")
    assert space is not None and space.GetValue(0) == "RAS"
    assert grid.GetNumberOfCells() > 0
    assert grid.GetCellData().GetArray("label") is not None
