"""`import repose`: the bindings against nibabel (a reader we did not write), against the command
line (same files, same messages), and as a script uses them: arrays in and out without copies,
a rig posed in and out of core, scenes, progress and cancellation, and the two examples."""
import ctypes
import os
import pathlib
import subprocess
import sys
import threading

import nibabel as nib
import numpy as np
import pytest

# Built into build/python (ctest sets PYTHONPATH): a broken or missing extension fails here,
# never skips.
import repose as rp  # noqa: E402

REPO = pathlib.Path(__file__).resolve().parents[2]
POSES = REPO / "bench" / "poses"


@pytest.fixture(scope="module")
def phantom():
    return rp.make_phantom(8.0, image=True)


@pytest.fixture(scope="module")
def elbow_rig(phantom):
    return rp.build_rig(phantom["organs"], phantom["parts"],
                        rp.Pose.read(str(POSES / "elbow90.pose.json")), skeleton=phantom["skeleton"])


def phantom_bones(organs):
    """The phantom's bone labels (rigid in its tissue table) present in `organs`."""
    import csv
    rows = csv.DictReader(line for line in (REPO / "Resources" / "Tissues" / "phantom.csv")
                          .read_text().splitlines() if not line.startswith("#"))
    rigid = {int(r["label"]) for r in rows if r["rigid"] == "1"}
    return sorted(rigid & set(organs.label_volumes_ml()))


def test_version_is_the_projects():
    cmake = (REPO / "CMakeLists.txt").read_text()
    assert f"VERSION {rp.__version__}" in cmake


def test_array_is_a_view_in_nibabel_order(phantom):
    g = phantom["organs"]
    a = g.array
    assert a.shape == g.shape and a.flags["F_CONTIGUOUS"] and a.dtype == np.uint8
    assert np.shares_memory(a, g.array)  # no copy on each access
    copy = g.copy()
    copy.array[0, 0, 0] = 77  # writes go into the volume
    assert copy.array[0, 0, 0] == 77 and g.array[0, 0, 0] != 77


def test_round_trip_with_nibabel_both_ways(tmp_path, phantom):
    g = phantom["organs"]
    # Repose -> file -> nibabel: same voxels and affine.
    rp.write_volume(g, str(tmp_path / "g.nii.gz"))
    img = nib.load(tmp_path / "g.nii.gz")
    np.testing.assert_array_equal(np.asanyarray(img.dataobj), g.array)
    np.testing.assert_allclose(img.affine, g.affine, atol=1e-5)
    # nibabel array (another dtype, C order, an oblique affine) -> Repose -> nibabel: the same.
    rng = np.random.default_rng(3)
    data = np.ascontiguousarray(rng.integers(0, 300, size=(11, 7, 5)).astype(np.int64))
    affine = np.array([[0, -1.3, 0, 20.0], [1.3, 0, 0, -4.5], [0, 0, 7.2, -804.5], [0, 0, 0, 1]])
    v = rp.volume_from_array(data, affine, labels={1: "liver", 299: "spleen"})
    assert v.dtype == np.uint16 and v.is_label_map
    assert {l["name"] for l in v.labels} == {"liver", "spleen"}
    np.testing.assert_array_equal(v.array, data)
    np.testing.assert_allclose(v.spacing, [1.3, 1.3, 7.2])
    out = rp.to_nibabel(v)
    nib.save(out, tmp_path / "v.nii.gz")
    back = nib.load(tmp_path / "v.nii.gz")
    np.testing.assert_array_equal(np.asanyarray(back.dataobj), data)
    np.testing.assert_allclose(back.affine, affine)
    assert rp.read_volume(str(tmp_path / "v.nii.gz")).axis_codes == "".join(nib.aff2axcodes(affine))


