"""scene.mrml (issue 22): `repose pose --scene` writes, beside each frame, a 3D Slicer scene of the
input label map, the posed one, the displacement field, the cage and the transfer mesh. Checked
against the conventions of Slicer's MRML writer and reader (Slicer/Slicer, Libs/MRML/Core):

- vtkMRMLScene.cxx: the root <MRML version="Slicer <major>.<minor>.<patch> <revision>">, one element
  per node named by its tag (GetNodeTagName), ids unique;
- vtkMRMLNode.cxx: references="role:id;...;" with the roles in alphabetical order (a std::map),
  every referenced node present;
- vtkMRMLStorageNode.cxx: fileName URL-encoded (URLEncodeString) and relative to the folder holding
  the scene (as Slicer writes it), resolved against that folder on read;
- vtkMRMLModelStorageNode.cxx: coordinateSystem "RAS" (the files also say SPACE=RAS, which wins);
- display nodes name their colour table with colorNodeID.
"""
import json
import pathlib
import re
import subprocess
import urllib.parse
import xml.etree.ElementTree as ET

import pytest
import vtk

REPO = pathlib.Path(__file__).resolve().parents[2]

TAGS = {  # tag -> what it is (vtkMRML*Node::GetNodeTagName)
    "LabelMapVolume": "data", "LabelMapVolumeDisplay": "display",
    "VolumeArchetypeStorage": "storage", "Segmentation": "data",
    "SegmentationDisplay": "display", "SegmentationStorage": "storage",
    "GridTransform": "data", "TransformStorage": "storage", "Model": "data",
    "ModelDisplay": "display", "ModelStorage": "storage", "ColorTable": "data",
    "ColorTableStorage": "storage",
}
SLICER_COLOR_TABLES = {"vtkMRMLColorTableNodeFileGenericColors.txt"}


