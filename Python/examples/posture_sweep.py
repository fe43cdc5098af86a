#!/usr/bin/env python3
"""Posture sweep for dosimetry: one body, every frame of a pose (by default the 7-keyframe walk
of the pose suite), each posed grid written at the FDTD solver's voxel size with its mass report,
and a CSV of the whole-body mass change per posture.

    PYTHONPATH=build/python /usr/bin/python3 Python/examples/posture_sweep.py --out sweep
    PYTHONPATH=build/python /usr/bin/python3 Python/examples/posture_sweep.py \
        --organs G.nii.gz --parts rig/S.nii.gz --pose my.pose.json --spacing-mm 2 --out sweep

Without --organs/--parts it poses the generated phantom (--phantom-mm). With them, the joints the
pose names and the tissue table come from the skeleton.json and tissues.csv beside S, as
`repose rig` writes them (or --skeleton, --tissues). Writes
OUT/<frame>/{posed_G.nii.gz, posed_S.nii.gz, transform.nrrd, report.json} and
OUT/mass_summary.csv, and prints the table.
"""
import argparse
import csv
import pathlib
import sys
import time

import repose

REPO = pathlib.Path(__file__).resolve().parents[2]


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--organs", help="label map G (default: the generated phantom)")
    p.add_argument("--parts", help="body-part map S on G's grid")
    p.add_argument("--phantom-mm", type=float, default=4.0,
                   help="voxel size of the generated phantom (without --organs)")
    p.add_argument("--pose", default=str(REPO / "bench" / "poses" / "walk.pose.json"))
    p.add_argument("--spacing-mm", type=float, default=2.0,
                   help="output voxel size (the FDTD grid); 0 keeps the input's")
    p.add_argument("--tissues", default="auto",
                   help="tissue table CSV (label,name,density_kg_m3,rigid); 'auto': the one "
                        "beside S, else the phantom's")
    p.add_argument("--skeleton", help="skeleton.json for the joints the pose names (default: "
                                      "the one beside S, or the phantom's)")
    p.add_argument("--out", required=True, help="output folder")
    a = p.parse_args(argv)

    if a.organs:
        if not a.parts:
            p.error("--parts is required with --organs")
        organs, parts = repose.read_volume(a.organs), repose.read_volume(a.parts)
        beside = pathlib.Path(a.parts).parent
        skeleton = a.skeleton or beside / "skeleton.json"
        if a.tissues == "auto" and (beside / "tissues.csv").exists():
            a.tissues = str(beside / "tissues.csv")
    else:
        phantom = repose.make_phantom(a.phantom_mm)
        organs, parts = phantom["organs"], phantom["parts"]
        skeleton = a.skeleton or phantom["skeleton"]
    pose = repose.Pose.read(a.pose)
    out = pathlib.Path(a.out)
    out.mkdir(parents=True, exist_ok=True)

    def show(fraction, stage):  # on a terminal only: a log gets the table, not the ticks
        print(f"\r  {stage}: {100 * fraction:5.1f} %          ", end="", file=sys.stderr,
              flush=True)

    progress = show if sys.stderr.isatty() else None

    start = time.time()
    rig = repose.build_rig(organs, parts, pose, tissues=a.tissues, skeleton=skeleton,
                           progress=progress)
    print(f"\rrig: {len(rig.cage_vertices)} cage vertices, {len(rig.mesh_vertices)} mesh "
          f"vertices, tissue table: {rig.tissue_table} ({time.time() - start:.1f} s)")

    rows = []
    for index, name in enumerate(rig.frame_names):
        frame = rig.pose_frame(organs, parts, index, spacing_mm=a.spacing_mm, progress=progress)
        frame.write(str(out / name))
        body = frame.report["body"]
        rows.append({
            "posture": name,
            "grid": "x".join(map(str, frame.report["grid"]["dims"])),
            "mass_before_kg": body.get("mass_before_kg", float("nan")),
            "mass_after_kg": body.get("mass_after_kg", float("nan")),
            "mass_change_percent": body.get("mass_change_percent", float("nan")),
            "volume_change_percent": body["volume_change_percent"],
            "quality_targets_met": frame.report["quality"]["all_met"],
        })
        if progress:
            print("\r" + " " * 60 + "\r", end="", file=sys.stderr)

    with open(out / "mass_summary.csv", "w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=list(rows[0]))
        writer.writeheader()
        writer.writerows(rows)

    print(f"{'posture':12} {'grid':>15} {'mass before kg':>15} {'after kg':>10} "
          f"{'mass change %':>14} {'volume change %':>16}  targets met")
    for r in rows:
        print(f"{r['posture']:12} {r['grid']:>15} {r['mass_before_kg']:15.3f} "
              f"{r['mass_after_kg']:10.3f} {r['mass_change_percent']:14.3f} "
              f"{r['volume_change_percent']:16.3f}  {'yes' if r['quality_targets_met'] else 'no'}")
    print(f"{len(rows)} postures in {time.time() - start:.1f} s -> {out}/mass_summary.csv")
    return 0


if __name__ == "__main__":
    sys.exit(main())
