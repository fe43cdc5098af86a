#!/usr/bin/python3
"""Where a frame made slab by slab spends its time, by the step `repose pose --mpi` gives each
rank (docs/PERFORMANCE.md, "Over MPI ranks"): `perf record` of one `repose pose` command, its
samples summed by step: the scans ranks 1..N-1 take over, the ordered steps rank 0 keeps
(rounding candidates, background trace, tally, zlib), and the rest.

    /usr/bin/python3 bench/profile_pose_steps.py -- build/bin/repose pose --input G.nii.gz \\
        --parts S.nii.gz --pose P.pose.json --scene SCENE --spacing-mm 1 --memory 2G \\
        --out-of-core --out OUT

Prints one line per step with its share of the samples, and the commands it ran.
"""
import re
import subprocess
import sys
import tempfile
from pathlib import Path

# The first matching step of a sample's symbol (or library) names its step.
STEPS = [
    ("rank 0: label-volume rounding's candidates", lambda dso, sym: "Rounding" in sym),
    ("rank 0: zlib (gzip pieces)", lambda dso, sym: "libz" in dso or "crc32" in sym),
    ("rank 0: the report's tally", lambda dso, sym: "countSlices" in sym or "PosedTally" in sym),
    ("rank 0: background trace, pockets",
     lambda dso, sym: "BackgroundTrace" in sym or "Pocket" in sym),
    ("makers: scans of G, S, field, image",
     lambda dso, sym: any(k in sym for k in ("scanLabels", "LabelSlabs::rasterize",
                                             "DisplacementSlabs::rasterize",
                                             "ImageSlabs::rasterize", "prepareTet", "scanTet",
                                             "runScan"))),
]


def main():
    if "--" not in sys.argv:
        sys.exit(__doc__)
    command = sys.argv[sys.argv.index("--") + 1:]
    with tempfile.TemporaryDirectory() as tmp:
        data = str(Path(tmp) / "perf.data")
        record = ["perf", "record", "-g", "-o", data, "--"] + command
        subprocess.run(record, check=True, stdout=subprocess.DEVNULL)
        report = ["perf", "report", "-i", data, "--no-children", "--sort", "dso,symbol", "-g",
                  "none", "--percent-limit", "0.05", "--stdio"]
        text = subprocess.run(report, check=True, capture_output=True, text=True).stdout
    shares = {name: 0.0 for name, _ in STEPS}
    shares["other (setup on every rank, memory, kernel)"] = 0.0
    for line in text.splitlines():
        m = re.match(r"\s*([\d.]+)%\s+(\S+)\s+\[.\]\s+(.*)", line)
        if not m:
            continue
        share, dso, sym = float(m.group(1)), m.group(2), m.group(3)
        step = next((name for name, test in STEPS if test(dso, sym)),
                    "other (setup on every rank, memory, kernel)")
        shares[step] += share
    print(" ".join(record))
    print(" ".join(report))
    for name, share in shares.items():
        print(f"{share:5.1f} %  {name}")


if __name__ == "__main__":
    main()