def test_bad_input_raises_the_command_lines_message(tmp_path, repose):
    bad = tmp_path / "bad.nii.gz"
    bad.write_bytes(b"not a nifti file at all")
    with pytest.raises(rp.Error) as python_error:
        rp.read_volume(str(bad))
    cli = repose("info", bad, check=False)
    assert cli.returncode != 0
    assert str(python_error.value) in cli.stderr
    assert "\n" not in str(python_error.value)
    with pytest.raises(rp.Error, match="no such|cannot|not found|does not exist"):
        rp.read_volume(str(tmp_path / "missing.nii.gz"))
    with pytest.raises(rp.Error, match="angle_deg"):
        rp.Pose.from_json('{"format": "repose-pose", "version": 1, "name": "x", "groups":'
                          ' [{"name": "a", "select": {"rest": true}, "rotation": {"axis":'
                          ' [1,0,0], "angle_deg": "ninety", "pivot": [0,0,0]}}]}', "x.pose.json")
    with pytest.raises(rp.Error, match="expected 3 dimensions"):
        rp.volume_from_array(np.zeros((4, 4)), np.eye(4))


def test_reads_stay_within_a_memory_budget(tmp_path, data_dir):
    # A 150-byte NRRD whose header claims 4000^3 voxels (64 GB): refused from the header alone
    # under the default budget (half the physical memory), naming the file and the numbers.
    claim = tmp_path / "claims-64GB.nrrd"
    claim.write_bytes(b"NRRD0004\ntype: uint8\ndimension: 3\nsizes: 4000 4000 4000\n"
                      b"space: left-posterior-superior\nspace directions: (1,0,0) (0,1,0) (0,0,1)\n"
                      b"encoding: raw\n\n" + bytes(64))
    with pytest.raises(rp.Error) as refused:
        rp.read_volume(str(claim))
    message = str(refused.value)
    assert str(claim) in message and "reading it needs" in message and "64000000000 voxels" in message
    assert "memory_bytes=" in message and "\n" not in message
    # An explicit budget: too small for a real file, then enough for it.
    seg = str(data_dir / "totalsegmentator" / "example_seg.nii.gz")
    with pytest.raises(rp.Error, match="memory budget is already used up"):
        rp.read_volume(seg, memory_bytes=1e6)
    assert rp.read_volume(seg, memory_bytes=64e9).shape == (122, 101, 30)
    with pytest.raises(ValueError, match="memory_bytes must be positive"):
        rp.read_volume(seg, memory_bytes=0)


def test_a_dicom_seg_reads_with_its_segments_and_its_grid_said_as_a_warning(tmp_path, data_dir):
    seg = data_dir / "dcmqi_ct3slice" / "partial_overlaps.dcm"
    with pytest.warns(UserWarning, match="placed on the grid of its referenced series"):
        v = rp.read_volume(str(seg))
    # The same lines stay with the volume, for the reports of a rig built from it.
    assert len(v.read_notes) == 1 and "placed on the grid of its referenced series" in v.read_notes[0]
    assert v.shape == (512, 512, 3)
    assert [l["name"] for l in v.labels] == ["GREEN", "LIGHT_BLUE", "DARK_BLUE", "ORANGE", "PURPLE"]
    assert sorted({l["layer"] for l in v.labels}) == [0, 1, 2]
    assert all("TerminologyEntry:" in l["tags"] for l in v.labels)
    # Written back as DICOM SEG and read again: the same voxels, names and layers.
    out = tmp_path / "back.dcm"
    rp.write_volume(v, str(out))
    back = rp.read_volume(str(out))
    assert np.array_equal(np.asarray(back.array), np.asarray(v.array))
    assert [(l["name"], l["layer"]) for l in back.labels] == [(l["name"], l["layer"]) for l in v.labels]


def test_the_phantom_s_clavicles_meet_at_the_midline_when_the_girdles_touch():
    # girdles_touching reaches the phantom (repose phantom --girdles-touching): the clavicles'
    # medial ends come to a few mm of the midline instead of a joint beside the manubrium, and
    # the option belongs to the arms-resting posture.
    def medial_gap_mm(**kw):
        ph = rp.make_phantom(2.0, arms_resting=True, **kw)
        g = ph["organs"]
        value = [l["value"] for l in g.labels if l["name"] == "clavicle" and l["layer"] == 0]
        assert value, [l["name"] for l in g.labels]
        ijk = np.argwhere(np.isin(np.asarray(g.array), value))
        ras = ijk @ np.asarray(g.affine)[:3, :3].T + np.asarray(g.affine)[:3, 3]
        midline = ph["skeleton"].centre("pelvis")[0]
        return float(np.abs(ras[:, 0] - midline).min())
    assert medial_gap_mm(girdles_touching=True) < 6.0 < 15.0 < medial_gap_mm()
    with pytest.raises(Exception, match="arms-resting"):
        rp.make_phantom(4.0, girdles_touching=True)


