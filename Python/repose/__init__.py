"""Repose: re-pose segmented whole-body volumes with a cage, from Python.

A label map G (organs and tissues) with its body-part map S is rigged once (a cage around the
body and a transfer mesh inside it), then posed by a pose file: each frame of the pose is a few
solves, and its posed volumes, displacement field and report come out at full resolution. The
same files as the command line (`repose pose`) and the workbench, from the same C++ core.

    import repose
    g = repose.read_volume("G.nii.gz")
    body = repose.rig_body(g)                                # S, skeleton, tissues from the bones
    pose = repose.Pose.read("walk.pose.json")                # joints named: "elbow_left", ...
    rig = repose.build_rig(g, body.parts, pose, body=body)   # cage + mesh, embedded
    for i, name in enumerate(rig.frame_names):
        frame = rig.pose_frame(g, body.parts, i)              # posed G, S, field, report
        frame.write(f"out/{name}")

Long calls release the GIL, take `progress=callable(fraction, stage)` (return False to cancel:
repose.Cancelled is raised) and stop on Ctrl+C. Errors are repose.Error with the command line's
one-line messages. See docs/PYTHON.md.
"""

from __future__ import annotations

import os
from typing import NamedTuple, Optional

from ._repose import (  # noqa: F401  (re-exported)
    Cancelled,
    Error,
    LiveSession,
    Pose,
    PosedFrame,
    Rig,
    RiggedBody,
    Skeleton,
    Volume,
    __version__,
    average_sar,
    make_phantom,
    read_volume,
    rig_body,
    write_volume,
)
from . import _repose

__all__ = [
    "Cancelled", "Error", "LiveSession", "Pose", "PosedFrame", "Rig", "RiggedBody", "Scene", "Skeleton",
    "Volume", "__version__", "average_sar", "build_rig", "from_nibabel", "load_scene",
    "make_phantom", "read_volume", "rig_body", "to_nibabel", "volume_from_array",
    "write_volume",
]

# Voxel types Repose keeps; others are converted (labels to the smallest integer type that holds
# them, intensities to float32).
_KEPT = ("uint8", "uint16", "int16", "int32", "float32")


def volume_from_array(array, affine, labels=None, label_map: Optional[bool] = None) -> Volume:
    """A Volume from a numpy array indexed [i, j, k] (as nibabel's) and its 4x4 IJK->RAS affine.

    labels: {value: name} or a list of {'value', 'name', 'color'} dicts. label_map: whether the
    voxels are labels (default: integer voxels are). The voxels are copied once into Repose's
    buffer; `Volume.array` then is a view of it, without copies.
    """
    import numpy as np

    a = np.asanyarray(array)
    if a.ndim not in (3, 4):
        raise Error(f"array: expected 3 dimensions (or 4 with layers last), got {a.ndim}")
    if a.dtype == bool:
        a = a.astype(np.uint8)
    integer = np.issubdtype(a.dtype, np.integer)
    if label_map is None:
        label_map = integer
    if a.dtype.name not in _KEPT:
        if integer:
            lo, hi = (int(a.min()), int(a.max())) if a.size else (0, 0)
            for t in ("uint8", "uint16", "int16", "int32"):
                info = np.iinfo(t)
                if info.min <= lo and hi <= info.max:
                    a = a.astype(t)
                    break
            else:
                raise Error(f"array: labels from {lo} to {hi} do not fit in int32")
        else:
            a = a.astype(np.float32)
    return Volume._from_buffer(np.asfortranarray(a), np.asarray(affine, dtype=float), labels,
                               bool(label_map))


def from_nibabel(image, labels=None, label_map: Optional[bool] = None) -> Volume:
    """A Volume from a nibabel image (its data array and affine; NIfTI is RAS already)."""
    import numpy as np

    return volume_from_array(np.asanyarray(image.dataobj), image.affine, labels, label_map)


