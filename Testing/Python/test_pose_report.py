"""`repose pose` on the 8 mm phantom, read as a user scripting a study would: the posed maps open
in nibabel on the report's grid, the report's per-label volumes match the voxels, and the plot
script draws both PNGs from the report."""
import json
import subprocess

import nibabel as nib
import numpy as np

from conftest import REPO


def test_report_matches_the_posed_voxels_and_plots(repose, tmp_path):
    repose("phantom", "--voxel", 8, "--out", tmp_path / "ph")
    out = tmp_path / "posed"
    repose("pose", "--input", tmp_path / "ph" / "G.nii.gz", "--parts", tmp_path / "ph" / "S.nii.gz",
           "--pose", REPO / "bench" / "poses" / "elbow90.pose.json", "--out", out)
    report = json.loads((out / "report.json").read_text())
    posed = nib.load(out / "posed_G.nii.gz")
    data = np.asarray(posed.dataobj)
    assert list(data.shape) == report["grid"]["dims"]
    voxel_ml = float(np.prod(posed.header.get_zooms()[:3])) / 1000
    for label in report["labels"]:
        count = int((data == label["value"]).sum())
        assert count == label["voxels_after"], label["name"]
        assert abs(count * voxel_ml - label["volume_after_ml"]) < 1e-6 * max(1, count)
    assert report["quality"]["no_label_lost"]["met"]

    result = subprocess.run(["/usr/bin/python3", str(REPO / "scripts" / "plot-report.py"),
                             str(out / "report.json")], capture_output=True, text=True)
    assert result.returncode == 0, result.stderr
    for name in ("volume_change.png", "distortion.png"):
        png = out / name
        assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
        assert png.stat().st_size > 5000  # axes, bars and labels, not an empty canvas