def test_the_phantom_s_limb_vessels_take_the_diameter_asked():
    # vessel_mm reaches the phantom (repose phantom --vessel-mm): 12 mm vessels hold more voxels
    # than the anatomical ones at 4 mm, and the option belongs to the arms-resting posture.
    def vessel_voxels(**kw):
        g = rp.make_phantom(4.0, arms_resting=True, **kw)["organs"]
        values = [l["value"] for l in g.labels if "vessels" in l["name"] and l["layer"] == 0]
        return int(np.isin(np.asarray(g.array), values).sum())
    assert vessel_voxels(vessel_mm=12.0) > vessel_voxels()
    with pytest.raises(Exception, match="arms-resting"):
        rp.make_phantom(4.0, vessel_mm=3.0)


def test_a_frame_posed_in_python_equals_the_command_lines(tmp_path, repose):
    # 4 mm, not the module's 8 mm phantom: the coarsest whose bones reach the report's
    # 1000-voxel floor, so "all met" includes bones whose rigidity was actually measured.
    phantom = rp.make_phantom(4.0)
    g, s = phantom["organs"], phantom["parts"]
    rp.write_volume(g, str(tmp_path / "G.nii.gz"))
    rp.write_volume(s, str(tmp_path / "S.nii.gz"))
    # The suite's poses name joints: the skeleton beside S says where they are, for both.
    (tmp_path / "skeleton.json").write_text(phantom["skeleton"].to_json())
    pose_file = POSES / "elbow90.pose.json"
    repose("pose", "--input", tmp_path / "G.nii.gz", "--parts", tmp_path / "S.nii.gz",
           "--pose", pose_file, "--scene", tmp_path / "scene", "--out", tmp_path / "cli")
    # The same rig from the scene the command line saved, posed here.
    scene = rp.load_scene(tmp_path / "scene")
    frame = scene.rig.pose_frame(scene.organs, scene.parts)
    frame.write(str(tmp_path / "py"))
    for name in ("posed_G.nii.gz", "posed_S.nii.gz"):
        a = nib.load(tmp_path / "cli" / name)
        b = nib.load(tmp_path / "py" / name)
        np.testing.assert_array_equal(np.asanyarray(a.dataobj), np.asanyarray(b.dataobj))
        np.testing.assert_allclose(a.affine, b.affine)
    report = frame.report
    assert report["quality"]["all_met"] and report["tissue_table"] == "phantom default"
    checked = {t["bone"] for t in report["rigid_tissues"] if t["checked"]}
    assert checked >= {"femur", "humerus", "skull", "vertebrae"}, report["rigid_tissues"]
    assert abs(report["body"]["volume_change_percent"]) < 0.5
    assert report["body"]["mass_before_kg"] > 20
    # The Green coordinates came from the scene's tm.green, not computed again.
    assert report["green_coordinates"]["read"], report["green_coordinates"]
    field = frame.field
    assert field.shape == frame.organs.shape + (3,) and np.isfinite(field).all()


def test_what_the_reader_said_about_g_is_in_every_frames_report(tmp_path, phantom):
    """A Rig keeps G's read_notes (what read_volume's reader decided about the file) and writes
    them into each frame's report as input_notes, as `repose pose` does; a file the reader had
    nothing to say about gives none."""
    rp.write_volume(phantom["organs"], str(tmp_path / "G.nii.gz"))
    g = rp.read_volume(str(tmp_path / "G.nii.gz"))
    assert g.read_notes == []
    pose = rp.Pose.read(str(POSES / "elbow90.pose.json"))
    quiet = rp.build_rig(g, phantom["parts"], pose, skeleton=phantom["skeleton"])
    assert "input_notes" not in quiet.pose_frame(g, phantom["parts"]).report
    # As a DICOM SEG placed on its referenced series' grid would have it (that reader's own
    # note: test_a_dicom_seg_reads_with_its_segments_and_its_grid_said_as_a_warning).
    note = "G.dcm: the segmentation is placed on the grid of its referenced series"
    g.read_notes = [note]
    rig = rp.build_rig(g, phantom["parts"], pose, skeleton=phantom["skeleton"])
    assert rig.pose_frame(g, phantom["parts"]).report["input_notes"] == [note]


