"""SIGINT and SIGTERM during long commands: the command stops at its next progress point, exits
128 + the signal with one line on stderr, and leaves the output folder as it found it (no output,
no temporary folder)."""
import signal
import subprocess

import pytest


@pytest.fixture(scope="module")
def rig(bin_dir, tmp_path_factory):
    """A 4 mm phantom with a cage and a 36K-vertex transfer mesh: embedding it takes seconds."""
    folder = tmp_path_factory.mktemp("interrupt")
    repose = str(bin_dir / "repose")
    subprocess.run([repose, "phantom", "--voxel", "4", "--out", folder], check=True)
    subprocess.run([repose, "cage", "--parts", folder / "S.nii.gz", "--out", folder / "cage.obj",
                    "--vertices", "500"], check=True, capture_output=True)
    return folder


def interrupt(command, out_dir, sig):
    """Runs `command` with --slicer-progress and signals it once its first progress line shows
    the work under way: an event, not a guessed delay, so neither a slow nor a fast machine
    makes the signal land before the command listens or after it ended."""
    before = sorted(p.name for p in out_dir.iterdir())
    process = subprocess.Popen(command + ["--slicer-progress"], stdout=subprocess.PIPE,
                               stderr=subprocess.PIPE, text=True)
    started = any(line.startswith("<filter-progress>") for line in process.stdout)
    assert started and process.poll() is None, "the command ended before the signal"
    process.send_signal(sig)
    _, stderr = process.communicate(timeout=120)
    assert process.returncode == 128 + sig, stderr
    lines = stderr.strip().splitlines()
    assert lines and ("interrupted" in lines[-1] or "terminated" in lines[-1]), stderr
    assert sorted(p.name for p in out_dir.iterdir()) == before


def test_sigint_during_mesh_leaves_no_mesh(bin_dir, rig, tmp_path):
    interrupt([str(bin_dir / "repose"), "mesh", "--parts", rig / "S.nii.gz", "--cage",
               rig / "cage.obj", "--size-mm", "8.5", "--out", tmp_path / "tm.vtu"],
              tmp_path, signal.SIGINT)


def test_sigterm_during_warp_leaves_no_output(bin_dir, rig, tmp_path):
    tm = rig / "tm.vtu"
    if not tm.exists():
        subprocess.run([str(bin_dir / "repose"), "mesh", "--parts", rig / "S.nii.gz", "--cage",
                        rig / "cage.obj", "--size-mm", "8.5", "--out", tm], check=True,
                       capture_output=True)
    # The cage itself as the posed cage: the identity, but the embedding runs all the same, since
    # the Green coordinates `repose mesh` keeps beside the mesh are taken away. Its first progress
    # line starts seconds of work; read, they would leave only a rasterization of a fraction of a
    # second after it, which the signal could miss.
    tm.with_suffix(".green").unlink(missing_ok=True)
    interrupt([str(bin_dir / "repose"), "warp", "--input", rig / "G.nii.gz", "--mesh", tm,
               "--cage", rig / "cage.obj", "--posed-cage", rig / "cage.obj",
               "--out", tmp_path / "posed.nii.gz", "--transform-out", tmp_path / "field.nrrd"],
              tmp_path, signal.SIGTERM)
