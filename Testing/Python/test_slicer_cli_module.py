"""Repose as a 3D Slicer CLI module (issue 22), driven the way Slicer drives one, with the rules of
Slicer's own source (named in each test):

- `ReposePose --xml` (the script Slicer finds in the module folder) prints a module description that
  validates against Testing/Slicer/SlicerModuleDescription.xsd (the rules of SlicerExecutionModel's
  ModuleDescriptionParser.cxx) and whose every long flag `repose pose` accepts;
- run with the arguments Slicer passes (Base/Logic/vtkSlicerCLIModuleLogic.cxx: --returnparameterfile
  first, then long flags in the XML's order, label maps exported as uncompressed .nrrd, output nodes
  as temporary file names), it prints the progress lines Slicer parses, writes the return-parameter
  file and the output files, and those hold what `repose pose` writes itself.
"""
import json
import os
import pathlib
import re
import shutil
import subprocess
import xml.etree.ElementTree as ET

import numpy as np
import pytest

REPO = pathlib.Path(__file__).resolve().parents[2]
SCHEMA = REPO / "Testing" / "Slicer" / "SlicerModuleDescription.xsd"


def module_script(bin_dir, name):
    """A module script of the build tree (<build>/<libdir>/repose/cli-modules/<name>)."""
    found = sorted(bin_dir.parent.glob(f"lib*/**/repose/cli-modules/{name}"))
    assert found, f"no {name} under {bin_dir.parent}"
    path = found[0]
    assert os.access(path, os.X_OK)
    assert "." not in path.name  # Slicer takes only dot-free executables as CLI modules on Linux
    return path


def describe(path):
    r = subprocess.run([str(path), "--xml"], capture_output=True, text=True, timeout=5)
    assert r.returncode == 0, r.stderr
    assert r.stdout.startswith("<?xml"), r.stdout[:80]  # Slicer strips anything before <?xml
    return r.stdout


@pytest.fixture(scope="module")
def module(bin_dir):
    return module_script(bin_dir, "ReposePose")


@pytest.fixture(scope="module")
def description(module):
    return describe(module)


@pytest.fixture(scope="module")
def warp_module(bin_dir):
    return module_script(bin_dir, "ReposeWarp")


@pytest.mark.parametrize("name", ["ReposePose", "ReposeWarp"])
def test_the_description_validates_against_the_schema(bin_dir, tmp_path, name):
    if not shutil.which("xmllint"):
        pytest.fail("xmllint is missing (Debian: libxml2-utils; make test installs it)")
    xml = tmp_path / f"{name}.xml"
    xml.write_text(describe(module_script(bin_dir, name)))
    r = subprocess.run(["xmllint", "--noout", "--schema", str(SCHEMA), str(xml)],
                       capture_output=True, text=True)
    assert r.returncode == 0, r.stderr


@pytest.mark.parametrize("mutation", [
    ('type="label"', 'type="labelmap"'),                     # not one of the parser's image types
    ("<longflag>cageVertices<", "<longflag>cage-vertices<"),  # a flag must be an identifier
    ("<channel>output<", "<channel>out<"),                    # input or output
    ("<category>", "<categories>x</categories><category>"),   # an element the parser refuses
    ('type="nonlinear"', 'type="grid"'),                      # not one of its transform types
])
def test_the_schema_refuses_what_the_parser_refuses(description, tmp_path, mutation):
    old, new = mutation
    assert old in description
    xml = tmp_path / "bad.xml"
    xml.write_text(description.replace(old, new, 1))
    r = subprocess.run(["xmllint", "--noout", "--schema", str(SCHEMA), str(xml)],
                       capture_output=True, text=True)
    assert r.returncode != 0, f"{new} was accepted"


def parameters(description):
    root = ET.fromstring(description)
    for group in root.findall("parameters"):
        for p in group:
            if p.tag not in ("label", "description"):
                yield p