def test_a_rig_of_something_other_than_a_volume_is_refused_naming_the_argument(phantom):
    """Rig takes organs as an object (to read its read_notes), so the type is checked by name:
    an array, or a Volume whose read_notes a user set to something other than a list of str,
    gets a TypeError saying which argument and what it got, before any work is done."""
    pose = rp.Pose.read(str(POSES / "elbow90.pose.json"))
    array = np.zeros((4, 4, 4), np.uint8)
    with pytest.raises(TypeError) as wrong:
        rp.build_rig(array, phantom["parts"], pose, skeleton=phantom["skeleton"])
    message = str(wrong.value)
    assert message.startswith("organs: expected a repose.Volume") and "\n" not in message, message
    assert type(array).__name__ in message
    for notes, said in (("one line", "got str"), ([1], "holds an item of type int")):
        volume = phantom["organs"].copy()
        volume.read_notes = notes
        with pytest.raises(TypeError) as wrong:
            rp.build_rig(volume, phantom["parts"], pose, skeleton=phantom["skeleton"])
        assert str(wrong.value).startswith("organs.read_notes: expected a list of str")
        assert said in str(wrong.value), str(wrong.value)


def test_a_frame_write_refuses_a_folder_another_run_writes_into(tmp_path, phantom, elbow_rig):
    """PosedFrame.write takes the folder's lock as `repose pose --out` does: while another run
    holds it (here this test, with flock as FolderLock takes it), the write refuses with one line
    naming the folder and the holder, and leaves the folder as it was; then it writes."""
    import fcntl
    frame = elbow_rig.pose_frame(phantom["organs"], phantom["parts"])
    out = tmp_path / "out"
    frame.write(str(out))
    before = {p.name: p.stat().st_mtime_ns for p in out.iterdir()}
    with open(out / ".repose.lock", "w") as held:
        fcntl.flock(held, fcntl.LOCK_EX | fcntl.LOCK_NB)
        held.write("%d\n" % os.getpid())
        held.flush()
        with pytest.raises(rp.Error) as refused:
            frame.write(str(out))
        message = str(refused.value)
        assert "\n" not in message and message.startswith(str(out)), message
        assert "another Repose run (process %d) is writing here" % os.getpid() in message
        after = {p.name: p.stat().st_mtime_ns for p in out.iterdir() if p.name != ".repose.lock"}
        assert after == before
    os.unlink(out / ".repose.lock")
    frame.write(str(out))
    assert sorted(p.name for p in out.iterdir()) == sorted(before)


def test_the_posed_image_background_is_the_images_minimum_unless_given(phantom, elbow_rig):
    g, s = phantom["organs"], phantom["parts"]
    # A CT padded outside its field of view: its minimum (-3024) is what the default takes.
    ct = phantom["image"].array.copy()
    ct[0, 0, 0] = -3024
    image = rp.volume_from_array(ct, phantom["image"].affine)
    outside = lambda frame: frame.image.array[frame.organs.array == 0]
    default = elbow_rig.pose_frame(g, s, image=image, fill_pockets=False)
    assert outside(default).min() == -3024 and np.median(outside(default)) == -3024
    given = elbow_rig.pose_frame(g, s, image=image, background=-1000, fill_pockets=False)
    assert np.median(outside(given)) == -1000
    # Inside the body both are the same posed image.
    inside = given.organs.array != 0
    np.testing.assert_array_equal(default.image.array[inside], given.image.array[inside])


def test_a_frame_beyond_the_memory_budget_is_refused_with_the_numbers(phantom, elbow_rig):
    g, s = phantom["organs"], phantom["parts"]
    with pytest.raises(rp.Error) as refused:
        elbow_rig.pose_frame(g, s, memory_bytes=1e6)
    message = str(refused.value)
    assert message.startswith("pose_frame needs ") and "output voxels beyond the" in message
    assert "more than the memory budget of 0.000931 GiB" in message and "\n" not in message


