#!/usr/bin/env python3
"""The standard pose suite on a generated phantom, rigged by `repose rig` and posed by `repose pose`
alone (named joints, automatic contact separation), checked against docs/QUALITY.md's targets
from each frame's report.json:

  body volume within +-0.5 %; every label of >= 1000 voxels within +-1 % beyond its resampling
  floor; each bone (all its labels) Dice >= 0.95; no new holes; no label lost; and no two bones
  run into each other (issue 21: with the rig's joint centres the standard poses must not
  collide). With `--gap-mm` (hands and forearms held off the body) a moving hand must be cut from
  its thigh across the gap; both arms up (`arms_up160`, `arms_up180`) must turn both shoulder girdles and `sitting` tilt the
  pelvis (the rhythms of docs/POSES.md). With `--girdles-touching` (the clavicles meet over the
  manubrium) both arms up must cut the two girdles apart across the sternum.

With `--out-of-core` each pose is posed again slab by slab (`repose pose --out-of-core` under a
1.5 GiB budget, issue 56) and every file and report must equal the in-core frame's;
`--out-of-core-poses` names the poses that are (a suite whose other poses another suite already
compares slab by slab).

usage: pose_suite_quality.py BIN_DIR POSES_DIR WORK_DIR [phantom options...]
       [--label-bound PERCENT]  the per-label bound beyond the floor (default 1, the target)
       [--suite NAME,NAME...]   the pose files of POSES_DIR to pose (default the standard suite)
       [--out-of-core]          also slab by slab, compared file by file with the in-core frames
       [--out-of-core-poses NAME,NAME...]  only these poses of the suite slab by slab too
       [--max-inverted-tets N]  tets the posed mesh may leave inside out in a frame (default 0,
                                the target of issue 64; a suite not there yet names its ceiling)

Exits 1 naming every frame and target that fails.
"""
import json
import os
import shutil
import subprocess
import sys

SUITE = ["elbow90", "arm_raise90", "leg_step30", "walk"]


# `repose pose` exits 4 when it wrote every frame but some missed their targets: the frames are
# checked below like any other (and must then say so in their report).
EXIT_TARGETS_MISSED = 4


def run(args, allowed=(0,)):
    r = subprocess.run(args, capture_output=True, text=True)
    if r.returncode not in allowed:
        sys.exit(f"{' '.join(args)}: exit {r.returncode}: {r.stderr.strip()}")
    return r.stdout, r.returncode


def same_out_of_core(repose, g, s, pose, out, frames, scene):
    """The pose again slab by slab, its rig read from the scene the in-core run saved: every file
    of every frame folder equal to the in-core one (the colour tables after their first line,
    which names the file), every report too but for what says where the rig came from."""
    slabs = out + "_slabs"
    text, _ = run([repose, "pose", "--input", g, "--parts", s, "--pose", pose, "--out", slabs,
                   "--json", "--out-of-core", "--memory", "1500M"] + scene,
                  allowed=(0, EXIT_TARGETS_MISSED))
    streamed = json.loads(text)
    streamed = streamed.get("frames", [streamed])
    failures = []
    for f, g_ in zip(frames, streamed):
        where = f"{f['pose']}/{f['frame']} out of core"
        if "streamed" not in g_:
            failures.append(f"{where}: not made slab by slab")
            continue
        slabs_of = g_.pop("streamed")["slabs"]
        rig_keys = ("scene_reused", "green_coordinates")
        if {k: v for k, v in g_.items() if k not in rig_keys} != \
                {k: v for k, v in f.items() if k not in rig_keys}:
            failures.append(f"{where}: the report differs from the in-core frame's")
        one = len(frames) == 1
        a = out if one else os.path.join(out, f["frame"])
        b = slabs if one else os.path.join(slabs, f["frame"])
        for name in sorted(os.listdir(a)):
            x, y = open(os.path.join(a, name), "rb").read(), open(os.path.join(b, name), "rb").read()
            if name.endswith(".ctbl"):
                x, y = x[x.index(b"\n"):], y[y.index(b"\n"):]
            if name != "report.json" and x != y:
                failures.append(f"{where}: {name} differs from the in-core frame's")
        print(f"{where}: {slabs_of} slabs, every file equal to the in-core frame's")
    return failures