def to_nibabel(volume: Volume):
    """A nibabel Nifti1Image of a Volume: the voxels are a view of the volume's buffer (no copy;
    keep the volume alive while the image is used)."""
    import nibabel as nib

    image = nib.Nifti1Image(volume.array, volume.affine)
    image.header.set_xyzt_units("mm")
    if volume.is_label_map:
        image.header.set_intent("label")
    return image


def _tissues(tissues):
    """(path, auto) for the rig: None no table; "auto" the tissues.csv beside S (a scene's), else
    the phantom's when G's labels are the phantom's; else the table at that path."""
    if tissues is None:
        return "", False
    if tissues == "auto":
        return "", True
    return os.fspath(tissues), False


def build_rig(organs: Volume, parts: Volume, pose: Pose, *, body: Optional[RiggedBody] = None,
              skeleton=None, tissues="auto", auto_separate: bool = True,
              cage_vertices: int = 300, dilate_mm: float = 10.0, mesh_mm: float = 0.0,
              whole_organs: bool = True, joint_rings: int = -1, threads: int = 0,
              progress=None) -> Rig:
    """Builds the cage and the transfer mesh of S for the pose (its separations made, and the
    automatic ones: parts that move apart are cut free where they touch, except across their own
    joint), meshes bones and one-part organs as whole pieces, embeds the mesh and resolves the
    pose's groups.

    body: what rig_body made (its skeleton and tissue table are used). skeleton: a Skeleton or a
    skeleton.json path, for the joints the pose names. tissues: a tissue table CSV
    (label,name,density_kg_m3,rigid[,bone]) for masses and bones, "auto" (the phantom's table
    when G's labels are the phantom's) or None. The rest as `repose pose`.
    """
    path, auto = _tissues(tissues)
    csv = ""
    if body is not None:
        skeleton = body.skeleton if skeleton is None else skeleton
        if tissues == "auto":
            path, auto, csv = "", False, body.tissues_csv
    if isinstance(skeleton, (str, os.PathLike)):
        skeleton = Skeleton.read(os.fspath(skeleton))
    return Rig(organs, parts, pose, cage_vertices=cage_vertices, dilate_mm=dilate_mm,
               mesh_mm=mesh_mm, _tissues_path=path, _tissues_auto=auto,
               _tissues_csv=csv, whole_organs=whole_organs, joint_rings=joint_rings,
               threads=threads, skeleton=skeleton, auto_separate=auto_separate,
               progress=progress)


class Scene(NamedTuple):
    """A scene folder opened: its inputs read, its rig prepared for its (or a given) pose."""
    organs: Volume
    parts: Volume
    image: Optional[Volume]
    rig: Rig
    inputs: dict


def load_scene(folder, pose: Optional[Pose] = None, *, tissues="auto", joint_rings: int = -1,
               threads: int = 0, memory_bytes: Optional[float] = None) -> Scene:
    """Opens a scene folder (the workbench's File > Save Scene, `repose pose --scene`,
    Rig.save_scene): reads G, S and the image it names and prepares its cage and transfer mesh
    for its pose, or for `pose` (which may differ in transforms and keyframes, not separations).
    `memory_bytes` is read_volume's budget for each of the three reads.
    """
    folder = os.fspath(folder)
    inputs = _repose._scene_inputs(folder)
    organs = read_volume(inputs["organs"], memory_bytes=memory_bytes)
    parts = read_volume(inputs["parts"], memory_bytes=memory_bytes) if inputs["parts"] else None
    if parts is None:
        raise Error(f"{folder}: the scene names no body-part map")
    image = read_volume(inputs["image"], memory_bytes=memory_bytes) if inputs["image"] else None
    path, auto = _tissues(tissues)
    rig, inputs = _repose._rig_from_scene(folder, organs, parts, pose, joint_rings=joint_rings,
                                          threads=threads, _tissues_path=path,
                                          _tissues_auto=auto)
    return Scene(organs, parts, image, rig, dict(inputs))