def test_a_frame_beyond_the_budget_is_written_slab_by_slab_into_its_folder(tmp_path, phantom,
                                                                          elbow_rig):
    """pose_frame_to_folder runs the frame as `repose pose` does: within the budget whole, beyond
    it slab by slab (issue 56), with the same files and report either way."""
    g, s = phantom["organs"], phantom["parts"]
    whole = elbow_rig.pose_frame_to_folder(g, s, str(tmp_path / "whole"), spacing_mm=4.0,
                                           image=phantom["image"], output_format="both")
    assert "streamed" not in whole
    # The process's resident set now, as the memory rule reads it (the heap the allocator keeps
    # of what was freed given back first: repose::residentBytes), and a little more: the posed
    # volumes do not fit.
    def resident():
        ctypes.CDLL("libc.so.6").malloc_trim(0)
        with open("/proc/self/status") as status:
            return next(int(l.split()[1]) * 1024 for l in status if l.startswith("VmRSS:"))

    streamed = elbow_rig.pose_frame_to_folder(g, s, str(tmp_path / "slabs"), spacing_mm=4.0,
                                              image=phantom["image"], output_format="both",
                                              memory_bytes=resident() + 24 * 2**20)
    assert streamed["streamed"]["slabs"] > 1, streamed["streamed"]
    del streamed["streamed"]
    assert streamed == whole
    for f in sorted((tmp_path / "whole").iterdir()):
        a, b = f.read_bytes(), (tmp_path / "slabs" / f.name).read_bytes()
        if f.suffix == ".ctbl":  # the first line names the file
            a, b = a[a.index(b"\n"):], b[b.index(b"\n"):]
        if f.name != "report.json":
            assert a == b, f.name
    # The same voxels as the frame posed in core.
    frame = elbow_rig.pose_frame(g, s, spacing_mm=4.0, image=phantom["image"])
    posed = np.asanyarray(nib.load(tmp_path / "slabs" / "posed_G.nii.gz").dataobj)
    np.testing.assert_array_equal(posed, frame.organs.array)
    # As DICOM SEG, slab by slab too: the same voxels, read back.
    dcm = elbow_rig.pose_frame_to_folder(g, s, str(tmp_path / "dcm"), spacing_mm=4.0,
                                         output_format="dcmseg",
                                         memory_bytes=resident() + 24 * 2**20)
    assert dcm["streamed"]["slabs"] > 1, dcm["streamed"]
    np.testing.assert_array_equal(rp.read_volume(str(tmp_path / "dcm" / "posed_G.dcm")).array,
                                  frame.organs.array)


def test_output_spacing_and_out_of_core(tmp_path, phantom, elbow_rig):
    g, s = phantom["organs"], phantom["parts"]
    frame = elbow_rig.pose_frame(g, s, spacing_mm=4.0, image=phantom["image"], background=-1000)
    np.testing.assert_allclose(frame.organs.spacing, [4, 4, 4])
    assert frame.image is not None and frame.image.array.min() == -1000
    # Body volume kept at 4 mm within a percent of the 8 mm input's.
    before = sum(g.label_volumes_ml().values())
    after = sum(frame.organs.label_volumes_ml().values())
    assert abs(after / before - 1) < 0.01
    # Out of core, under a small budget: the labels in core, except where the in-core frame
    # uses G and S at rest, which the stream does not hold (docs/ARCHITECTURE.md, "Whole
    # pieces"): a bone's rim moved with the bone, the shell outside the body kept off a
    # neighbour's tissue and off the voxels another part's shell fills with its skin. Those differ
    # only beside a bone or at the body's surface, in a few dozen voxels (53 of 511K at 8 mm).
    rp.write_volume(g, str(tmp_path / "G.nii"))
    elbow_rig.pose_labels_to_file(str(tmp_path / "G.nii"), str(tmp_path / "posed.nii.gz"),
                                  memory_bytes=32 * 2**20)
    in_core = elbow_rig.pose_frame(g, s, fill_pockets=False, label_volumes="nearest").organs.array
    streamed = np.asanyarray(nib.load(tmp_path / "posed.nii.gz").dataobj)
    assert streamed.shape == in_core.shape
    differ = np.argwhere(streamed != in_core)
    assert len(differ) <= 2e-4 * in_core.size
    bones = set(phantom_bones(g)) | {0}  # a bone, or outside the body
    # Beside a bone in either frame: where a joint space's tets went soft (a bone end placed by its
    # piece's motion, PieceGhosts), the stream may give a voxel to the bone that the in-core frame
    # gives to the muscle beside it, or the other way round.
    for i, j, k in differ:
        box = np.s_[max(i - 1, 0):i + 2, max(j - 1, 0):j + 2, max(k - 1, 0):k + 2]
        near = set(np.unique(in_core[box]).tolist()) | set(np.unique(streamed[box]).tolist())
        assert bones & near, (i, j, k)