def main():
    argv = sys.argv[1:]
    bound = 1.0
    if "--label-bound" in argv:
        i = argv.index("--label-bound")
        bound = float(argv[i + 1])
        del argv[i:i + 2]
    suite = SUITE
    if "--suite" in argv:
        i = argv.index("--suite")
        suite = argv[i + 1].split(",")
        del argv[i:i + 2]
    max_inverted = 0
    if "--max-inverted-tets" in argv:
        i = argv.index("--max-inverted-tets")
        max_inverted = int(argv[i + 1])
        del argv[i:i + 2]
    out_of_core = "--out-of-core" in argv
    if out_of_core:
        argv.remove("--out-of-core")
    slab_poses = None  # every pose of the suite, with --out-of-core
    if "--out-of-core-poses" in argv:
        i = argv.index("--out-of-core-poses")
        slab_poses = argv[i + 1].split(",")
        del argv[i:i + 2]
        out_of_core = True
        if not set(slab_poses) <= set(suite):
            sys.exit(f"--out-of-core-poses {','.join(slab_poses)}: not all in the suite "
                     f"{','.join(suite)}")
    bin_dir, poses, work = argv[:3]
    phantom_args = argv[3:]
    gap_variant = "--gap-mm" in phantom_args
    girdles_touching = "--girdles-touching" in phantom_args
    repose = os.path.join(bin_dir, "repose")
    shutil.rmtree(work, ignore_errors=True)
    os.makedirs(work)
    run([repose, "phantom", "--out", work] + phantom_args)
    g = os.path.join(work, "G.nii.gz")
    rig = os.path.join(work, "rig")
    run([repose, "rig", "--input", g, "--out", rig])
    failures, frames = [], 0
    for name in suite:
        slabs_too = out_of_core and (slab_poses is None or name in slab_poses)
        out = os.path.join(work, name)
        # With --out-of-core the rig is kept in a scene folder, which the run slab by slab reuses.
        scene = ["--scene", os.path.join(work, "scene_" + name)] if slabs_too else []
        text, code = run([repose, "pose", "--input", g, "--parts",
                          os.path.join(rig, "S.nii.gz"), "--pose",
                          os.path.join(poses, name + ".pose.json"), "--out", out, "--json"]
                         + scene, allowed=(0, EXIT_TARGETS_MISSED))
        report = json.loads(text)
        framesOf = report.get("frames", [report])
        if slabs_too:
            failures += same_out_of_core(repose, g, os.path.join(rig, "S.nii.gz"),
                                         os.path.join(poses, name + ".pose.json"), out, framesOf,
                                         scene)
        # The exit status and the reports agree: 4 exactly when some frame missed.
        missed = [f["frame"] for f in framesOf if not f["targets"]["met"]]
        if bool(missed) != (code == EXIT_TARGETS_MISSED):
            failures.append(f"{name}: exit {code} but frames that missed: {missed}")
        for f in framesOf:
            frames += 1
            q, where = f["quality"], f"{f['pose']}/{f['frame']}"
            body = f["body"]["volume_change_percent"]
            worst = q["labels_within_1_percent"]
            beyond = worst["worst_change_beyond_floor_percent"]
            collided = f["bone_collisions"]["voxels"]
            print(f"{where}: body {body:+.3f} % (predicted {f['predicted']['body_change_percent']:+.3f} %), "
                  f"worst label {worst['worst_name']} "
                  f"{worst['worst_change_percent']:+.2f} % (floor "
                  f"{worst['worst_resampling_floor_percent']:+.2f} %), bones min Dice "
                  f"{q['bones_rigid']['min_dice']:.3f}, new holes "
                  f"{q['no_new_holes']['new_enclosed_voxels']}, predicted worst part "
                  f"{q['prediction_within_targets']['worst_part']} "
                  f"{q['prediction_within_targets']['worst_part_change_percent']:+.2f} %, lost "
                  f"{q['no_label_lost']['labels_lost']}, bones collided in {collided} voxels")
            if abs(body) > 0.5:
                failures.append(f"{where}: body volume {body:+.3f} % (target +-0.5 %)")
            if abs(beyond) > bound:
                failures.append(f"{where}: {worst['worst_name']} {beyond:+.2f} % beyond its "
                                f"resampling floor (bound +-{bound} %)")
            # Vessels crossing a crease keep their volume whatever their size (issue 64: on a
            # reference phantom's grid a limb's vessel is a few hundred voxels, below the
            # per-label rule's 1000).
            for label in f["labels"]:
                if "vessel" in label["name"].lower() and label["voxels_before"] > 0:
                    moved = label["change_beyond_floor_percent"]
                    if abs(moved) > bound:
                        failures.append(f"{where}: {label['name']} ({label['voxels_before']} "
                                        f"voxels) {moved:+.2f} % beyond its resampling floor "
                                        f"(bound +-{bound} %)")
            if not q["bones_rigid"]["met"]:
                failures.append(f"{where}: bone {q['bones_rigid']['min_dice_bone']} Dice "
                                f"{q['bones_rigid']['min_dice']:.3f} (target >= 0.95)")
            if not q["no_new_holes"]["met"]:
                failures.append(f"{where}: {q['no_new_holes']['new_enclosed_voxels']} new "
                                "enclosed voxels")
            # Two bones may share a voxel or two where their voxel staircases turn against each
            # other at a joint (0.1 % of the smaller, at least a rest voxel's volume: docs/QUALITY.md); more
            # is a collision.
            if not q["pieces_apart"]["met"]:
                pairs = ", ".join(f"{c['a']} / {c['b']} {c['voxels']} (allowed "
                                  f"{c['allowed_voxels']})"
                                  for c in f["bone_collisions"]["pairs"])
                failures.append(f"{where}: bones run into each other in {collided} voxels ({pairs})")
            if not q["no_label_lost"]["met"]:
                failures.append(f"{where}: {q['no_label_lost']['labels_lost']} labels lost")
            seps = f["separations"]
            if not seps.get("automatic") or not seps.get("made"):
                failures.append(f"{where}: no automatic contact separation was made")
            # The gap variant: a hand that moves is cut from the thigh it hangs beside, across
            # the air between them, and both arms up and sitting turn the girdles and the pelvis.
            made = [set(m["parts"]) for m in seps.get("made", [])]
            if gap_variant and name in ("elbow90", "arm_raise90", "arms_up160", "arms_up180"):
                if {"hand_left", "thigh_left"} not in made:
                    failures.append(f"{where}: the left hand was not cut from its thigh")
            applied = " ".join(f.get("rhythms", {}).get("applied", []))
            if name in ("arms_up160", "arms_up180") and applied.count("scapulohumeral rhythm") != 2:
                failures.append(f"{where}: the shoulder girdles did not turn with the arms")
            # Girdles that touch across the sternum part there when both arms go up: the body
            # reproduces the contact only if the pose had to cut it.
            if (girdles_touching and name in ("arms_up160", "arms_up180")
                    and {"shoulder_girdle_left", "shoulder_girdle_right"} not in made):
                failures.append(f"{where}: the shoulder girdles were not cut apart at the sternum")
            if name == "sitting" and "lumbopelvic rhythm" not in applied:
                failures.append(f"{where}: the pelvis did not tilt with the thighs")
            # Creases: the tets the frame's mesh left inside out, counted at the nearest joint.
            inverted = f["mesh"]["inverted_tets"]
            print(f"{where}: {inverted} tets inside out {f['mesh']['inverted_tets_by_joint']}")
            if inverted > max_inverted:
                failures.append(f"{where}: {inverted} tets inside out "
                                f"({f['mesh']['inverted_tets_by_joint']}; at most {max_inverted})")
            # The posed mesh's own prediction: the body and every body part keep their volume.
            pred = q["prediction_within_targets"]
            if not pred["met"]:
                failures.append(f"{where}: predicted body {pred['body_change_percent']:+.2f} %, "
                                f"{pred['worst_part']} {pred['worst_part_change_percent']:+.2f} % "
                                "(targets +-0.5 %, +-1 %)")
            # A frame that meets every target above says so; one that misses says which.
            if bool(f["targets"]["met"]) != (not f["targets"]["missed"]):
                failures.append(f"{where}: report's targets disagree with themselves")
    if frames < 10:
        failures.append(f"only {frames} frames posed")
    for line in failures:
        print("FAILED", line)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
