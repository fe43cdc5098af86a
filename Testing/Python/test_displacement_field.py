"""The exported displacement field, applied by a tool we did not write (scipy's map_coordinates,
nearest neighbour), must reproduce `repose warp`'s posed label map: the field follows ITK's
convention (LPS vectors, from each output voxel to where the input is sampled)."""
import gzip
import json

import nibabel as nib
import numpy as np
from scipy import ndimage


def read_nrrd(path):
    raw = path.read_bytes()
    end = raw.index(b"\n\n")
    fields = {}
    for line in raw[:end].decode().splitlines()[1:]:
        if line.startswith("#") or ":" not in line:
            continue
        key, value = line.split(":", 1)
        fields[key.strip()] = value.strip()
    data = raw[end + 2:]
    if fields["encoding"] == "gzip":
        data = gzip.decompress(data)
    sizes = [int(s) for s in fields["sizes"].split()]
    assert fields["type"] == "float" and sizes[0] == 3
    assert fields["space"] == "left-posterior-superior"
    assert fields["kinds"].split() == ["vector", "domain", "domain", "domain"]
    vectors = np.frombuffer(data, dtype="<f4").reshape(sizes[3], sizes[2], sizes[1], 3)
    dirs = [d for d in fields["space directions"].split() if d != "none"]
    directions = np.array([[float(x) for x in d.strip("()").split(",")] for d in dirs]).T
    origin = np.array([float(x) for x in fields["space origin"].strip("()").split(",")])
    return vectors, directions, origin


def read_obj(path):
    vertices, faces = [], []
    for line in path.read_text().splitlines():
        parts = line.split()
        if parts and parts[0] == "v":
            vertices.append([float(x) for x in parts[1:4]])
        elif parts and parts[0] == "f":
            faces.append([p.split("/")[0] for p in parts[1:4]])
    return np.array(vertices), faces


def test_scipy_applying_the_field_agrees_with_repose(repose, tmp_path):
    repose("phantom", "--voxel", "4", "--out", tmp_path)
    repose("cage", "--parts", tmp_path / "S.nii.gz", "--out", tmp_path / "cage.obj")
    repose("mesh", "--parts", tmp_path / "S.nii.gz", "--cage", tmp_path / "cage.obj",
           "--size-mm", "20", "--out", tmp_path / "tm.vtu")
    # A real, non-rigid pose: the left arm's cage below the elbow turned 60 degrees forward.
    joints = {j["name"]: np.array(j["ras"]) for j in
              json.loads((tmp_path / "skeleton.json").read_text())["joints"]}
    elbow, shoulder = joints["elbow_left"], joints["shoulder_left"]
    vertices, faces = read_obj(tmp_path / "cage.obj")
    a = np.radians(60)
    rot = np.array([[1, 0, 0], [0, np.cos(a), -np.sin(a)], [0, np.sin(a), np.cos(a)]])
    arm = (vertices[:, 2] < elbow[2]) & (vertices[:, 0] < shoulder[0] + 25)
    assert arm.sum() > 5
    posed = vertices.copy()
    posed[arm] = (vertices[arm] - elbow) @ rot.T + elbow
    lines = [f"v {x:.9g} {y:.9g} {z:.9g}" for x, y, z in posed]
    lines += ["f " + " ".join(f) for f in faces]
    (tmp_path / "posed.obj").write_text("\n".join(lines) + "\n")

    result = repose("warp", "--input", tmp_path / "G.nii.gz", "--mesh", tmp_path / "tm.vtu",
                    "--cage", tmp_path / "cage.obj", "--posed-cage", tmp_path / "posed.obj",
                    "--out", tmp_path / "posed.nii.gz", "--transform-out",
                    tmp_path / "field.nrrd", "--json")
    report = json.loads(result.stdout)
    ours = nib.load(tmp_path / "posed.nii.gz")
    labels = np.asarray(ours.dataobj)
    assert list(labels.shape) == report["dims"]

    vectors, directions, origin = read_nrrd(tmp_path / "field.nrrd")
    # The field's grid is the posed map's grid (NIfTI is RAS: flip x and y to compare).
    flip = np.diag([-1.0, -1.0, 1.0])
    np.testing.assert_allclose(flip @ directions, ours.affine[:3, :3], atol=1e-6)
    np.testing.assert_allclose(flip @ origin, ours.affine[:3, 3], atol=1e-4)

    # Sample the input where the field points, nearest neighbour, in the input's voxel indices.
    nx, ny, nz = labels.shape
    k, j, i = np.meshgrid(np.arange(nz), np.arange(ny), np.arange(nx), indexing="ij")
    ijk = np.stack([i, j, k], axis=-1).reshape(-1, 3).astype(np.float64)
    lps = ijk @ directions.T + origin + vectors.reshape(-1, 3)
    ras = lps * np.array([-1.0, -1.0, 1.0])
    source = nib.load(tmp_path / "G.nii.gz")
    src_ijk = (ras - source.affine[:3, 3]) @ np.linalg.inv(source.affine[:3, :3]).T
    sampled = ndimage.map_coordinates(np.asarray(source.dataobj), src_ijk.T, order=0,
                                      mode="constant", cval=0)
    expected = labels.transpose(2, 1, 0).reshape(-1)  # x fastest, like ijk above
    agree = np.mean(sampled == expected)
    print(f"scipy agrees with repose on {agree:.6f} of {expected.size} voxels")
    assert agree >= 0.999, f"only {agree:.5f} of voxels agree"
    assert report["labels_lost"] == 0