def test_label_volumes_preserved_or_sampled(phantom, elbow_rig):
    # By default each soft label is rounded to the volume the deformation gives it; "nearest"
    # is plain sampling. The rounding only relabels voxels between soft labels: the body's
    # outline (background) is the same either way.
    g, s = phantom["organs"], phantom["parts"]
    nearest = elbow_rig.pose_frame(g, s, label_volumes="nearest")
    preserved = elbow_rig.pose_frame(g, s)
    assert nearest.report["label_volumes"] == {"rounding": "nearest", "relabelled_voxels": 0}
    assert preserved.report["label_volumes"]["rounding"] == "preserve"
    relabelled = preserved.report["label_volumes"]["relabelled_voxels"]
    a, b = nearest.organs.array, preserved.organs.array
    assert int((a != b).sum()) == relabelled
    assert np.array_equal(a == 0, b == 0)
    for row in preserved.report["labels"]:
        if row.get("rounded") and row["voxels_before"] >= 1000:
            assert row["change_beyond_floor_percent"] == row["change_percent"]
            assert abs(row["change_percent"] - row["deformation_change_percent"]) < 0.5, row
    with pytest.raises(rp.Error, match="label_volumes"):
        elbow_rig.pose_frame(g, s, label_volumes="cubic")


def test_progress_cancellation_and_the_gil(phantom, elbow_rig):
    g, s = phantom["organs"], phantom["parts"]
    seen = []
    elbow_rig.pose_frame(g, s, progress=lambda f, stage: seen.append((f, stage)))
    assert seen and seen[-1][0] == pytest.approx(1.0)
    # Returning False cancels: repose.Cancelled, a repose.Error.
    with pytest.raises(rp.Cancelled):
        elbow_rig.pose_frame(g, s, progress=lambda f, stage: f < 0.3)
    # An exception in the callback stops the work and comes back as itself.
    class Stop(Exception):
        pass

    def stop(f, stage):
        raise Stop(stage)

    with pytest.raises(Stop):
        rp.build_rig(g, s, rp.Pose.read(str(POSES / "elbow90.pose.json")),
                     skeleton=phantom["skeleton"], progress=stop)
    # The GIL is released during the work: another Python thread runs meanwhile.
    ticks = []
    done = threading.Event()

    def count():
        while not done.is_set():
            ticks.append(1)
            done.wait(0.001)

    t = threading.Thread(target=count)
    t.start()
    for _ in range(3):
        elbow_rig.pose_frame(g, s)
    done.set()
    t.join()
    assert len(ticks) > 5


def test_pose_edits_move_the_frame(phantom):
    pose = rp.Pose.read(str(POSES / "elbow90.pose.json"))
    assert pose.transform("left forearm and hand")["angle_deg"] == 90
    pose.set_transform("left forearm and hand", angle_deg=0)
    assert rp.Pose.from_json(pose.to_json()).transform("left forearm and hand")["angle_deg"] == 0
    with pytest.raises(rp.Error, match="fixed"):
        pose.set_transform("body", angle_deg=5)
    # Further turns about the pivot survive a round trip and compose after the first.
    pose.set_transform("left forearm and hand", then=[{"axis": [0, 0, 2], "angle_deg": 30}])
    turned = rp.Pose.from_json(pose.to_json()).transform("left forearm and hand")
    assert len(turned["then"]) == 1 and turned["then"][0]["angle_deg"] == 30
    np.testing.assert_allclose(turned["then"][0]["axis"], [0, 0, 1])
    pose.set_transform("left forearm and hand", then=[])
    rig = rp.build_rig(phantom["organs"], phantom["parts"], pose, skeleton=phantom["skeleton"])
    cage, deformed = rig.deform(0)
    # At 0 degrees the mesh stays where it was (the solve is the identity up to round-off).
    np.testing.assert_allclose(deformed, rig.mesh_vertices, atol=1e-6)
    np.testing.assert_allclose(cage, rig.cage_vertices, atol=1e-6)


