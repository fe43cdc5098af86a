"""SIGINT and SIGTERM during long commands: the command stops at its next progress point, exits
128 + the signal with one line on stderr, and leaves the output folder as it found it (no output,
no temporary folder)."""
import json
import signal
import socket
import subprocess

import pytest

from conftest import REPO

ELBOW = REPO / "bench" / "poses" / "elbow90.pose.json"


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


def start_pose(bin_dir, rig, out, *extra):
    """`repose pose` of the phantom's elbow into `out`, returned once its first progress line
    shows the run under way."""
    process = subprocess.Popen(
        [str(bin_dir / "repose"), "pose", "--input", rig / "G.nii.gz", "--parts",
         rig / "S.nii.gz", "--pose", ELBOW, "--out", out,
         "--slicer-progress", *map(str, extra)],
        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    for line in process.stdout:
        if line.startswith("<filter-progress>"):
            break
    assert process.poll() is None, "the pose ended before the test could act on it"
    return process


def temporaries(folder):
    return sorted(p.name for p in folder.iterdir() if p.name.startswith(".repose-tmp-"))


def test_a_second_pose_into_the_same_folder_refuses_and_the_first_finishes(bin_dir, rig,
                                                                             tmp_path):
    out, scene = tmp_path / "out", tmp_path / "scene"
    first = start_pose(bin_dir, rig, out, "--scene", scene)
    # Into the same output folder, and into the same scene from another output folder: each
    # refuses at once, naming the folder and the run that holds it, and writes nothing.
    for args in (["--out", out], ["--out", tmp_path / "other", "--scene", scene]):
        second = subprocess.run(
            [str(bin_dir / "repose"), "pose", "--input", rig / "G.nii.gz", "--parts",
             rig / "S.nii.gz", "--pose", ELBOW, *map(str, args)],
            capture_output=True, text=True, timeout=60)
        assert second.returncode != 0
        lines = second.stderr.strip().splitlines()
        assert len(lines) == 1 and "another Repose run (process %d)" % first.pid in lines[0], \
            second.stderr
        assert not (tmp_path / "other").exists()
    _, stderr = first.communicate(timeout=600)
    assert first.returncode == 0, stderr
    assert (out / "report.json").is_file() and (out / "posed_G.nii.gz").is_file()
    assert not (out / ".repose.lock").exists() and not (scene / ".repose.lock").exists()
    assert temporaries(out) == []


def test_a_killed_pose_blocks_nothing_and_its_temporaries_go_with_the_next_run(bin_dir, rig,
                                                                                 tmp_path):
    out = tmp_path / "out"
    killed = start_pose(bin_dir, rig, out)
    killed.kill()  # SIGKILL: no handler runs, the lock file and any temporary folder stay
    killed.communicate(timeout=60)
    assert not (out / "report.json").exists() and not (out / "posed_G.nii.gz").exists()
    # What a kill in the middle of writing a frame leaves: the run's temporary folder with part of
    # a file (named as AtomicOutput names it: host, the dead process, six characters).
    host = socket.gethostname().replace("-", "_").replace("/", "_")
    stale = out / (".repose-tmp-%s-%d-abc123" % (host, killed.pid))
    stale.mkdir()
    (stale / "posed_G.nii.gz").write_bytes(b"\x1f\x8b partial")
    # Another host's (a shared file system) is not ours to judge.
    foreign = out / (".repose-tmp-otherhost-%d-abc123" % killed.pid)
    foreign.mkdir()
    result = subprocess.run(
        [str(bin_dir / "repose"), "pose", "--input", rig / "G.nii.gz", "--parts",
         rig / "S.nii.gz", "--pose", ELBOW, "--out", out],
        capture_output=True, text=True, timeout=600)
    assert result.returncode == 0, result.stderr
    assert "removed %s, left by a run that was killed" % stale in result.stdout
    assert temporaries(out) == [foreign.name]
    assert (out / "report.json").is_file() and not (out / ".repose.lock").exists()


def full_disk():
    """In the child: files may grow to 30 KB only, and a write beyond fails with EFBIG (the
    signal the kernel sends then, SIGXFSZ, is ignored, as a full disk sends none)."""
    import resource
    signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
    resource.setrlimit(resource.RLIMIT_FSIZE, (30000, 30000))


@pytest.mark.parametrize("name", ["posed.nii.gz", "posed.nii", "posed.nrrd", "posed.seg.nrrd",
                                  "posed.nhdr"])
def test_a_full_disk_gives_one_line_and_leaves_nothing(bin_dir, rig, tmp_path, name):
    """Every writer, the detached NRRD too (teem freed its data file name twice on this path),
    stops with one line naming the file, and leaves the folder as it was: no partial file, no
    temporary folder."""
    before = sorted(p.name for p in tmp_path.iterdir())
    r = subprocess.run([str(bin_dir / "repose"), "convert", rig / "G.nii.gz", tmp_path / name],
                       preexec_fn=full_disk, capture_output=True, text=True, timeout=120)
    assert r.returncode == 1, r.stderr
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith(
        "repose convert: error: %s: " % (tmp_path / name)), r.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == before


def test_a_full_disk_during_a_pose_leaves_no_frame_and_no_folder(bin_dir, rig, tmp_path):
    out = tmp_path / "out"
    r = subprocess.run(
        [str(bin_dir / "repose"), "pose", "--input", rig / "G.nii.gz", "--parts",
         rig / "S.nii.gz", "--pose", ELBOW, "--out", out],
        preexec_fn=full_disk, capture_output=True, text=True, timeout=600)
    assert r.returncode == 1, r.stderr
    lines = [l for l in r.stderr.strip().splitlines() if "warning" not in l]
    assert len(lines) == 1 and "error: " in lines[0] and str(out) in lines[0], r.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == []  # the folder it made is gone too


def test_a_kill_while_out_of_core_slabs_are_written_leaves_the_previous_output(bin_dir, rig,
                                                                                tmp_path):
    """SIGKILL while the out-of-core path writes its slabs: the previous output stays as it was,
    nothing partial sits at the target, and the next run into the folder removes what the
    killed run left (its temporary folder with part of the file)."""
    repose = str(bin_dir / "repose")
    tm = rig / "tm.vtu"
    if not tm.exists():
        subprocess.run([repose, "mesh", "--parts", rig / "S.nii.gz", "--cage", rig / "cage.obj",
                        "--size-mm", "8.5", "--out", tm], check=True, capture_output=True)
    out = tmp_path / "posed.nii.gz"
    warp = [repose, "warp", "--input", rig / "G.nii.gz", "--mesh", tm, "--cage",
            rig / "cage.obj", "--posed-cage", rig / "cage.obj", "--out", out]
    first = subprocess.run(warp + ["--memory", "4G", "--json"], capture_output=True, text=True,
                           check=True)
    previous = out.read_bytes()
    # A budget a third of the volumes above what the mesh and cage took: out of core, in slabs.
    summary = json.loads(first.stdout)
    budget = (summary["memory_in_use_before_volumes_bytes"]
              + summary["memory_volumes_need_in_core_bytes"] / 3)
    process = subprocess.Popen(warp + ["--memory", "%dK" % (budget // 1024), "--slicer-progress"],
                               stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    out_of_core, slabs = False, 0
    for line in process.stdout:
        out_of_core = out_of_core or "rasterize labels (out of core)" in line
        slabs += out_of_core and line.startswith("<filter-progress>")
        if slabs == 3:
            break
    assert out_of_core and slabs == 3, "the budget must force the out-of-core path"
    process.send_signal(signal.SIGSTOP)  # held mid-slabs while the folder is looked at
    assert process.poll() is None, "the warp ended before the kill"
    stale = temporaries(tmp_path)
    # The slab writer's own temporary folder sits in the run's: the part written so far.
    assert len(stale) == 1 and list((tmp_path / stale[0]).rglob("posed.nii.gz")), stale
    process.kill()
    process.communicate(timeout=60)
    assert out.read_bytes() == previous
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(["posed.nii.gz", stale[0]])
    subprocess.run(warp + ["--memory", "4G"], check=True, capture_output=True)
    assert temporaries(tmp_path) == []