@pytest.mark.parametrize("name,command", [("ReposePose", "pose"), ("ReposeWarp", "warp")])
def test_the_description_follows_the_parser_and_the_command(bin_dir, repose, name, command):
    description = describe(module_script(bin_dir, name))
    root = ET.fromstring(description)
    assert root.findtext("category") == "Segmentation.Repose"
    for field in ("title", "description", "version", "contributor"):
        assert root.findtext(field).strip(), field
    help_text = repose(command, "--help").stdout
    names = set()
    for p in parameters(description):
        name = p.findtext("name")
        assert name not in names, f"two parameters named {name}"
        names.add(name)
        assert p.findtext("label").strip() and p.findtext("description").strip(), name
        flag, index = p.findtext("longflag"), p.findtext("index")
        # ModuleDescriptionParser.cxx: a parameter has a flag or an index, not both.
        assert not (flag and index), name
        if flag is None and index is None:
            # A return parameter (vtkSlicerCLIModuleLogic.cxx): an output channel, not a file.
            assert p.findtext("channel") == "output", name
            assert p.tag in ("integer", "double", "float", "boolean", "string"), name
            continue
        # Each flag is an option of `repose pose` (camelCase for the hyphenated ones).
        option = re.sub(r"([A-Z])", lambda m: "-" + m.group(1).lower(), flag.lstrip("-"))
        assert f"--{option} " in help_text or f"--{option}\n" in help_text, flag
        if p.tag in ("image", "transform", "file", "geometry"):
            assert p.findtext("channel") in ("input", "output"), name
    # What Slicer needs to run a pose and take its results back.
    typed = {p.findtext("name"): (p.tag, p.get("type")) for p in parameters(description)}
    assert typed["input"] == ("image", "label")
    if command == "warp":
        assert typed["out"] == ("image", "label")
        assert typed["posedCage"] == ("geometry", "model")
        assert typed["transformOut"] == ("transform", "nonlinear")
        return
    assert typed["parts"] == ("image", "label")
    assert typed["posedLabels"] == ("image", "label")
    assert typed["transform"] == ("transform", "nonlinear")
    assert typed["pose"][0] == "file"
    assert typed["out"][0] == "directory"


def slicer_command(module, description, values, return_file):
    """The command line vtkSlicerCLIModuleLogic.cxx builds: the return-parameter file first, then
    each parameter with a value, `--flag value` in the XML's order (a boolean only as its flag, when
    true)."""
    cmd = [str(module), "--returnparameterfile", str(return_file)]
    for p in parameters(description):
        name, flag = p.findtext("name"), p.findtext("longflag")
        if flag is None or name not in values:
            continue
        if p.tag == "boolean":
            if values[name]:
                cmd.append("--" + flag.lstrip("-"))
        else:
            cmd += ["--" + flag.lstrip("-"), str(values[name])]
    return cmd