def run_example(name, *args):
    env = dict(os.environ, PYTHONPATH=os.environ.get("PYTHONPATH", str(REPO / "build" / "python")))
    return subprocess.run([sys.executable, str(REPO / "Python" / "examples" / name), *map(str, args)],
                          capture_output=True, text=True, env=env, timeout=600)


def test_posture_sweep_example(tmp_path):
    r = run_example("posture_sweep.py", "--phantom-mm", 8, "--spacing-mm", 6, "--out", tmp_path)
    assert r.returncode == 0, r.stderr
    rows = (tmp_path / "mass_summary.csv").read_text().splitlines()
    assert rows[0].startswith("posture,") and len(rows) == 8  # the walk's 7 keyframes
    for step in range(7):
        assert (tmp_path / f"step{step}" / "posed_G.nii.gz").exists()
        img = nib.load(tmp_path / f"step{step}" / "posed_G.nii.gz")
        np.testing.assert_allclose(img.header.get_zooms(), [6, 6, 6])
    assert "mass change %" in r.stdout and "step6" in r.stdout


def test_nibabel_roundtrip_example(tmp_path):
    r = run_example("nibabel_roundtrip.py", "--phantom-mm", 8, "--angle", 45,
                    "--out", tmp_path / "posed.nii.gz")
    assert r.returncode == 0, r.stdout + r.stderr
    assert "27 of 27 labels kept" in r.stdout


def test_cmake_install_gives_an_importable_package(tmp_path, bin_dir):
    build = pathlib.Path(bin_dir).parent
    r = subprocess.run(["cmake", "--install", str(build), "--prefix", str(tmp_path)],
                       capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    package = tmp_path / "lib" / "python3" / "dist-packages"
    assert (package / "repose" / "__init__.pyi").exists()
    code = "import repose; print(repose.__version__, repose.make_phantom(8)['organs'].shape)"
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=tmp_path,
                       env=dict(os.environ, PYTHONPATH=str(package)))
    assert r.returncode == 0, r.stderr
    assert r.stdout.startswith(rp.__version__)


def test_a_pose_is_edited_by_the_workbenchs_rules(phantom):
    """Core's pose edits (pose/PoseEdit.h) from Python, the rules the workbench edits by: joint
    groups posed by their turns, a group moved in the world as the 3D box moves it, separations."""
    skeleton, parts = phantom["skeleton"], phantom["parts"]
    p = rp.Pose.new("scripted")
    assert p.groups == ["rest"]
    # Both joints of the left arm, as the workbench's joint control adds them: the elbow follows
    # the shoulder, each turns about its joint's axes (rotation, then abduction, then flexion).
    assert p.set_joint_group(skeleton, "shoulder_left", parts) == "shoulder_left"
    assert p.set_joint_group(skeleton, "elbow_left", parts) == "elbow_left"
    turns = p.turns("elbow_left")
    assert [t["axis_name"] for t in turns][-1] == "elbow_left.flexion"
    p.set_turn_angle("elbow_left", len(turns) - 1, 90.0)
    assert p.turns("elbow_left")[-1]["angle_deg"] == 90.0
    p.set_turn_angle("shoulder_left", 1, 40.0)
    shoulder = p.motion("shoulder_left")
    elbow = p.motion("elbow_left")
    # The elbow's motion is its own carried by the shoulder's.
    own = p.transform("elbow_left")
    assert own["pivot"] is not None
    assert not np.allclose(elbow, shoulder)
    # A follower's world motion set back exactly: a single-turn group (a box drag's kind).
    q = rp.Pose.new("box")
    q.set_joint_group(skeleton, "elbow_left", parts)
    world = np.eye(4)
    c, s_ = np.cos(0.4), np.sin(0.4)
    world[:3, :3] = [[1, 0, 0], [0, c, -s_], [0, s_, c]]
    world[:3, 3] = [3.0, -2.0, 5.0]
    with pytest.raises(rp.Error, match="several axes"):
        q.set_motion("elbow_left", world)  # a joint group is moved by its turns
    box = rp.Pose.read(str(POSES / "elbow90.pose.json"))
    box.resolve_joints(skeleton)
    box.set_motion("left forearm and hand", world)
    assert np.allclose(box.motion("left forearm and hand"), world, atol=1e-9)
    # About its own pivot still: only the angle and translation changed.
    assert np.allclose(box.transform("left forearm and hand")["pivot"], skeleton.centre("elbow_left"))
    with pytest.raises(rp.Error, match="is fixed"):
        q.set_turn_angle("rest", 0, 10.0)
    # Separations by name or label, refused for one part twice.
    p.add_separation("hand_left", "thigh_left", "sphere:0,0,0,40")
    with pytest.raises(rp.Error, match="itself"):
        p.add_separation("hand_left", "hand_left", "everywhere")
    # The edited pose round-trips as a file.
    back = rp.Pose.from_json(p.to_json(), "back")
    assert back.to_json() == p.to_json()


