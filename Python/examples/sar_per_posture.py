#!/usr/bin/env python3
"""Whole-body SAR per posture: the generated phantom at rest, with the left arm raised 90 degrees
and with the left leg stepped 30 degrees forward, each exported as an openEMS voxel model and
exposed to a 900 MHz plane wave from the front (E along the body's axis).

    PYTHONPATH=build/python /usr/bin/python3 Python/examples/sar_per_posture.py --out sar
    make dosimetry                      # the same, into build/dosimetry

For each posture: `repose pose` (the standard pose suite's pose files), `repose export-fdtd
--spacing-mm CELL`, then repose.openems.plane_wave_sar. Writes OUT/<posture>/ (posed maps, the
FDTD model, result.json), OUT/sar_per_posture.csv, OUT/sar_per_posture.json and
OUT/sar_per_posture.png (the table's bars and each posture's local SAR, coronal maximum
projection), and prints the table. SAR figures are per W/m^2 of incident power density.
Needs openEMS's Python module (python3-openems) and libReposeCsxcadFix (restarts itself with it
preloaded). About 2 minutes at 10 mm cells on 2 cores.
"""
import argparse
import csv
import json
import os
import pathlib
import shutil
import subprocess
import sys
import time

REPO = pathlib.Path(__file__).resolve().parents[2]
POSTURES = {"rest": None, "arm_raise90": "arm_raise90", "leg_step30": "leg_step30"}


def repose_binary():
    for candidate in (os.environ.get("REPOSE_BIN_DIR", ""), str(REPO / "build" / "bin")):
        exe = pathlib.Path(candidate) / "repose"
        if candidate and exe.exists():
            return str(exe)
    found = shutil.which("repose")
    if not found:
        sys.exit("sar_per_posture: the repose command is not found (set REPOSE_BIN_DIR)")
    return found


def run(*args):
    done = subprocess.run(list(args), capture_output=True, text=True)
    if done.returncode != 0:
        sys.exit(f"sar_per_posture: {' '.join(args[:2])} failed: {done.stderr.strip()}")
    return done.stdout