def test_a_pose_run_as_slicer_runs_it(module, description, repose, tmp_path):
    # The user's workflow (docs/SLICER.md): rig the segmentation once, load G and the rig's S into
    # Slicer, run the module with the rig's skeleton and tissue table.
    repose("phantom", "--voxel", "6", "--out", tmp_path)
    rig = tmp_path / "rig"
    repose("rig", "--input", tmp_path / "G.nii.gz", "--out", rig)
    # Slicer exports the selected label map nodes as uncompressed NRRD temporary files: no label
    # names reach the module.
    repose("convert", tmp_path / "G.nii.gz", tmp_path / "slicer_G.nrrd")
    repose("convert", rig / "S.nii.gz", tmp_path / "slicer_S.nrrd")
    pose = REPO / "bench" / "poses" / "elbow90.pose.json"
    values = {
        "input": tmp_path / "slicer_G.nrrd", "parts": tmp_path / "slicer_S.nrrd", "pose": pose,
        "skeleton": rig / "skeleton.json", "tissues": rig / "tissues.csv",
        "posedLabels": tmp_path / "out_G.nrrd",
        "posedParts": tmp_path / "out_S.nrrd", "transform": tmp_path / "out_T.nrrd",
        "cageVertices": 300, "dilateMm": 10, "meshMm": 0, "jointRings": -1, "spacingMm": 0,
        "bendOrgans": False, "noAutoSeparate": False, "keepPockets": False, "frame": 0,
        "background": 0, "threads": 0, "outputFormat": "auto",
    }
    params = tmp_path / "params.txt"
    cmd = slicer_command(module, description, values, params)
    r = subprocess.run(cmd, capture_output=True, text=True, cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    # S arrived without names: named by the rig's convention, and said so.
    assert "named as `repose rig` names them" in r.stderr
    out = r.stdout
    # Slicer's progress bar (vtkSlicerCLIModuleLogic.cxx reads the last complete tag on stdout).
    assert out.index("<filter-start>") < out.index("<filter-progress>") < out.index("<filter-end>")
    progress = [float(v) for v in re.findall(r"<filter-progress>([^<]*)</filter-progress>", out)]
    assert progress and all(0.0 <= v <= 1.0 for v in progress)
    assert progress[-1] == pytest.approx(1.0)
    assert re.search(r"<filter-name>repose pose</filter-name>", out)
    # The return parameters (ModuleDescription::ReadParameterFile: "name = value" lines), named as
    # the XML's parameters with no flag and an output channel.
    returned = dict(line.split(" = ", 1) for line in params.read_text().splitlines())
    declared = {p.findtext("name") for p in parameters(description)
                if p.findtext("longflag") is None and p.findtext("index") is None}
    assert set(returned) == declared
    # No results folder was asked for: only the files Slicer named, nothing left beside them.
    leftovers = [p.name for p in tmp_path.iterdir() if p.name.startswith(".repose")]
    assert not leftovers
    # The same pose run as a user runs `repose pose`: the same voxels and figures.
    repose("pose", "--input", tmp_path / "G.nii.gz", "--parts", rig / "S.nii.gz", "--pose", pose,
           "--tissues", rig / "tissues.csv", "--out", tmp_path / "direct")
    report = json.loads((tmp_path / "direct" / "report.json").read_text())
    assert float(returned["bodyVolumeChangePercent"]) == pytest.approx(
        report["body"]["volume_change_percent"], abs=1e-4)
    assert int(returned["labelsLost"]) == report["labels_lost"]
    assert float(returned["bonesMinDice"]) == pytest.approx(
        report["quality"]["bones_rigid"]["min_dice"], abs=1e-5)
    # The NRRD Slicer reads back holds the posed labels, at the same place (LPS in the file).
    nrrd = (tmp_path / "out_G.nrrd").read_bytes()
    header = nrrd[:nrrd.index(b"\n\n")].decode()
    assert "space: left-posterior-superior" in header
    # The same posed voxels: the LPS models were read in RAS (read as written, the cage would be
    # mirrored left-right and front-back and the mesh would leave it).
    info = json.loads(repose("info", tmp_path / "out_G.nrrd", "--json").stdout)
    direct_info = json.loads(
        repose("info", tmp_path / "direct" / "posed_G.nii.gz", "--json").stdout)
    assert info["dimensions"] == direct_info["dimensions"]
    assert {l["value"]: l["voxels"] for l in info["labels"]} == {
        l["value"]: l["voxels"] for l in direct_info["labels"]}
    assert np.allclose(info["ijk_to_ras"], direct_info["ijk_to_ras"], atol=1e-6)
    header_t = (tmp_path / "out_T.nrrd").read_bytes()
    assert b"intent_code:=1006" in header_t[:header_t.index(b"\n\n")]


def test_a_bad_run_fails_with_one_line_and_no_output(module, tmp_path):
    r = subprocess.run([str(module), "--input", str(tmp_path / "missing.nrrd"), "--parts",
                        str(tmp_path / "missing.nrrd"), "--pose", str(tmp_path / "p.json"),
                        "--posedLabels", str(tmp_path / "o.nrrd")], capture_output=True, text=True)
    assert r.returncode != 0
    assert len(r.stderr.strip().splitlines()) == 1, r.stderr
    assert not (tmp_path / "o.nrrd").exists()


def write_slicer_obj(path, vertices, faces):
    """A model as Slicer hands it to a CLI module: vtkMRMLModelStorageNode.cxx converts it to LPS
    and writes it with vtkOBJExporter, comment "3D Slicer output. SPACE=LPS"; the exporter's
    layout (vtkOBJExporter.cxx WriteData/WriteAnActor): "#  <comment>", a blank line, mtllib,
    vertices, normals, a group, the material, faces "i//i"."""
    lines = ["#  3D Slicer output. SPACE=LPS", "", f"mtllib {path.stem}.mtl", ""]
    lines += [f"v {-x!r} {-y!r} {z!r}" for x, y, z in vertices]
    lines += ["vn 0 0 1"] * len(vertices)
    lines += ["", "g grp1", "usemtl mtl1"]
    lines += [f"f {a + 1}//{a + 1} {b + 1}//{b + 1} {c + 1}//{c + 1} " for a, b, c in faces]
    path.write_text("\n".join(lines) + "\n")


def read_obj(path):
    vertices, faces = [], []
    for line in path.read_text().splitlines():
        parts = line.split()
        if parts and parts[0] == "v":
            vertices.append(tuple(float(v) for v in parts[1:4]))
        elif parts and parts[0] == "f":
            faces.append(tuple(int(p.split("/")[0]) - 1 for p in parts[1:4]))
    return np.array(vertices), faces


def test_a_warp_run_as_slicer_runs_it(warp_module, repose, tmp_path):
    repose("phantom", "--voxel", "8", "--out", tmp_path)
    repose("cage", "--parts", tmp_path / "S.nii.gz", "--out", tmp_path / "cage.obj")
    repose("mesh", "--parts", tmp_path / "S.nii.gz", "--cage", tmp_path / "cage.obj", "--out",
           tmp_path / "tm.vtu")
    # A posed cage: turned 8 degrees about the vertical through its centre, the left half of it
    # lifted 20 mm (any motion will do: the module must give what the command gives).
    vertices, faces = read_obj(tmp_path / "cage.obj")
    c = vertices.mean(axis=0)
    a = np.radians(8.0)
    rot = np.array([[np.cos(a), -np.sin(a), 0], [np.sin(a), np.cos(a), 0], [0, 0, 1]])
    posed = (vertices - c) @ rot.T + c
    posed[vertices[:, 0] > c[0], 2] += 20.0
    (tmp_path / "posed.obj").write_text(
        "# SPACE=RAS\n" + "".join(f"v {x!r} {y!r} {z!r}\n" for x, y, z in posed) +
        "".join(f"f {a + 1} {b + 1} {c + 1}\n" for a, b, c in faces))
    # What Slicer hands the module: the models in LPS .obj, the label map as .nrrd.
    write_slicer_obj(tmp_path / "slicer_cage.obj", vertices, faces)
    write_slicer_obj(tmp_path / "slicer_posed.obj", posed, faces)
    repose("convert", tmp_path / "G.nii.gz", tmp_path / "slicer_G.nrrd")
    cmd = [str(warp_module), "--input", str(tmp_path / "slicer_G.nrrd"), "--mesh",
           str(tmp_path / "tm.vtu"), "--cage", str(tmp_path / "slicer_cage.obj"), "--posedCage",
           str(tmp_path / "slicer_posed.obj"), "--out", str(tmp_path / "out_G.nrrd"),
           "--transformOut", str(tmp_path / "out_T.nrrd"), "--spacingMm", "0", "--shellMm", "-1",
           "--threads", "0"]
    r = subprocess.run(cmd, capture_output=True, text=True, cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    assert "<filter-start>" in r.stdout and "<filter-end>" in r.stdout
    progress = [float(v) for v in re.findall(r"<filter-progress>([^<]*)</filter-progress>",
                                             r.stdout)]
    assert progress and progress[-1] == pytest.approx(1.0)
    repose("warp", "--input", tmp_path / "G.nii.gz", "--mesh", tmp_path / "tm.vtu", "--cage",
           tmp_path / "cage.obj", "--posed-cage", tmp_path / "posed.obj", "--out",
           tmp_path / "direct.nii.gz")
    # The same posed voxels: the LPS models were read in RAS (read as written, the cage would be
    # mirrored left-right and front-back and the mesh would leave it).
    info = json.loads(repose("info", tmp_path / "out_G.nrrd", "--json").stdout)
    direct = json.loads(repose("info", tmp_path / "direct.nii.gz", "--json").stdout)
    assert info["dimensions"] == direct["dimensions"]
    assert np.allclose(info["ijk_to_ras"], direct["ijk_to_ras"], atol=1e-6)
    assert {l["value"]: l["voxels"] for l in info["labels"]} == {
        l["value"]: l["voxels"] for l in direct["labels"]}
