"""The JSON schema of pose files (docs/pose.schema.json) and `repose`'s own validation agree:
every file of the pose suite is valid for both, and each broken variant is refused by both,
`repose` naming the field the schema's validator points at."""
import copy
import json

import jsonschema
import pytest

from conftest import REPO

SCHEMA = json.loads((REPO / "docs" / "pose.schema.json").read_text())
SUITE = sorted((REPO / "bench" / "poses").glob("*.pose.json"))


def test_the_suite_is_valid():
    assert len(SUITE) == 8
    for path in SUITE:
        jsonschema.validate(json.loads(path.read_text()), SCHEMA)


def test_a_chain_of_joints_with_several_axes_is_valid():
    # As the workbench saves a limb posed by its joints: the elbow's group follows the
    # shoulder's, each turning about all of its joint's axes by name.
    pose = {"format": "repose-pose", "version": 1, "name": "arm", "groups": [
        {"name": "shoulder_left", "select": {"parts": ["upper_arm_left"]},
         "rotation": {"axis": "shoulder_left.flexion", "angle_deg": 20, "pivot": "shoulder_left",
                      "then": [{"axis": "shoulder_left.abduction", "angle_deg": 90},
                               {"axis": "shoulder_left.rotation", "angle_deg": 0}]}},
        {"name": "elbow_left", "select": {"parts": ["forearm_left", "hand_left"]},
         "follows": "shoulder_left",
         "rotation": {"axis": "elbow_left.flexion", "angle_deg": 90, "pivot": "elbow_left",
                      "then": [{"axis": "elbow_left.rotation"}]}},
        {"name": "rest", "select": {"rest": True}, "fixed": True}]}
    jsonschema.validate(pose, SCHEMA)


def _broken():
    base = json.loads((REPO / "bench" / "poses" / "elbow90.pose.json").read_text())
    edits = {
        "groups[0].rotation.angle_deg": lambda p: p["groups"][0]["rotation"].update(angle_deg="90"),
        "groups[0].select.parts[0]": lambda p: p["groups"][0]["select"].update(parts=[0]),
        "groups[1].colour": lambda p: p["groups"][1].update(colour="red"),
        "version": lambda p: p.update(version=2),
        "groups[0].rotation.pivot": lambda p: p["groups"][0]["rotation"].update(pivot=[1, 2]),
        "groups[0].rotation.then[0].axis":
            lambda p: p["groups"][0]["rotation"].update(then=[{"angle_deg": 10}]),
        "groups[0].follows": lambda p: p["groups"][0].update(follows=7),
    }
    for field, edit in edits.items():
        pose = copy.deepcopy(base)
        edit(pose)
        yield field, pose


@pytest.mark.parametrize("field,pose", list(_broken()), ids=[f for f, _ in _broken()])
def test_broken_files_are_refused_by_both(field, pose, repose, tmp_path):
    with pytest.raises(jsonschema.ValidationError):
        jsonschema.validate(pose, SCHEMA)
    path = tmp_path / "broken.pose.json"
    path.write_text(json.dumps(pose))
    # The pose file is read before any volume: dummy inputs are never opened.
    result = repose("pose", "--input", str(tmp_path / "G.nii.gz"), "--parts",
                    str(tmp_path / "S.nii.gz"), "--pose", str(path), "--out", str(tmp_path / "o"),
                    check=False)
    assert result.returncode != 0
    assert f"{path}: {field}" in result.stderr, result.stderr
    assert result.stderr.count("\n") == 1
    assert not (tmp_path / "o").exists()
