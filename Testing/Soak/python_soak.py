#!/usr/bin/env python3
"""A long batch script through the Python module (issue 30): cycle after cycle it opens a scene
folder (load_scene: G and S read, the rig prepared for a pose), solves 50 frames of a drag (the
pose's 50 keyframes, each an edit of the group's angle, through Rig.deform), exports the last
frame at full resolution (Rig.pose_frame(...).write), and drops everything. Every tenth cycle it
is also fed corrupt files (five volumes the readers refuse and a scene folder with a truncated
mesh), which must raise repose.Error with one line.

Resident memory is sampled after every cycle, once the garbage collector has run and glibc has
returned its free lists (malloc_trim), so a sample counts what the process holds. The script runs
itself with one malloc arena (glibc.malloc.arena_max=1), as ReposeLogicSoak does: what
malloc_trim cannot return from per-thread arenas swings resident memory by megabytes from cycle
to cycle, and a leak holds memory in any arena. The slope of a least-squares line through the
samples after warm-up is the growth per cycle; the script exits 1 when it is above
--max-slope-kb, and prints JSON.

    python_soak.py [--cycles 500] [--warmup 100] [--edits 50] [--voxel-mm 8]
                   [--max-slope-kb 1] [--work DIR] [--series FILE]
Needs PYTHONPATH to hold the built module (build/python) and REPOSE_SOURCE_DIR or the repository
layout to find bench/poses.
"""
import argparse
import ctypes
import gc
import json
import os
import pathlib
import shutil
import sys
import tempfile
import time

import numpy as np

import repose as rp

REPO = pathlib.Path(os.environ.get("REPOSE_SOURCE_DIR", pathlib.Path(__file__).resolve().parents[2]))
LIBC = ctypes.CDLL("libc.so.6")


def resident_kb():
    """Resident memory in KiB (/proc/self/status): the whole set and its anonymous part."""
    gc.collect()
    LIBC.malloc_trim(0)
    fields = {}
    with open("/proc/self/status") as f:
        for line in f:
            key, _, value = line.partition(":")
            if key in ("VmRSS", "RssAnon"):
                fields[key] = float(value.split()[0])
    return fields["VmRSS"], fields["RssAnon"]


def exec_with_one_arena():
    tunables = os.environ.get("GLIBC_TUNABLES", "")
    if "glibc.malloc.arena_max=1" in tunables:
        return
    env = dict(os.environ, GLIBC_TUNABLES=":".join(
        t for t in (tunables, "glibc.malloc.arena_max=1") if t))
    os.execve(sys.executable, [sys.executable] + sys.argv, env)


def drag_pose(edits: int) -> rp.Pose:
    """elbow90 as a drag: one keyframe per edit, the forearm turned 30 degrees further in steps."""
    pose = json.loads((REPO / "bench" / "poses" / "elbow90.pose.json").read_text())
    pose["name"] = "elbow drag"
    pose["keyframes"] = [
        {"name": f"edit{e}", "groups": {"left forearm and hand": {
            "rotation": {"angle_deg": 90.0 + 30.0 * (e + 1) / edits}}}}
        for e in range(edits)]
    return rp.Pose.from_json(json.dumps(pose), "soak")


