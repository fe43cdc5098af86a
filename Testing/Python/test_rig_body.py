"""`repose.rig_body` from Python: the arms-resting phantom's G alone gives back its body parts and
joints (as `repose rig` does, same files), and the suite's named-joint pose runs on that rig with
automatic contact separation."""
import json
import pathlib

import numpy as np
import pytest

# Built into build/python (ctest sets PYTHONPATH): a broken or missing extension fails here,
# never skips.
import repose as rp  # noqa: E402

POSES = pathlib.Path(__file__).resolve().parents[2] / "bench" / "poses"


@pytest.fixture(scope="module")
def resting():
    return rp.make_phantom(4.0, arms_resting=True)


@pytest.fixture(scope="module")
def body(resting):
    return rp.rig_body(resting["organs"], source="phantom G")


def test_rig_body_reproduces_the_phantoms_parts_and_joints(resting, body):
    truth, rigged = resting["parts"].array, body.parts.array.copy()
    # The rig splits the phantom's torso (2) into the shoulder girdles (15, 16) and the pelvis
    # (17), parts the phantom's own S does not have.
    rigged[np.isin(rigged, (15, 16, 17))] = 2
    inside = truth > 0
    assert (truth[inside] == rigged[inside]).mean() >= 0.95
    skeleton = resting["skeleton"]
    for name in body.skeleton.joints:
        if name in skeleton.joints:
            assert np.linalg.norm(body.skeleton.centre(name) - skeleton.centre(name)) < 5.0, name
        # A sternoclavicular joint's first axis is its elevation (the clavicle's), others flex.
        first = "elevation" if name.startswith("sternoclavicular") else "flexion"
        assert abs(np.linalg.norm(body.skeleton.axis(name + "." + first)) - 1) < 1e-9
    assert not body.missing
    assert body.report["convention"] == "phantom"
    assert "rigid" in body.tissues_csv.splitlines()[0] or "rigid" in body.tissues_csv


def test_the_rig_folder_is_the_command_lines(tmp_path, body):
    body.write(str(tmp_path / "rig"), "G.nii.gz")
    for f in ("S.nii.gz", "skeleton.json", "tissues.csv", "rig.json"):
        assert (tmp_path / "rig" / f).exists(), f
    again = rp.Skeleton.read(str(tmp_path / "rig" / "skeleton.json"))
    assert again.joints == body.skeleton.joints
    assert json.loads((tmp_path / "rig" / "rig.json").read_text())["convention"] == "phantom"


def test_a_named_joint_pose_runs_on_the_rig_with_automatic_cuts(resting, body):
    pose = rp.Pose.read(str(POSES / "arm_raise90.pose.json"))
    rig = rp.build_rig(resting["organs"], body.parts, pose, body=body)
    frame = rig.pose_frame(resting["organs"], body.parts, 0)
    report = frame.report
    assert report["separations"]["automatic"] is True
    assert any(s["parts"] == ["torso", "upper_arm_left"] for s in report["separations"]["made"])
    assert abs(report["body"]["volume_change_percent"]) < 0.5
    assert report["labels_lost"] == 0
