#!/usr/bin/python3
"""Slab-parallel warp (docs/PERFORMANCE.md, "One grid over several ranks"): `repose warp` of one
output grid of about 860M voxels, out of core under a 512 MiB budget per process, in one process
(the serial out-of-core path) and with --mpi on 1 and 2 ranks; the files are compared byte for
byte.

    make bench-warp-mpi
    /usr/bin/python3 bench/warp_mpi_bench.py --build build --out build/bench-warp-mpi

The input is the phantom at --voxel mm (2 by default: its cage and mesh take seconds; the grid's
size is set by --spacing-mm), posed with the left forearm turned 60 degrees at the elbow as in
bench/run_bench.py. Prints and writes OUT/warp_mpi_bench.json: per run the wall time, each
process's peak resident memory, the number of slabs, rank 0's stage times (setup: MPI, reading,
the deformation; slabs: rasterized and written by all ranks) and whether the file equals the
serial one.
"""
import argparse
import filecmp
import json
import subprocess
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from run_bench import elbow_posed_cage  # noqa: E402


def run(args):
    done = subprocess.run([str(a) for a in args], capture_output=True, text=True)
    if done.returncode != 0:
        sys.exit(f"warp_mpi_bench: {' '.join(map(str, args[:4]))} failed:\n{done.stderr[-2000:]}")
    return done


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--build", default="build")
    p.add_argument("--out", default="build/bench-warp-mpi")
    p.add_argument("--voxel", type=float, default=2.0)
    p.add_argument("--target-voxels", type=float, default=860e6)
    p.add_argument("--memory", default="512M",
                   help="budget of each process (below the ~0.9 GB the grid needs in core)")
    p.add_argument("--ranks", default="1,2", help="rank counts of the --mpi runs")
    a = p.parse_args()
    repose = str((Path(a.build) / "bin" / "repose").resolve())
    out = Path(a.out).resolve()
    out.mkdir(parents=True, exist_ok=True)
    if not (out / "tm.vtu").exists():
        run([repose, "phantom", "--voxel", a.voxel, "--out", out])
        run([repose, "cage", "--parts", out / "S.nii.gz", "--out", out / "cage.obj"])
        run([repose, "mesh", "--parts", out / "S.nii.gz", "--cage", out / "cage.obj", "--out",
             out / "tm.vtu"])
    elbow_posed_cage(out / "cage.obj", out / "skeleton.json", out / "posed.obj")
    warp = [repose, "warp", "--input", out / "G.nii.gz", "--mesh", out / "tm.vtu", "--cage",
            out / "cage.obj", "--posed-cage", out / "posed.obj", "--json"]
    # The posed body's box in mm from a warp at the input's spacing, then the spacing that gives
    # about the target's voxels.
    probe = json.loads(run(warp + ["--out", out / "probe.nii.gz"]).stdout)
    (out / "probe.nii.gz").unlink()
    box_mm3 = probe["voxels"] * a.voxel ** 3
    spacing = round((box_mm3 / a.target_voxels) ** (1 / 3), 4)
    warp += ["--spacing-mm", spacing, "--memory", a.memory]

    results = {"voxel_mm": a.voxel, "spacing_mm": spacing, "memory_per_process": a.memory,
               "runs": []}
    runs = [("serial out of core", 0)] + [(f"--mpi, {r} rank(s)", int(r))
                                           for r in a.ranks.split(",")]
    reference = out / "posed_serial.nii.gz"
    for name, ranks in runs:
        target = reference if ranks == 0 else out / f"posed_mpi{ranks}.nii.gz"
        target.unlink(missing_ok=True)
        cmd = warp + ["--out", target] + (["--mpi"] if ranks else [])
        # Each process under /usr/bin/time: its peak resident memory in <rss>.<rank>.
        rss = out / f"rss-{ranks}"
        timed = ["sh", "-c", '/usr/bin/time -f %M -o "$0.${OMPI_COMM_WORLD_RANK:-0}" "$@"',
                 rss] + cmd
        if ranks > 1:
            timed = ["mpirun", "-np", ranks, "--oversubscribe", "--allow-run-as-root"] + timed
        start = time.time()
        summary = json.loads(run(timed).stdout)
        seconds = time.time() - start
        if not summary["out_of_core"]:
            sys.exit(f"warp_mpi_bench: {name} ran in core under {a.memory}: not an out-of-core run")
        peaks = [round(int(Path(f"{rss}.{k}").read_text().split()[-1]) / 1024)
                 for k in range(max(1, ranks))]
        row = {"run": name, "ranks": ranks, "seconds": round(seconds, 1),
               "voxels": summary["voxels"], "dims": summary["dims"],
               "slabs": summary.get("mpi", {}).get("slabs"),
               "stage_seconds": summary.get("mpi", {}).get("stage_seconds"),
               "peak_rss_mb_per_process": peaks,
               "file_mb": round(target.stat().st_size / 2**20, 1),
               "identical_to_serial": filecmp.cmp(target, reference, shallow=False)}
        results["runs"].append(row)
        print(json.dumps(row))
    for f in out.glob("posed_mpi*.nii.gz"):
        f.unlink()
    (out / "warp_mpi_bench.json").write_text(json.dumps(results, indent=1))


if __name__ == "__main__":
    main()
