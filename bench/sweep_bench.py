#!/usr/bin/python3
"""Posture-sweep throughput (docs/PERFORMANCE.md, "Posture sweeps"): the same sweep run in one
process and under mpirun with 2 ranks, each from empty outputs (the subjects' rigs built in the
run), on phantoms of the given voxel size.

    make bench-sweep                        # 2 mm phantoms, 1 and 2 ranks
    /usr/bin/python3 bench/sweep_bench.py --build build --out build/bench-sweep --voxel 2

Subjects: the phantom with free arms and with hands on the hips. Poses: bench/poses' elbow90,
arm_raise90, leg_step30 and hand_from_hip (one frame each). Prints and writes OUT/sweep_bench.json:
per rank count the wall time, jobs per minute (posing jobs over the whole sweep's time, rigs
included), the jobs' summed, slowest and fastest times, the jobs per rank and each rank's peak
resident memory.
"""
import argparse
import json
import shutil
import subprocess
import sys
import time
from pathlib import Path

SOURCE = Path(__file__).resolve().parent.parent
POSES = ["elbow90", "arm_raise90", "leg_step30", "hand_from_hip"]


def run(args, **kw):
    done = subprocess.run(args, capture_output=True, text=True, **kw)
    if done.returncode != 0:
        sys.exit(f"sweep_bench: {' '.join(map(str, args[:3]))} failed:\n{done.stderr[-2000:]}")
    return done


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--build", default="build")
    p.add_argument("--out", default="build/bench-sweep")
    p.add_argument("--voxel", type=float, default=2.0)
    p.add_argument("--ranks", default="1,2", help="comma-separated rank counts (1: no mpirun)")
    a = p.parse_args()
    repose = str((Path(a.build) / "bin" / "repose").resolve())
    out = Path(a.out).resolve()
    out.mkdir(parents=True, exist_ok=True)
    subjects = {"free_arms": [], "hands_on_hips": ["--arms-touching"]}
    for name, flags in subjects.items():
        if not (out / name / "S.nii.gz").exists():
            run([repose, "phantom", "--voxel", str(a.voxel), *flags, "--out", str(out / name)])
    (out / "subjects.txt").write_text("".join(f"{n}\n" for n in subjects))
    (out / "poses.txt").write_text(
        "".join(f"{SOURCE / 'bench' / 'poses' / (n + '.pose.json')}\n" for n in POSES))
    results = {"voxel_mm": a.voxel, "subjects": list(subjects), "poses": POSES, "runs": []}
    for ranks in [int(r) for r in a.ranks.split(",")]:
        target = out / f"sweep-{ranks}"
        shutil.rmtree(target, ignore_errors=True)
        sweep_cmd = [repose, "sweep", "--subjects", str(out / "subjects.txt"), "--poses",
                     str(out / "poses.txt"), "--out", str(target)]
        # Each rank under /usr/bin/time: its peak resident memory in <rss>.<rank>.
        rss = out / f"rss-{ranks}"
        timed = ["sh", "-c", '/usr/bin/time -f %M -o "$0.${OMPI_COMM_WORLD_RANK:-0}" "$@"',
                 str(rss)] + sweep_cmd
        cmd = timed if ranks == 1 else (
            ["mpirun", "-np", str(ranks), "--oversubscribe", "--allow-run-as-root"] + timed)
        start = time.time()
        run(cmd)
        seconds = time.time() - start
        peak_mb = [round(int(Path(f"{rss}.{k}").read_text().split()[-1]) / 1024)
                   for k in range(ranks)]
        sweep = json.loads((target / "sweep.json").read_text())
        jobs = [r for r in sweep["records"] if r["status"] == "done"]
        row = {
            "ranks": ranks,
            "seconds": round(seconds, 1),
            "jobs": len(jobs),
            "jobs_per_minute": round(60 * len(jobs) / seconds, 2),
            "job_seconds_total": round(sum(r["seconds"] for r in jobs), 1),
            "job_seconds_min": round(min(r["seconds"] for r in jobs), 1),
            "job_seconds_max": round(max(r["seconds"] for r in jobs), 1),
            "jobs_per_rank": {str(k): sum(1 for r in jobs if r["rank"] == k)
                              for k in range(ranks)},
            "peak_rss_mb_per_rank": peak_mb,
        }
        results["runs"].append(row)
        print(json.dumps(row), flush=True)
    (out / "sweep_bench.json").write_text(json.dumps(results, indent=2) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
