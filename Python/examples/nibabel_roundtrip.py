#!/usr/bin/env python3
"""numpy in, posed numpy out, through nibabel: a label map and its body-part map loaded with
nibabel (any NIfTI), handed to Repose as arrays with their affines, the left elbow bent by a
pose edited in code, and the posed label map handed back as a nibabel image and saved.

    PYTHONPATH=build/python /usr/bin/python3 Python/examples/nibabel_roundtrip.py --out posed.nii.gz
    PYTHONPATH=build/python /usr/bin/python3 Python/examples/nibabel_roundtrip.py \
        --organs G.nii.gz --parts S.nii.gz --angle 60 --out posed.nii.gz

Without --organs/--parts it writes the generated phantom with nibabel first (--phantom-mm). The
pose names the elbow: its place comes from the skeleton.json beside S (`repose rig` writes it), or
--skeleton, or the phantom's.
"""
import argparse
import pathlib
import sys
import tempfile

import nibabel as nib
import numpy as np

import repose

REPO = pathlib.Path(__file__).resolve().parents[2]


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--organs", help="label map G (NIfTI)")
    p.add_argument("--parts", help="body-part map S (NIfTI, G's grid)")
    p.add_argument("--phantom-mm", type=float, default=4.0)
    p.add_argument("--angle", type=float, default=90.0, help="elbow flexion in degrees")
    p.add_argument("--skeleton", help="skeleton.json (default: the one beside --parts)")
    p.add_argument("--out", required=True, help="the posed label map (.nii.gz)")
    a = p.parse_args(argv)

    with tempfile.TemporaryDirectory() as tmp:
        # The pose names body parts ("forearm_left"); nibabel gives no label names, so they come
        # from the file's label table as Repose reads it (its NIfTI extension or .seg.nrrd).
        if a.organs:
            g_img, s_img = nib.load(a.organs), nib.load(a.parts)
            part_names = repose.read_volume(a.parts).labels
            skeleton = a.skeleton or str(pathlib.Path(a.parts).parent / "skeleton.json")
        else:  # a NIfTI pair as another tool would have written it (no label names)
            ph = repose.make_phantom(a.phantom_mm)
            part_names = ph["parts"].labels
            skeleton = ph["skeleton"]
            nib.save(repose.to_nibabel(ph["organs"]), f"{tmp}/G.nii.gz")
            nib.save(repose.to_nibabel(ph["parts"]), f"{tmp}/S.nii.gz")
            g_img, s_img = nib.load(f"{tmp}/G.nii.gz"), nib.load(f"{tmp}/S.nii.gz")

        # numpy arrays and affines in (nibabel indexes [i, j, k], as Repose does).
        g_array = np.asanyarray(g_img.dataobj)
        organs = repose.volume_from_array(g_array, g_img.affine, label_map=True)
        parts = repose.volume_from_array(np.asanyarray(s_img.dataobj), s_img.affine,
                                         labels=part_names, label_map=True)

    pose = repose.Pose.read(str(REPO / "bench" / "poses" / "elbow90.pose.json"))
    pose.set_transform("left forearm and hand", angle_deg=a.angle)
    rig = repose.build_rig(organs, parts, pose, tissues=None, skeleton=skeleton)
    frame = rig.pose_frame(organs, parts)

    # The posed labels out: a numpy view in a nibabel image, saved by nibabel.
    posed = repose.to_nibabel(frame.organs)
    nib.save(posed, a.out)
    back = nib.load(a.out)
    posed_array = np.asanyarray(back.dataobj)
    before = {int(v): int(n) for v, n in zip(*np.unique(g_array, return_counts=True)) if v}
    after = {int(v): int(n) for v, n in zip(*np.unique(posed_array, return_counts=True)) if v}
    vox_in = abs(np.linalg.det(g_img.affine[:3, :3])) / 1000
    vox_out = abs(np.linalg.det(back.affine[:3, :3])) / 1000
    print(f"input {g_array.shape} -> posed {posed_array.shape}, {len(after)} of {len(before)} "
          f"labels kept, body {sum(before.values()) * vox_in:.0f} ml -> "
          f"{sum(after.values()) * vox_out:.0f} ml; elbow at {a.angle:g} deg -> {a.out}")
    return 0 if set(after) == set(before) else 1


if __name__ == "__main__":
    sys.exit(main())