def plot(rows, maps, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np

    fig, axes = plt.subplots(1, 1 + len(maps), figsize=(4 + 2.6 * len(maps), 5.5),
                             gridspec_kw={"width_ratios": [1.6] + [1] * len(maps)})
    names = [r["posture"] for r in rows]
    x = np.arange(len(rows))
    ax = axes[0]
    ax.bar(x - 0.2, [r["whole_body_sar_mw_kg_per_w_m2"] for r in rows], 0.4,
           label="whole-body SAR")
    ax.bar(x + 0.2, [r["peak_10g_sar_mw_kg_per_w_m2"] / 10 for r in rows], 0.4,
           label="peak 10 g SAR / 10 (IEC/IEEE 62704-1)")
    ax.set_xticks(x, names, rotation=20)
    ax.set_ylabel("mW/kg per W/m$^2$")
    ax.legend(fontsize=8)
    ax.set_title(f"{rows[0]['frequency_mhz']:.0f} MHz plane wave, front, E vertical", fontsize=9)
    top = max(float(m.max()) for m in maps.values())
    for a, (name, m) in zip(axes[1:], maps.items()):
        # Coronal maximum projection: x (R) across, z (S) up; the viewer faces the body.
        a.imshow(np.log10(np.maximum(m.max(axis=1).T, top * 1e-4)), origin="lower",
                 cmap="inferno", vmin=np.log10(top * 1e-4), vmax=np.log10(top))
        a.set_title(f"{name}\nlocal SAR (log, max {1e3 * m.max():.2g} mW/kg)", fontsize=8)
        a.invert_xaxis()
        a.axis("off")
    fig.tight_layout()
    fig.savefig(path, dpi=110)


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--out", required=True, help="output folder")
    p.add_argument("--phantom-mm", type=float, default=4.0, help="voxel size of the phantom")
    p.add_argument("--cell-mm", type=float, default=10.0, help="FDTD cell size")
    p.add_argument("--frequency", default="900MHz")
    p.add_argument("--postures", default=",".join(POSTURES),
                   help="comma-separated: rest and pose files of bench/poses")
    p.add_argument("--threads", type=int, default=0, help="openEMS threads (0: all cores)")
    a = p.parse_args(argv)

    import repose.openems as oe
    oe.reexec_with_csxcad_fix()  # Debian 12's CSXCAD needs it to read voxel models

    exe = repose_binary()
    out = pathlib.Path(a.out).resolve()
    out.mkdir(parents=True, exist_ok=True)
    phantom = out / "phantom"
    start = time.time()
    run(exe, "phantom", "--voxel", str(a.phantom_mm), "--out", str(phantom))
    rows, maps = [], {}
    for name in a.postures.split(","):
        folder = out / name
        folder.mkdir(exist_ok=True)
        if name == "rest":
            labels = phantom / "G.nii.gz"
        else:
            pose = REPO / "bench" / "poses" / f"{name}.pose.json"
            run(exe, "pose", "--input", str(phantom / "G.nii.gz"), "--parts",
                str(phantom / "S.nii.gz"), "--pose", str(pose), "--out", str(folder / "posed"))
            labels = folder / "posed" / "posed_G.nii.gz"
        model = folder / "model.h5"
        export = json.loads(run(exe, "export-fdtd", "--input", str(labels), "--out", str(model),
                                "--frequency", a.frequency, "--spacing-mm", str(a.cell_mm),
                                "--json"))
        r = oe.plane_wave_sar(str(model), threads=a.threads)
        result = r.as_dict()
        result["model_body_volume_change_percent"] = export["body"]["volume_change_percent"]
        with open(folder / "result.json", "w") as f:
            json.dump(result, f, indent=2)
        maps[name] = r.local_sar_w_kg
        rows.append({
            "posture": name,
            "frequency_mhz": r.frequency_hz / 1e6,
            "cell_mm": a.cell_mm,
            "mass_kg": round(r.mass_kg, 3),
            "absorbed_mw_per_w_m2": round(1e3 * r.absorbed_w, 4),
            "whole_body_sar_mw_kg_per_w_m2": round(1e3 * r.whole_body_sar_w_kg, 4),
            "peak_10g_sar_mw_kg_per_w_m2": round(1e3 * r.peak_10g_sar_w_kg, 3),
            "peak_10g_at_ras_mm": " ".join(f"{v:.0f}" for v in r.peak_10g_ras_mm),
            "peak_10g_rule": r.peak_10g_rule,
            "peak_10g_c95_3_mw_kg_per_w_m2": round(1e3 * r.peak_10g_c95_3_w_kg, 3),
            "face_cube_cells": r.averaging_counts["face_cube"],
            "energy_balance": round(r.balance, 4),
            "openems_local_sar_absorbed_ratio": round(r.openems_absorbed_w / r.absorbed_w, 4),
            "fdtd_cells": r.cells,
            "fdtd_seconds": round(r.seconds, 1),
        })
        print(f"{name}: whole-body SAR {1e3 * r.whole_body_sar_w_kg:.3f} mW/kg, peak 10 g "
              f"{1e3 * r.peak_10g_sar_w_kg:.2f} mW/kg per W/m^2; energy balance {r.balance:.3f}",
              flush=True)

    with open(out / "sar_per_posture.csv", "w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=list(rows[0]))
        writer.writeheader()
        writer.writerows(rows)
    with open(out / "sar_per_posture.json", "w") as f:
        json.dump({"rows": rows, "seconds": round(time.time() - start, 1)}, f, indent=2)
    plot(rows, maps, out / "sar_per_posture.png")
    print(f"{'posture':12} {'mass kg':>8} {'WB SAR':>8} {'10 g peak':>10} {'balance':>8}"
          "   (mW/kg per W/m^2)")
    for r in rows:
        print(f"{r['posture']:12} {r['mass_kg']:8.2f} {r['whole_body_sar_mw_kg_per_w_m2']:8.3f} "
              f"{r['peak_10g_sar_mw_kg_per_w_m2']:10.2f} {r['energy_balance']:8.3f}")
    print(f"{len(rows)} postures in {time.time() - start:.0f} s -> {out}/sar_per_posture.csv, .png")
    return 0


if __name__ == "__main__":
    sys.exit(main())