def test_a_live_session_drags_a_group_and_gives_the_three_slices(phantom):
    """repose.LiveSession (Core's pose/LiveSession.h, what the workbench drives while a user drags):
    a rig prepared once, a frame per drag, the axial, coronal and sagittal slices through a point
    as numpy arrays of G's labels, S's parts or the image."""
    g, s = phantom["organs"], phantom["parts"]
    pose = rp.Pose.read(str(POSES / "elbow90.pose.json"))
    live = rp.LiveSession(g, s, pose, skeleton=phantom["skeleton"], image=phantom["image"],
                          cage_vertices=200)
    assert not live.has_frame
    assert live.slices() == {"axial": None, "coronal": None, "sagittal": None}
    forearm = "left forearm and hand"
    # The session's pose has its joints resolved: the elbow's pivot is a place (RAS mm).
    elbow = live.pose.transform(forearm)["pivot"]

    def in_front(slices):
        """Labelled pixels of the axial slice in front of the rest body (RAS y beyond its box)."""
        lo, hi = live.bounds
        axial = slices["axial"]
        pixel = max(hi[0] - lo[0], hi[1] - lo[1]) / 256
        y = lo[1] + (np.arange(axial.shape[1]) + 0.5) * pixel
        return int(np.count_nonzero(axial[:, y > rest_front]))

    live.drag(forearm, angle_deg=0)
    assert live.has_frame and live.frame_ms > 0
    assert live.deformed.shape[1] == 3 and live.posed_cage.shape[1] == 3
    assert np.all(live.bounds[0] < elbow) and np.all(elbow < live.bounds[1])
    rest_front = live.bounds[1][1]
    straight = live.slices(point=elbow)
    labels = set(np.unique(np.concatenate([a.ravel() for a in straight.values()])))
    assert labels <= set(g.label_volumes_ml()) | {0} and len(labels) > 5
    for name, a in straight.items():
        assert a.ndim == 2 and a.dtype == g.array.dtype, name
    assert in_front(straight) == 0
    # Dragged to 90 degrees the forearm points forward, out of the rest body's box.
    live.drag(forearm, angle_deg=90)
    bent = live.slices(point=elbow)
    assert live.bounds[1][1] > rest_front + 100
    assert in_front(bent) > 50
    assert live.pose.transform(forearm)["angle_deg"] == 90
    # S's parts and the image on the same planes; the prediction of the export's volumes.
    parts = live.slices(point=elbow, layer="parts")
    assert set(np.unique(parts["axial"])) <= set(s.label_volumes_ml()) | {0}
    image = live.slices(point=elbow, layer="image")
    assert all(image[k].shape == bent[k].shape for k in bent)
    p = live.prediction
    assert p["met"] and abs(p["body_change_percent"]) < 0.5 and p["missed"] == ""
    # A pose file with its joint names is resolved as the prepared one was; other groups are not
    # this session's.
    assert live.solves(pose)
    live.set_pose(pose)
    assert live.has_frame
    with pytest.raises(rp.Error, match="not those the rig was prepared for"):
        live.set_pose(rp.Pose.new("other"))