def corrupt_inputs(work: pathlib.Path, organs_path: pathlib.Path, scene: pathlib.Path):
    bad = work / "corrupt"
    bad.mkdir()
    g = organs_path.read_bytes()
    head = (b"NRRD0004\ntype: short\ndimension: 3\nspace: left-posterior-superior\nsizes: 8 8 8\n"
            b"space directions: (1,0,0) (0,1,0) (0,0,1)\nendian: little\n")
    files = {
        "truncated.nii.gz": g[: len(g) // 2],
        "corrupt_gzip.nrrd": head + b"encoding: gzip\n\n" + g[len(g) // 3: len(g) // 3 + 4096],
        "kinds_first.nrrd": b"NRRD0004\nkinds: domain domain domain\ndimension: 3\n",
        "segment.seg.nrrd": head + b"encoding: raw\nSegment0_ID:=a\n\n" + b"x" * 100,
        "garbage.nii": b"\x7f" * 400,
    }
    volumes = []
    for name, data in files.items():
        (bad / name).write_bytes(data)
        volumes.append(str(bad / name))
    broken = bad / "scene"
    shutil.copytree(scene, broken)
    for mesh in broken.glob("*.vtu"):
        with open(mesh, "r+b") as f:
            f.truncate(300)
    return volumes, str(broken)


def main() -> int:
    exec_with_one_arena()
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--cycles", type=int, default=500)
    ap.add_argument("--warmup", type=int, default=100)
    ap.add_argument("--edits", type=int, default=50)
    ap.add_argument("--voxel-mm", type=float, default=8.0)
    ap.add_argument("--max-slope-kb", type=float, default=1.0)
    ap.add_argument("--work")
    ap.add_argument("--series")
    args = ap.parse_args()
    if args.cycles - args.warmup < 10:
        ap.error("--cycles must exceed --warmup by at least 10")
    start = time.monotonic()
    work = pathlib.Path(args.work or tempfile.mkdtemp(prefix="repose-python-soak-"))
    work.mkdir(parents=True, exist_ok=True)
    try:
        # The scene: the phantom's G and S, rigged for the elbow, saved as Rig.save_scene saves.
        phantom = rp.make_phantom(args.voxel_mm)
        organs_path, parts_path = work / "G.nii.gz", work / "S.nii.gz"
        rp.write_volume(phantom["organs"], str(organs_path))
        rp.write_volume(phantom["parts"], str(parts_path))
        (work / "skeleton.json").write_text(phantom["skeleton"].to_json())
        scene = work / "scene"
        rig = rp.build_rig(phantom["organs"], phantom["parts"],
                           rp.Pose.read(str(REPO / "bench" / "poses" / "elbow90.pose.json")),
                           skeleton=phantom["skeleton"])
        rig.save_scene(str(scene), str(organs_path), str(parts_path))
        del rig, phantom
        volumes, broken_scene = corrupt_inputs(work, organs_path, scene)
        out = work / "export"

        rss, anon, refused = [], [], 0
        for cycle in range(args.cycles):
            opened = rp.load_scene(scene, drag_pose(args.edits))
            for e in range(args.edits):
                cage, mesh = opened.rig.deform(e)
                assert np.isfinite(mesh).all()
            frame = opened.rig.pose_frame(opened.organs, opened.parts, args.edits - 1)
            frame.write(str(out))
            assert (out / "posed_G.nii.gz").exists()
            del opened, frame, cage, mesh
            # Every tenth cycle (from the first, so warm-up has seen every error path): each
            # corrupt volume, then the corrupt scene.
            if cycle % 10 == 0:
                attempts = [(bad, lambda bad=bad: rp.read_volume(bad)) for bad in volumes]
                attempts.append((broken_scene, lambda: rp.load_scene(broken_scene)))
                for bad, attempt in attempts:
                    try:
                        attempt()
                    except rp.Error as e:
                        assert "\n" not in str(e), str(e)
                        refused += 1
                    else:
                        raise SystemExit(f"python_soak: a corrupt input was read ({bad})")
            total, anonymous = resident_kb()
            rss.append(total)
            anon.append(anonymous)

        def slope_of(samples):
            after = np.array(samples[args.warmup:])
            return float(np.polyfit(np.arange(after.size), after, 1)[0])
        slope = slope_of(rss)
        after = np.array(rss[args.warmup:])
        report = {
            "cycles": args.cycles, "warmup": args.warmup, "edits_per_cycle": args.edits,
            "voxel_mm": args.voxel_mm, "corrupt_inputs_refused": refused,
            "seconds": time.monotonic() - start,
            "rss_mb_after_warmup": after[0] / 1024, "rss_mb_last": rss[-1] / 1024,
            "rss_slope_kb_per_cycle": slope, "rss_anon_slope_kb_per_cycle": slope_of(anon),
            "malloc_arenas": 1, "max_slope_kb_per_cycle": args.max_slope_kb,
            "flat": slope < args.max_slope_kb,
        }
        print(json.dumps(report, indent=2))
        if args.series:
            with open(args.series, "w") as f:
                f.write("cycle,rss_kb,rss_anon_kb\n")
                f.writelines(f"{i},{v},{a}\n" for i, (v, a) in enumerate(zip(rss, anon)))
        return 0 if slope < args.max_slope_kb else 1
    finally:
        if not args.work:
            shutil.rmtree(work, ignore_errors=True)


if __name__ == "__main__":
    sys.exit(main())
