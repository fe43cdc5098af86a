#!/usr/bin/python3
"""A coarse map at a real whole body's scale (issue 65 item 3): the arms-resting phantom at
0.79 mm, every bone in one label and every soft tissue in another (`repose phantom --labels
coarse`: 327M voxels, the size of a 1 mm whole-body CT's grid), rigged by `repose rig` with no
option, then posed (the suite's arm raise) slab by slab within `--memory 2G` (and, where that is
refused, 6G). Each command is timed with its peak resident memory (/usr/bin/time -v). Targets:
the rig within 2 minutes and 4 GiB on the 2-core machine; the pose within a 2 GiB budget.

    make bench-large    (runs this after the other large benchmarks)
    /usr/bin/python3 bench/rig_large_bench.py --build build --out build/bench-rig-large

Prints and writes OUT/rig_large_bench.json.
"""
import argparse
import json
import shutil
import subprocess
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from pose_large_bench import run  # noqa: E402  (a command timed with its peak resident memory)

VOXEL_MM = "0.79"


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--build", default="build")
    parser.add_argument("--out", default="build/bench-rig-large")
    args = parser.parse_args()
    repose = Path(args.build) / "bin" / "repose"
    out = Path(args.out)
    shutil.rmtree(out, ignore_errors=True)
    out.mkdir(parents=True)
    body = out / "body"
    run([repose, "phantom", "--voxel", VOXEL_MM, "--arms-resting", "--labels", "coarse",
         "--out", body])
    info = json.loads(subprocess.run([repose, "info", body / "G.nii.gz", "--json"],
                                     capture_output=True, text=True, check=True).stdout)
    voxels = info["dimensions"][0] * info["dimensions"][1] * info["dimensions"][2]
    done, rig_seconds, rig_peak = run([repose, "rig", "--input", body / "G.nii.gz", "--out",
                                       out / "rig", "--json"])
    rig = json.loads(done.stdout)
    # The pose slab by slab within 2 GiB, then (when that is refused: G and S stay in memory
    # beside the rig) within 6 GiB.
    poses = {}
    for budget in ("2G", "6G"):
        done, seconds, peak = run(
            [repose, "pose", "--input", body / "G.nii.gz", "--parts", out / "rig" / "S.nii.gz",
             "--pose", Path(__file__).resolve().parent / "poses" / "arm_raise90.pose.json",
             "--out", out / f"raised_{budget}", "--out-of-core", "--memory", budget, "--json"],
            check=False)
        row = {"seconds": round(seconds, 1), "peak_resident_bytes": peak,
               "exit": done.returncode}
        if done.returncode in (0, 4):
            report = json.loads(done.stdout)
            row.update({"slabs": report.get("streamed", {}).get("slabs"),
                        "all_met": report["quality"]["all_met"]})
        else:
            row["error"] = next((l for l in done.stderr.splitlines() if "error" in l), "")
        poses[f"pose_arm_raise90_out_of_core_{budget}"] = row
        if done.returncode in (0, 4):
            break
    result = {
        "voxels": voxels,
        "voxel_mm": float(VOXEL_MM),
        "rig": {"seconds": round(rig_seconds, 1), "peak_resident_bytes": rig_peak,
                "convention": rig["convention"], "joints": len(rig["joints"]),
                "missing": rig["missing"],
                "within_target": rig_seconds <= 120 and rig_peak <= 4 * 2**30},
        **poses,
    }
    (out / "rig_large_bench.json").write_text(json.dumps(result, indent=1))
    print(json.dumps(result, indent=1))


if __name__ == "__main__":
    main()
