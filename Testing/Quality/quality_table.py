#!/usr/bin/env python3
"""docs/QUALITY.md's tables from the report.json files a pose suite wrote (pose_suite_quality.py's
WORK_DIR, e.g. build/Testing/quality-2mm after `ctest -L quality`): one markdown row per frame, in
the suite's order.

usage: quality_table.py WORK_DIR [POSE,POSE...]
"""
import json
import pathlib
import sys

ORDER = ["elbow90", "arm_raise90", "leg_step30", "walk", "arms_up160", "arms_up180", "sitting"]


def row(r):
    q = r["quality"]
    w = q["labels_within_1_percent"]
    pred = q["prediction_within_targets"]
    label = r["labels"]
    worst = next((l for l in label if l.get("name") == w["worst_name"]), {})
    deformation = worst.get("deformation_change_percent")
    name = w["worst_name"] or "-"
    if deformation is not None:
        name += f"; deformation {deformation:+.2f}"
    bones = q.get("bones_rigid", {})
    dice = f"{bones['min_dice']:.3f}" if bones else "-"
    if bones and bones.get("min_dice_bone") and bones["min_dice"] < 0.9995:
        dice += f" ({bones['min_dice_bone']})"
    vr = r.get("volume_restoration", {})
    # The tets inside out, and the joint nearest most of them (report.json's
    # mesh.inverted_tets_by_joint).
    by_joint = r["mesh"].get("inverted_tets_by_joint", {})
    inverted = str(r["mesh"]["inverted_tets"])
    if by_joint:
        joint, n = max(by_joint.items(), key=lambda kv: kv[1])
        inverted += f" ({joint} {n})"
    return (f"| {r['frame'] if r['frame'] == r['pose'] else r['pose'] + '/' + r['frame']} "
            f"| {r['body']['volume_change_percent']:+.3f} "
            f"| {pred['worst_part'] or '-'} {pred['worst_part_change_percent']:+.2f} "
            f"| {w['worst_change_beyond_floor_percent']:+.2f} ({name}) "
            f"| {dice} | {r['bone_collisions']['voxels']} "
            f"| {q['no_new_holes']['new_enclosed_voxels']} | {q['no_label_lost']['labels_lost']} "
            f"| {len(r['separations'].get('made', []))} "
            f"| {vr.get('max_correction_mm', 0):.1f} "
            f"| {inverted} "
            f"| {'yes' if r['targets']['met'] else 'no'} |")


def main():
    work = pathlib.Path(sys.argv[1])
    order = sys.argv[2].split(",") if len(sys.argv) > 2 else ORDER
    print("| frame | body % | predicted worst part % | worst label beyond floor % | bones min Dice "
          "| bones collided (voxels) | new holes | lost | cuts | restoration's largest move (mm) "
          "| inverted tets (most at) | all met |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|")
    for pose in order:
        for p in sorted((work / pose).rglob("report.json")):
            print(row(json.loads(p.read_text())))


if __name__ == "__main__":
    main()