def run(bin_dir, *args):
    r = subprocess.run([str(bin_dir / "repose"), *map(str, args)], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    return r


@pytest.fixture(scope="module")
def scenes(tmp_path_factory, bin_dir):
    """The 8 mm phantom in a folder whose name has a space, posed with --scene, from a NIfTI G
    (label map volumes with a colour table) and from a .seg.nrrd G (segmentations)."""
    root = tmp_path_factory.mktemp("mrml") / "my data"
    root.mkdir()
    run(bin_dir, "phantom", "--voxel", "8", "--out", root)
    run(bin_dir, "convert", root / "G.nii.gz", root / "G.seg.nrrd")
    pose = REPO / "bench" / "poses" / "elbow90.pose.json"
    for name, g in (("nifti", "G.nii.gz"), ("seg", "G.seg.nrrd")):
        run(bin_dir, "pose", "--input", root / g, "--parts", root / "S.nii.gz", "--pose", pose,
            "--scene", root / "scene", "--out", root / name)
    return root


def parse(path):
    tree = ET.parse(path)
    root = tree.getroot()
    nodes = {n.get("id"): n for n in root}
    assert len(nodes) == len(root), "two nodes share an id"
    return root, nodes


def references(node):
    text = node.get("references", "")
    assert re.fullmatch(r"([a-zA-Z]+:[^; ]+( [^; ]+)*;)*", text), text
    refs = dict(part.split(":", 1) for part in text.split(";") if part)
    assert list(refs) == sorted(refs), f"roles not in alphabetical order: {text}"
    return refs


def file_of(storage, folder):
    name = urllib.parse.unquote(storage.get("fileName"))
    path = pathlib.Path(name)
    return path if path.is_absolute() else folder / path


@pytest.mark.parametrize("case", ["nifti", "seg"])
def test_the_scene_follows_mrml_conventions(scenes, case):
    folder = scenes / case
    report = json.loads((folder / "report.json").read_text())
    assert report["outputs"]["slicer_scene"] == "scene.mrml"
    root, nodes = parse(folder / "scene.mrml")
    assert root.tag == "MRML"
    assert re.fullmatch(r"Slicer \d+\.\d+\.\d+ \d+", root.get("version")), root.get("version")
    for node in root:
        assert node.tag in TAGS, node.tag
        assert node.get("id").startswith("vtkMRML") and node.get("name") is not None
        for flag in ("hideFromEditors", "selectable", "selected"):
            assert node.get(flag) in ("true", "false"), (node.tag, flag)
        for role, ids in references(node).items():
            for i in ids.split(" "):
                assert i in nodes, f"{node.get('id')} references missing {i}"
                assert TAGS[nodes[i].tag] == role, (node.get("id"), role, nodes[i].tag)
        if TAGS[node.tag] == "storage":
            # URL-encoded: no raw space.
            assert " " not in node.get("fileName")
            path = file_of(node, folder)
            assert path.is_file(), path
        if TAGS[node.tag] == "display" and node.get("colorNodeID"):
            assert node.get("colorNodeID") in nodes or node.get("colorNodeID") in SLICER_COLOR_TABLES
    data = [n for n in root if TAGS[n.tag] == "data"]
    kinds = sorted(n.tag for n in data)
    labels = "Segmentation" if case == "seg" else "LabelMapVolume"
    expected = sorted([labels, labels, "GridTransform", "Model", "Model"] +
                      (["ColorTable"] if case == "nifti" else []))
    assert kinds == expected
    # Every data node but the colour table has its storage; label maps and models a display.
    for n in data:
        refs = references(n)
        assert "storage" in refs
        if n.tag in ("LabelMapVolume", "Segmentation", "Model"):
            assert "display" in refs
    # Every file named relative to the scene's folder, as Slicer's writer does.
    storage = {urllib.parse.unquote(n.get("fileName")) for n in root if TAGS[n.tag] == "storage"}
    assert not any(pathlib.Path(f).is_absolute() for f in storage), storage
    assert "../scene/cage.vtk" in storage and "../scene/tm.vtu" in storage
    assert ("../G.nii.gz" if case == "nifti" else "../G.seg.nrrd") in storage
    assert "transform.nrrd" in storage
    assert ("posed_G.nii.gz" if case == "nifti" else "posed_G.seg.nrrd") in storage
    if case == "nifti":
        assert "posed_G.ctbl" in storage
        display = [n for n in root if n.tag == "LabelMapVolumeDisplay"]
        table = [n for n in root if n.tag == "ColorTable"][0]
        assert all(d.get("colorNodeID") == table.get("id") for d in display)


def test_the_models_open_in_ras_where_the_scene_says(scenes):
    folder = scenes / "nifti"
    root, nodes = parse(folder / "scene.mrml")
    models = [n for n in root if n.tag == "ModelStorage"]
    assert len(models) == 2
    for storage in models:
        assert storage.get("coordinateSystem") == "RAS"
        path = file_of(storage, folder)
        if path.suffix == ".vtk":
            reader = vtk.vtkPolyDataReader()
        else:
            reader = vtk.vtkXMLUnstructuredGridReader()
        reader.SetFileName(str(path))
        reader.Update()
        assert reader.GetOutput().GetNumberOfPoints() > 0, path
        head = path.read_bytes()[:2000]
        assert b"SPACE" in head and b"RAS" in head, path


def test_a_run_without_a_scene_leaves_no_stale_scene(scenes, bin_dir):
    # The same output folder, posed again without --scene: its scene.mrml (which would name a
    # rig this run did not use) is removed with the other files this run does not write.
    folder = scenes / "nifti"
    assert (folder / "scene.mrml").exists()
    run(bin_dir, "pose", "--input", scenes / "G.nii.gz", "--parts", scenes / "S.nii.gz", "--pose",
        REPO / "bench" / "poses" / "elbow90.pose.json", "--out", folder)
    assert not (folder / "scene.mrml").exists()
    assert "slicer_scene" not in json.loads((folder / "report.json").read_text())["outputs"]
