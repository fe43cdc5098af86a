#!/usr/bin/env python3
"""Where a label's volume changed: its volume at rest and posed in shells of distance from a
joint of the skeleton (in the joint's radii), and the difference. A change concentrated within a
radius or two of a bent joint is the joint's bend; one spread along a limb is resampling.

usage: radial_change.py G.nii.gz posed_G.nii.gz skeleton.json JOINT LABEL

Prints millilitres per shell (edges 0, 0.25, 0.5, 0.75, 1, 1.25, 1.5, 2, 3 radii and beyond).
Distances are from the joint's rest centre in both volumes: for a joint the pose turns about
(the shoulder of arm_raise90), tissue near it stays near it.
"""
import argparse
import json

import nibabel as nib
import numpy as np

EDGES = [0, 0.25, 0.5, 0.75, 1, 1.25, 1.5, 2, 3, np.inf]


def shells(path, label, centre, radius):
    image = nib.load(path)
    ijk = np.argwhere(np.asanyarray(image.dataobj) == label)
    ras = ijk @ image.affine[:3, :3].T + image.affine[:3, 3]
    voxel_ml = abs(np.linalg.det(image.affine[:3, :3])) / 1000
    counts, _ = np.histogram(np.linalg.norm(ras - centre, axis=1) / radius, bins=EDGES)
    return counts * voxel_ml


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("rest")
    p.add_argument("posed")
    p.add_argument("skeleton")
    p.add_argument("joint")
    p.add_argument("label", type=int)
    a = p.parse_args()
    joints = {j["name"]: j for j in json.load(open(a.skeleton))["joints"]}
    if a.joint not in joints:
        raise SystemExit(f"{a.skeleton}: no joint {a.joint}")
    centre, radius = np.array(joints[a.joint]["ras"]), joints[a.joint]["radius_mm"]
    rest = shells(a.rest, a.label, centre, radius)
    posed = shells(a.posed, a.label, centre, radius)
    np.set_printoptions(precision=2, suppress=True, linewidth=120)
    print(f"{a.joint}: radius {radius:.1f} mm; shell edges (radii) {EDGES[1:-1]} and beyond")
    print("rest ml ", rest)
    print("posed ml", posed)
    print("diff ml ", posed - rest, f"total {(posed - rest).sum():+.2f} of {rest.sum():.2f}")


if __name__ == "__main__":
    main()
