#!/usr/bin/env python3
"""How far a label's resampling floor itself moves: the floor (report.json's
resampling_floor_percent: the change that moving each group's body parts rigidly, with
nearest-neighbour sampling alone, gives on the output grid) recomputed with every group's motion
shifted by a random sub-voxel translation, many times. Its spread is the resampling noise of that
label on that grid: a change beyond the floor smaller than it cannot be told from sampling.

usage: floor_noise.py G.nii.gz S.nii.gz skeleton.json POSE.pose.json LABEL [--shifts N]

For a pose without keyframes whose groups select body parts by name (the standard suite's
elbow90, arm_raise90, leg_step30) and turn about named joints and axes. Prints the floor, and the
mean, standard deviation and range of the shifted floors, in percent of the label's volume.
"""
import argparse
import json

import nibabel as nib
import numpy as np
from scipy.spatial.transform import Rotation


def group_motions(pose, skeleton, part_labels):
    """(parts, R, pivot, translation) per group; the rest group takes the parts no group names."""
    joints = {j["name"]: j for j in skeleton["joints"]}
    out, named = [], set()
    for g in pose["groups"]:
        parts = [part_labels[p] for p in g.get("select", {}).get("parts", [])]
        named.update(parts)
        rot = g.get("rotation")
        if g.get("fixed") or not rot:
            out.append((parts, np.eye(3), np.zeros(3), np.zeros(3), g.get("select", {}).get("rest")))
            continue
        pivot = rot["pivot"]
        pivot = np.array(joints[pivot]["ras"]) if isinstance(pivot, str) else np.array(pivot)
        axis = rot["axis"]
        if isinstance(axis, str):
            joint, name = axis.split(".")
            axis = joints[joint]["axes"][name]
        axis = np.array(axis, float) / np.linalg.norm(axis)
        R = Rotation.from_rotvec(np.radians(rot["angle_deg"]) * axis).as_matrix()
        out.append((parts, R, pivot, np.array(g.get("translation", [0, 0, 0]), float),
                    g.get("select", {}).get("rest")))
    return [(p if not rest else sorted(set(part_labels.values()) - named), R, c, t)
            for p, R, c, t, rest in out]


def floor_voxels(g, s, affine, label, motions, shifts):
    """Output voxels whose nearest rest voxel, through its group's motion, holds `label`."""
    inv = np.linalg.inv(affine)
    total = 0
    for (parts, R, c, t), shift in zip(motions, shifts):
        idx = np.argwhere((g == label) & np.isin(s, parts))
        if len(idx) == 0:
            continue
        ras = idx @ affine[:3, :3].T + affine[:3, 3]
        moved = (ras - c) @ R.T + c + t + shift
        ijk = moved @ inv[:3, :3].T + inv[:3, 3]
        lo, hi = np.floor(ijk.min(0)) - 2, np.ceil(ijk.max(0)) + 2
        axes = [np.arange(lo[d], hi[d] + 1) for d in range(3)]
        q = np.stack(np.meshgrid(*axes, indexing="ij"), -1).reshape(-1, 3)
        back = ((q @ affine[:3, :3].T + affine[:3, 3]) - shift - t - c) @ R + c
        b = np.rint(back @ inv[:3, :3].T + inv[:3, 3]).astype(int)
        ok = np.all((b >= 0) & (b < np.array(g.shape)), 1)
        hit = np.zeros(len(q), bool)
        hit[ok] = (g[tuple(b[ok].T)] == label) & np.isin(s[tuple(b[ok].T)], parts)
        total += int(hit.sum())
    return total


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("organs")
    p.add_argument("parts")
    p.add_argument("skeleton")
    p.add_argument("pose")
    p.add_argument("label", type=int)
    p.add_argument("--shifts", type=int, default=16)
    a = p.parse_args()
    G = nib.load(a.organs)
    g, s = np.asarray(G.dataobj), np.asarray(nib.load(a.parts).dataobj)
    skeleton = json.load(open(a.skeleton))
    pose = json.load(open(a.pose))
    # The phantom's part numbering (`repose rig` keeps it).
    names = ["head", "torso", "upper_arm_left", "forearm_left", "hand_left", "upper_arm_right",
             "forearm_right", "hand_right", "thigh_left", "shank_left", "foot_left",
             "thigh_right", "shank_right", "foot_right"]
    motions = group_motions(pose, skeleton, {n: i + 1 for i, n in enumerate(names)})
    before = int((g == a.label).sum())
    spacing = np.abs(np.diag(G.affine[:3, :3]))
    rng = np.random.default_rng(1)
    zero = [np.zeros(3)] * len(motions)
    floor = floor_voxels(g, s, G.affine, a.label, motions, zero)
    shifted = [floor_voxels(g, s, G.affine, a.label, motions,
                            [rng.uniform(-0.5, 0.5, 3) * spacing for _ in motions])
               for _ in range(a.shifts)]
    pct = lambda n: 100 * (n / before - 1)  # noqa: E731
    print(f"label {a.label}: {before} voxels; floor {pct(floor):+.2f} %; {a.shifts} sub-voxel "
          f"shifts: mean {pct(np.mean(shifted)):+.2f} %, standard deviation "
          f"{100 * np.std(shifted) / before:.2f} %, range {pct(min(shifted)):+.2f} .. "
          f"{pct(max(shifted)):+.2f} %")


if __name__ == "__main__":
    main()
