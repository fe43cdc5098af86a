"""`cmake --install` (make install) lays out a folder that works on its own (issue 22): the
installed `repose` finds its library beside it, runs a pose, and the folder's 3D Slicer CLI module
answers --xml, after the folder was moved; no installed file names the source or build tree.
"""
import csv
import json
import os
import pathlib
import shutil
import subprocess
import sys

import pytest

REPO = pathlib.Path(__file__).resolve().parents[2]


@pytest.fixture(scope="module")
def installed(bin_dir, tmp_path_factory):
    build = bin_dir.parent
    root = tmp_path_factory.mktemp("install")
    r = subprocess.run(["cmake", "--install", str(build), "--prefix", str(root / "prefix")],
                       capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    # Moved as a whole: nothing may depend on where it was installed.
    moved = root / "moved"
    shutil.move(str(root / "prefix"), str(moved))
    return moved


def test_the_installed_command_runs_a_pose_from_its_folder(installed, tmp_path):
    repose = installed / "bin" / "repose"
    run = lambda *a: subprocess.run([str(repose), *map(str, a)], capture_output=True, text=True,
                                    cwd=tmp_path)
    r = run("--version")
    assert r.returncode == 0 and r.stdout.startswith("repose "), r.stderr
    # 4 mm: the coarsest phantom whose bones are big enough (>= 1000 voxels) for the report to
    # check their rigidity; at 8 mm every bone is under that floor and "bones rigid" says nothing.
    assert run("phantom", "--voxel", "4", "--out", tmp_path / "ph").returncode == 0
    r = run("pose", "--input", tmp_path / "ph" / "G.nii.gz", "--parts", tmp_path / "ph" / "S.nii.gz",
            "--pose", REPO / "bench" / "poses" / "elbow90.pose.json", "--out", tmp_path / "o",
            "--json")
    assert r.returncode == 0, r.stderr
    report = json.loads(r.stdout)
    assert report["labels_lost"] == 0
    # The phantom's tissue table travels with the installed binary: without it no label is a
    # bone, the pose bends the bones like soft tissue and nothing below would be reported.
    assert report["tissue_table"] == "phantom default"
    with open(REPO / "Resources" / "Tissues" / "phantom.csv") as f:
        rigid = {int(row["label"]) for row in csv.DictReader(
            line for line in f if not line.startswith("#")) if row["rigid"] == "1"}
    # The rigid labels this (basic) phantom has: the table also lists the detailed anatomy's.
    present = {label["value"] for label in report["labels"] if label["voxels_before"] > 0}
    rigid &= present
    assert rigid and rigid <= set(report["whole_pieces"]["labels"]), report["whole_pieces"]
    checked = [t for t in report["rigid_tissues"] if t["checked"]]
    assert {t["bone"] for t in checked} >= {"femur", "humerus", "skull", "vertebrae"}, checked
    assert all(t["dice"] >= 0.95 for t in checked), checked
    assert report["quality"]["bones_rigid"]["met"], report["quality"]["bones_rigid"]


def test_the_slicer_module_folder_is_where_the_docs_say(installed):
    modules = list(installed.glob("lib*/repose/cli-modules/ReposePose"))
    assert len(modules) == 1, list(installed.rglob("*"))
    r = subprocess.run([str(modules[0]), "--xml"], capture_output=True, text=True, timeout=5)
    assert r.returncode == 0, r.stderr
    assert "<category>Segmentation.Repose</category>" in r.stdout


def test_no_installed_file_names_the_source_or_build_tree(installed, bin_dir):
    trees = {str(REPO).encode(), str(bin_dir.parent.resolve()).encode()}
    # A sanitizer build keeps source file names for its reports (and line tables): there only the
    # libraries' search paths and the text files are checked.
    sanitized = os.environ.get("REPOSE_SANITIZE") == "1"
    for f in installed.rglob("*"):
        if not f.is_file() or f.is_symlink():
            continue
        data = f.read_bytes()
        if data[:4] == b"\x7fELF":
            dynamic = subprocess.run(["readelf", "-d", str(f)], capture_output=True,
                                     text=True).stdout
            for line in dynamic.splitlines():
                if "RPATH" in line or "RUNPATH" in line:
                    assert "$ORIGIN" in line and not any(t.decode() in line for t in trees), line
            if sanitized:
                continue
        for t in trees:
            assert t not in data, f"{f} names {t.decode()}"


def test_the_installed_python_package_finds_its_csxcad_fix(installed):
    """repose.openems preloads libReposeCsxcadFix for openEMS (docs/DOSIMETRY.md): the installed
    package must find the installed library, not the build tree's."""
    packages = list(installed.glob("lib*/**/dist-packages"))
    assert len(packages) == 1, packages
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "REPOSE_CSXCAD_FIX")}
    env["PYTHONPATH"] = str(packages[0])
    r = subprocess.run([sys.executable, "-c",
                        "import repose.openems as oe; print(oe.csxcad_fix_library())"],
                       capture_output=True, text=True, env=env, cwd=installed)
    assert r.returncode == 0, r.stderr
    found = pathlib.Path(r.stdout.strip())
    assert found.is_file() and installed in found.parents, found
