#!/usr/bin/python3
"""One run of every performance figure of docs/PERFORMANCE.md, each against a baseline measured
in the same run on the same data, at three or more sizes to show how the cost grows.

    make bench                      # quick: 4, 3 and 2 mm phantoms (2.5M-20M voxels), < 15 min
    make bench-large                # adds 1.1 mm (~120M) and 0.85 mm (~260M) phantoms and the
                                    # out-of-core run to ~860M output voxels under a 1 GiB budget

Figures (ours / baseline):
  rasterization      the posed label map in core / vtkProbeFilter + the same label lookup
                     (same deformed mesh and grid, in the same process); and file to file /
                     plastimatch warp --interpolation nn of G with our displacement field (field
                     computed by us and written uncompressed beforehand, not charged to them)
  frame              one interaction frame (Green coordinates + both rigidity solves) at three
                     mesh sizes / the same frame with dense double coordinates and Eigen's product
  live slice         one deformed-label slice / vtkProbeFilter of the same slice
  preprocessing      repose cage + repose mesh (TM and embedding) / the surface 3D Slicer builds
                     to show the segmentation (bench/slicer_surface_baseline.py)
  full deformation   repose warp, file to file (the seed's "CT" column) / repose warp in core
  out of core        repose warp --memory BUDGET / the same warp in core (time, peak RSS)

Writes OUT/results.json and OUT/bench_scaling.png and prints a table. Timings of whole commands
are wall clock from /usr/bin/time (with peak RSS); the rest are Google Benchmark medians.
"""
import argparse
import gzip
import json
import os
import platform
import shutil
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

SOURCE = Path(__file__).resolve().parent.parent
QUICK_SIZES_MM = [4.0, 3.0, 2.0]
LARGE_SIZES_MM = [1.1, 0.85]
FRAME_TM_MM = [17.0, 12.0, 8.5]          # ~7K, ~15K and ~36K transfer-mesh vertices
# Out of core in quick mode: the 2 mm phantom posed onto finer output grids (113M-430M voxels)
# within 400 MB, of which the 36K-vertex mesh's coefficients take ~314 MB whatever the grid.
QUICK_OOC = {"phantom_mm": 2.0, "spacings_mm": [1.25, 1.0, 0.8], "budget": "400M"}
# The spacing is chosen from the quick run's posed box; at finer spacings the grid's margins shrink
# relative to the body, so aiming at 900M gives ~860M (aiming at 860M gave 823M).
LARGE_OOC = {"phantom_mm": 0.85, "target_voxels": 900e6, "budget": "1G"}

# The seed's Table 1 (its own hardware): model, voxels, cage vertices, FPS, TM vertices, CT.
SEED_TABLE = [
    ("Thelonious", "122M", 303, 11, 36157, "2m31"),
    ("Eartha", "243M", 479, 9, 33308, "3m10"),
    ("Louis", "260M", 512, 7, 27588, "4m03"),
    ("Dizzy", "141M", 479, 10, 29226, "2m38"),
    ("LR Visible Human", "108M", 152, 11, 17036, "1m28"),
    ("HR Visible Human (out of core, 862M grid)", "374M", None, None, None, "11m33"),
]


def log(message):
    print(f"[bench {time.strftime('%H:%M:%S')}] {message}", flush=True)


def run(cmd, env=None, capture=True):
    """Runs cmd under /usr/bin/time; returns (stdout, wall seconds, peak RSS bytes)."""
    timing = Path(os.environ.get("TMPDIR", "/tmp")) / f"repose-bench-time-{os.getpid()}"
    full = ["/usr/bin/time", "-f", "%e %M", "-o", str(timing)] + [str(c) for c in cmd]
    result = subprocess.run(full, env={**os.environ, **(env or {})}, text=True,
                            stdout=subprocess.PIPE if capture else None)
    if result.returncode != 0:
        sys.exit(f"bench: command failed ({result.returncode}): {' '.join(full[5:])}")
    wall, kb = timing.read_text().split()[-2:]
    timing.unlink()
    return result.stdout, float(wall), int(kb) * 1024


def gbench(binary, out_json, env, filter_regex, min_time):
    run([binary, f"--benchmark_filter={filter_regex}", f"--benchmark_min_time={min_time}",
         f"--benchmark_out={out_json}", "--benchmark_out_format=json"], env=env)
    data = json.loads(Path(out_json).read_text())
    return {b["name"]: b for b in data["benchmarks"]}


def ms(entry):
    scale = {"ns": 1e-6, "us": 1e-3, "ms": 1.0, "s": 1e3}[entry["time_unit"]]
    return entry["real_time"] * scale


def nifti_voxels(path):
    import nibabel
    return int(np.prod(nibabel.load(str(path)).shape[:3]))


def raw_field_copy(src, dst):
    """The gzip NRRD field rewritten raw, so a baseline reading it is not charged the gunzip."""
    with open(src, "rb") as f:
        data = f.read()
    end = data.index(b"\n\n") + 2
    header = data[:end].decode().replace("encoding: gzip", "encoding: raw")
    with open(dst, "wb") as out:
        out.write(header.encode())
        out.write(gzip.decompress(data[end:]))


def elbow_posed_cage(cage, skeleton, out):
    """The cage with the left arm below the elbow turned 60 degrees forward about the elbow:
    a non-rigid pose (the cage bends at the joint), the one of docs/PERFORMANCE.md's warp runs."""
    joints = {j["name"]: np.array(j["ras"]) for j in json.loads(skeleton.read_text())["joints"]}
    elbow, shoulder = joints["elbow_left"], joints["shoulder_left"]
    vertices, faces = [], []
    for line in cage.read_text().splitlines():
        parts = line.split()
        if parts and parts[0] == "v":
            vertices.append([float(x) for x in parts[1:4]])
        elif parts and parts[0] == "f":
            faces.append(" ".join(p.split("/")[0] for p in parts[1:4]))
    vertices = np.array(vertices)
    a = np.radians(60)
    rot = np.array([[1, 0, 0], [0, np.cos(a), -np.sin(a)], [0, np.sin(a), np.cos(a)]])
    arm = (vertices[:, 2] < elbow[2]) & (vertices[:, 0] < shoulder[0] + 25)
    posed = vertices.copy()
    posed[arm] = (vertices[arm] - elbow) @ rot.T + elbow
    lines = [f"v {x:.9g} {y:.9g} {z:.9g}" for x, y, z in posed] + [f"f {f}" for f in faces]
    out.write_text("\n".join(lines) + "\n")


class Bench:
    def __init__(self, args):
        self.build = Path(args.build).resolve()
        self.bin = self.build / "bin"
        self.out = Path(args.out).resolve()
        self.work = self.out / "work"
        self.large = args.large
        self.figures = []
        self.work.mkdir(parents=True, exist_ok=True)

    def repose(self, *args, env=None):
        return run([self.bin / "repose", *args], env=env)

    def add(self, figure, size, voxels, ours, ours_unit, baseline_name, baseline, ratio,
            target=None, met=None, **extra):
        row = {"figure": figure, "size": size, "voxels": voxels, "ours": ours,
               "unit": ours_unit, "baseline": baseline_name, "baseline_value": baseline,
               "ratio": ratio, "target": target, "met": met, **extra}
        self.figures.append(row)
        tail = f"; target {target}: {'met' if met else 'NOT met'}" if target else ""
        log(f"{figure} [{size}]: ours {ours:.4g} {ours_unit}, {baseline_name} "
            f"{baseline:.4g}, ratio {ratio:.3g}{tail}")

    # --- phantoms -------------------------------------------------------------------------
    def phantom(self, mm):
        folder = self.work / f"phantom_{mm:g}mm"
        if not (folder / "S.nii.gz").exists():
            log(f"phantom at {mm:g} mm")
            self.repose("phantom", "--voxel", mm, "--out", folder)
        return folder

    # --- rasterization and live slices (ReposeRasterBench) ----------------------------------
    def rasterization(self, mm, with_slices):
        folder = self.work / f"raster_{mm:g}mm"
        folder.mkdir(exist_ok=True)
        env = {"REPOSE_RASTER_VOXEL_MM": f"{mm:g}", "REPOSE_RASTER_EXPORT_DIR": str(folder)}
        regex = "BM_RasterizeLabels|BM_VtkProbeFilterBaseline"
        if with_slices:
            regex += "|BM_LiveSlice|BM_VtkProbeSliceBaseline"
        log(f"rasterization at {mm:g} mm{' with live slices' if with_slices else ''}")
        b = gbench(self.bin / "ReposeRasterBench", folder / "raster.json", env, regex, 1.0)
        voxels = nifti_voxels(folder / "posed_G.nii")
        ours = ms(b["BM_RasterizeLabels/real_time"])
        vtk = ms(b["BM_VtkProbeFilterBaseline/iterations:1/real_time"])
        self.add("rasterization in core", f"{mm:g} mm", voxels, ours, "ms", "vtkProbeFilter", vtk,
                 vtk / ours, target=">= 20x", met=vtk / ours >= 20,
                 ours_voxels_per_s=voxels / ours * 1e3)

        # plastimatch: G.nii warped by our field (raw NRRD), nearest neighbour, file to file.
        field = folder / "transform_raw.nrrd"
        raw_field_copy(folder / "transform.nrrd", field)
        (folder / "transform.nrrd").unlink()
        _, wall, rss = run(["plastimatch", "warp", "--input", folder / "G.nii", "--xf", field,
                            "--output-img", folder / "plastimatch.nii", "--interpolation", "nn",
                            "--output-type", "uchar"])
        import nibabel
        theirs = np.asarray(nibabel.load(str(folder / "plastimatch.nii")).dataobj)
        ours_labels = np.asarray(nibabel.load(str(folder / "posed_G.nii")).dataobj)
        agree = float(np.mean(theirs == ours_labels)) if theirs.shape == ours_labels.shape else 0.0
        file_ms = ms(b["BM_RasterizeLabelsFileToFile/real_time"])
        self.add("rasterization file to file", f"{mm:g} mm", voxels, file_ms, "ms",
                 "plastimatch warp (nn)", wall * 1e3, wall * 1e3 / file_ms,
                 plastimatch_peak_rss=rss, agreement=agree)
        for f in ("transform_raw.nrrd", "plastimatch.nii", "ours_file.nii"):
            (folder / f).unlink(missing_ok=True)

        if with_slices:
            names = {0: "axial", 1: "coronal", 2: "sagittal"}
            for o in (0, 1, 2):
                for size in ((256, 512, 1024) if o == 0 else (512,)):
                    ours = ms(b[f"BM_LiveSlice/{o}/0/{size}/real_time"])
                    vtk = ms(b[f"BM_VtkProbeSliceBaseline/{o}/{size}/real_time"])
                    target = "<= 10 ms" if size == 512 else None
                    self.add("live slice", f"{names[o]} {size}x{size}, {mm:g} mm", size * size,
                             ours, "ms", "vtkProbeFilter", vtk, vtk / ours, target=target,
                             met=(ours <= 10) if target else None)

    # --- interaction frame (ReposeFrameBench) ------------------------------------------------
    def frame(self, tm_mm):
        out = self.work / f"frame_{tm_mm:g}.json"
        log(f"interaction frame, TM size {tm_mm:g} mm")
        b = gbench(self.bin / "ReposeFrameBench", out, {"REPOSE_FRAME_TM_MM": f"{tm_mm:g}"},
                   "BM_Frame/|BM_FrameDenseBaseline", 1.0)
        vertices = int(b["BM_Frame/preview/real_time"]["TM_vertices"])
        dense = ms(b["BM_FrameDenseBaseline/real_time"])
        for mode in ("preview", "exact"):
            ours = ms(b[f"BM_Frame/{mode}/real_time"])
            self.add(f"frame ({mode})", f"TM {vertices} vertices, cage 495", vertices, ours,
                     "ms", "dense double Green coordinates (Eigen)", dense, dense / ours,
                     target="<= 16 ms", met=ours <= 16)

    # --- the workbench's live path end to end (ReposeLiveBench, issue 25) --------------------
    def live(self):
        """A scripted drag of 200 events through the Logic on the seed's rig size (the 2 mm
        phantom, 500 cage vertices, 8.5 mm tets: ~36-41K transfer-mesh vertices): the group's
        motion and the frame it triggers, then three 512-pixel slices."""
        tool = self.bin / "ReposeLiveBench"
        if not tool.exists():
            log("live path: skipped (built without the GUI layers)")
            return
        p = self.phantom(2.0)
        scene = self.work / "live_scene"
        if not (scene / "scene.json").exists():
            log("live path: rig of the 2 mm phantom, 500 cage vertices, 8.5 mm tets")
            self.repose("pose", "--input", p / "G.nii.gz", "--parts", p / "S.nii.gz", "--pose",
                        SOURCE / "bench/poses/elbow90.pose.json", "--scene", scene,
                        "--cage-vertices", 500, "--mesh-mm", 8.5, "--out",
                        self.work / "live_pose")
        log("live path: 200 drag events, three 512-pixel slices each")
        out, _, _ = run([tool, scene, "--events", 200, "--pixels", 512])
        r = json.loads(out)
        size = f"TM {r['tm_vertices']} vertices, cage {r['cage_vertices']}, 3 slices 512 px"
        event = r["stages"]["event"]
        self.add("live path end to end (median)", size, r["tm_vertices"], event["median_ms"],
                 "ms", "", float("nan"), float("nan"), target="<= 16 ms",
                 met=event["median_ms"] <= 16, stages=r["stages"], prepare_ms=r["prepare_ms"])
        self.add("live path end to end (p99)", size, r["tm_vertices"], event["p99_ms"], "ms",
                 "", float("nan"), float("nan"), target="<= 25 ms", met=event["p99_ms"] <= 25)
        for stage in ("frame", "edit_outside_frame", "slice_axial", "slice_coronal",
                      "slice_sagittal"):
            s = r["stages"][stage]
            self.add(f"live path: {stage.replace('_', ' ')} (median / p99)", size,
                     r["tm_vertices"], s["median_ms"], "ms", "p99", s["p99_ms"],
                     s["p99_ms"] / s["median_ms"] if s["median_ms"] > 0 else float("nan"))
        # When a drag ends: what the asking thread (the panel's event loop) pays for the
        # prediction, and how long until it is ready on the Logic's worker (issue 66).
        for stage, target in (("prediction_request", 16), ("prediction", 100)):
            s = r["stages"][stage]
            self.add(f"live path: {stage.replace('_', ' ')} (median / p99)", size,
                     r["tm_vertices"], s["median_ms"], "ms", "p99", s["p99_ms"],
                     s["p99_ms"] / s["median_ms"] if s["median_ms"] > 0 else float("nan"),
                     target=f"<= {target} ms", met=s["median_ms"] <= target)
        # The same drag with the left upper arm's cage vertices free: the cage's ARAP, warm-started
        # from event to event (PoseRig::liveFrame), is in every frame.
        log("live path: the same drag with free cage vertices (warm-started ARAP)")
        out, _, _ = run([tool, scene, "--events", 200, "--pixels", 512, "--pose",
                         SOURCE / "bench/live/elbow90_free_upper_arm.pose.json"])
        r = json.loads(out)
        for stage in ("frame", "event"):
            s = r["stages"][stage]
            self.add(f"live path, free cage vertices: {stage} (median / p99)", size,
                     r["tm_vertices"], s["median_ms"], "ms", "p99", s["p99_ms"],
                     s["p99_ms"] / s["median_ms"] if s["median_ms"] > 0 else float("nan"))

    # --- preprocessing and whole-file deformation ----------------------------------------------
    def preprocessing_and_warp(self, mm):
        p = self.phantom(mm)
        voxels = nifti_voxels(p / "S.nii.gz")
        log(f"preprocessing at {mm:g} mm ({voxels / 1e6:.1f}M voxels)")
        out, cage_s, cage_rss = self.repose("cage", "--parts", p / "S.nii.gz", "--out",
                                            p / "cage.obj", "--vertices", 500, "--json")
        cage_vertices = json.loads(out).get("vertices")
        out, mesh_s, mesh_rss = self.repose("mesh", "--parts", p / "S.nii.gz", "--cage",
                                            p / "cage.obj", "--out", p / "tm.vtu", "--size-mm",
                                            8.5, "--json")
        tm_vertices = json.loads(out).get("vertices")
        out, wall, rss = run([sys.executable, SOURCE / "bench/slicer_surface_baseline.py",
                              p / "G.nii.gz"])
        ours = cage_s + mesh_s
        self.add("preprocessing (cage + TM + embedding)", f"{mm:g} mm", voxels, ours, "s",
                 "Slicer 3D surface of G (VTK)", wall, wall / ours, target="<= 60 s",
                 met=ours <= 60, cage_vertices=cage_vertices, tm_vertices=tm_vertices,
                 peak_rss=max(cage_rss, mesh_rss), baseline_triangles=json.loads(out)["triangles"])

        elbow_posed_cage(p / "cage.obj", p / "skeleton.json", p / "posed.obj")
        log(f"full deformation at {mm:g} mm")
        warp = ["warp", "--input", p / "G.nii.gz", "--mesh", p / "tm.vtu", "--cage",
                p / "cage.obj", "--posed-cage", p / "posed.obj", "--json"]
        # As a saved rig is used (the Green coordinates `repose mesh` wrote beside tm.vtu), and
        # with the coordinates computed again (no file): what keeping them saves.
        out, wall, rss = self.repose(*warp, "--out", p / "posed.nii.gz", "--memory", "16G")
        saved = json.loads(out)
        posed_voxels = nifti_voxels(p / "posed.nii.gz")
        (p / "posed.nii.gz").unlink()
        out, computed_wall, computed_rss = self.repose(
            *warp, "--out", p / "posed.nii.gz", "--memory", "16G", "--coordinates",
            p / "no_such.green")
        computed = json.loads(out)
        (p / "posed.nii.gz").unlink()
        if not saved["green_coordinates"]["read"] or computed["green_coordinates"]["read"]:
            sys.exit(f"bench: warp at {mm:g} mm did not read / compute the Green coordinates "
                     f"as asked: {saved['green_coordinates']}, {computed['green_coordinates']}")
        self.add("full deformation, file to file (repose warp)", f"{mm:g} mm", posed_voxels,
                 wall, "s", "coordinates computed again", computed_wall, computed_wall / wall,
                 target="<= 5 s at 260M input voxels" if voxels > 2e8 else None,
                 met=(wall <= 5) if voxels > 2e8 else None, peak_rss=rss,
                 input_voxels=voxels, deformation_s=saved["deformation_seconds"],
                 computed_deformation_s=computed["deformation_seconds"],
                 computed_peak_rss=computed_rss)

    # --- out of core -----------------------------------------------------------------------
    def out_of_core(self, phantom_mm, spacing_mm, budget, label, proxy=False):
        p = self.phantom(phantom_mm)
        if not (p / "posed.obj").exists():
            self.preprocessing_and_warp(phantom_mm)
        cage, mesh = p / "cage.obj", p / "tm.vtu"
        extra = {}
        if proxy:
            # The seed's out-of-core case: cage and mesh made on a proxy within the budget too.
            log(f"cage and mesh within {budget} at {phantom_mm:g} mm")
            cage, mesh = p / "cage_budget.obj", p / "tm_budget.vtu"
            _, cs, cr = self.repose("cage", "--parts", p / "S.nii.gz", "--out", cage,
                                    "--vertices", 500, "--memory", budget)
            _, ms_, mr = self.repose("mesh", "--parts", p / "S.nii.gz", "--cage", cage, "--out",
                                     mesh, "--size-mm", 8.5, "--memory", budget)
            elbow_posed_cage(cage, p / "skeleton.json", p / "posed_budget.obj")
            extra = {"proxy_cage_s": cs, "proxy_cage_peak_rss": cr, "proxy_mesh_s": ms_,
                     "proxy_mesh_peak_rss": mr}
        posed = p / ("posed_budget.obj" if extra else "posed.obj")
        warp = ["warp", "--input", p / "G.nii.gz", "--mesh", mesh, "--cage", cage,
                "--posed-cage", posed, "--spacing-mm", spacing_mm, "--json"]
        log(f"out of core: {label}, output spacing {spacing_mm:g} mm, budget {budget}")
        out, ooc_s, ooc_rss = self.repose(*warp, "--out", p / "posed_ooc.nii.gz", "--memory",
                                          budget)
        if not json.loads(out)["out_of_core"]:
            sys.exit(f"bench: {label} fits in {budget}: not an out-of-core run")
        voxels = nifti_voxels(p / "posed_ooc.nii.gz")
        _, in_s, in_rss = self.repose(*warp, "--out", p / "posed_in.nii.gz", "--memory", "20G")
        same = subprocess.run(f"cmp -s <(zcat {p}/posed_ooc.nii.gz) <(zcat {p}/posed_in.nii.gz)",
                              shell=True, executable="/bin/bash").returncode == 0
        for f in ("posed_ooc.nii.gz", "posed_in.nii.gz"):
            (p / f).unlink()
        limit = _bytes(budget)
        self.add("out of core: peak RSS", label, voxels, ooc_rss / 2**20, "MiB",
                 "in core", in_rss / 2**20, in_rss / ooc_rss, target=f"<= {budget}",
                 met=ooc_rss <= limit, identical_to_in_core=same, **extra)
        self.add("out of core: wall clock", label, voxels, ooc_s, "s", "in core", in_s,
                 in_s / ooc_s)
        return voxels

    # --- report ---------------------------------------------------------------------------
    def machine(self):
        cpu = next((l.split(":", 1)[1].strip() for l in open("/proc/cpuinfo")
                    if l.startswith("model name")), platform.processor())
        mem = next(int(l.split()[1]) * 1024 for l in open("/proc/meminfo")
                   if l.startswith("MemTotal"))
        rev = subprocess.run(["git", "-C", SOURCE, "rev-parse", "--short", "HEAD"], text=True,
                             capture_output=True).stdout.strip()
        return {"cpu": cpu, "cores": os.cpu_count(), "memory_bytes": mem,
                "os": platform.platform(), "commit": rev, "date": time.strftime("%Y-%m-%d %H:%M")}

    def table(self):
        rows = [("figure", "size", "voxels", "ours", "baseline", "baseline value", "ratio",
                 "target")]
        for f in self.figures:
            base = "" if f["baseline_value"] != f["baseline_value"] else f"{f['baseline_value']:.4g}"
            ratio = "" if f["ratio"] != f["ratio"] else f"{f['ratio']:.3g}x"
            target = (f"{f['target']} {'met' if f['met'] else 'NOT met'}" if f["target"] else "")
            rows.append((f["figure"], f["size"], f"{f['voxels'] / 1e6:.3g}M",
                         f"{f['ours']:.4g} {f['unit']}", f["baseline"], base, ratio, target))
        widths = [max(len(r[i]) for r in rows) for i in range(len(rows[0]))]
        lines = ["  ".join(c.ljust(w) for c, w in zip(r, widths)) for r in rows]
        lines.insert(1, "  ".join("-" * w for w in widths))
        seed = ["", "The seed's Table 1 (its own hardware, for reference, not a ratio):",
                "model  voxels  cage vertices  FPS  TM vertices  CT"]
        seed += [f"{m}  {v}  {c or '-'}  {f or '-'}  {t or '-'}  {ct}"
                 for m, v, c, f, t, ct in SEED_TABLE]
        return "\n".join(lines + seed)

    def markdown(self):
        """The table of docs/PERFORMANCE.md, from this run."""
        lines = ["| figure | size | output voxels | Repose | baseline (same run) | ratio | target |",
                 "|---|---|---|---|---|---|---|"]
        for f in self.figures:
            base = ("—" if f["baseline_value"] != f["baseline_value"]
                    else f"{f['baseline']}: {f['baseline_value']:.4g} {f['unit']}")
            ratio = "—" if f["ratio"] != f["ratio"] else f"{f['ratio']:.3g}×"
            target = f"{f['target']}: {'met' if f['met'] else '**not met**'}" if f["target"] else ""
            voxels = "—" if f["figure"].startswith("frame") else f"{f['voxels'] / 1e6:.3g}M"
            lines.append(f"| {f['figure']} | {f['size']} | {voxels} | "
                         f"{f['ours']:.4g} {f['unit']} | {base} | {ratio} | {target} |")
        return "\n".join(lines) + "\n"

    def plot(self, path):
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        fig, ax = plt.subplots(figsize=(8, 5.5))
        series = [
            ("rasterization in core", "ours", "Repose rasterization (in core)", "o-"),
            ("rasterization in core", "baseline", "vtkProbeFilter (same mesh and grid)", "s--"),
            ("rasterization file to file", "ours", "Repose file to file", "o-"),
            ("rasterization file to file", "baseline", "plastimatch warp (nn, given the field)",
             "s--"),
            ("full deformation, file to file (repose warp)", "ours",
             "repose warp (read, pose, rasterize, gzip write)", "^-"),
            ("out of core: wall clock", "ours", "repose warp out of core", "v-"),
        ]
        for figure, which, label, style in series:
            rows = sorted((f for f in self.figures if f["figure"] == figure),
                          key=lambda f: f["voxels"])
            if not rows:
                continue
            scale = 1e-3 if rows[0]["unit"] == "ms" else 1.0
            y = [(f["ours"] if which == "ours" else f["baseline_value"]) * scale for f in rows]
            ax.loglog([f["voxels"] for f in rows], y, style, label=label)
        ax.set_xlabel("output voxels")
        ax.set_ylabel("wall-clock time (s)")
        ax.set_title("Posing a label map: time against size (this machine, one run)")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=8)
        fig.tight_layout()
        fig.savefig(path, dpi=110)


def _bytes(text):
    units = {"K": 2**10, "M": 2**20, "G": 2**30}
    return int(float(text[:-1]) * units[text[-1]]) if text[-1] in units else int(text)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--build", default="build", help="build folder (default: build)")
    parser.add_argument("--out", default="build/bench", help="results folder")
    parser.add_argument("--large", action="store_true",
                        help="add the seed's scales: ~120M and ~260M in core, ~860M out of core")
    parser.add_argument("--plot", help="also copy the plot here (e.g. docs/images/...)")
    args = parser.parse_args()
    for tool in ("plastimatch", "/usr/bin/time"):
        if not shutil.which(tool):
            sys.exit(f"bench: {tool} is missing (scripts/install-deps.sh installs it)")
    bench = Bench(args)
    start = time.time()
    sizes = QUICK_SIZES_MM + (LARGE_SIZES_MM if args.large else [])
    for mm in sizes:
        bench.rasterization(mm, with_slices=(mm == 2.0))
    for tm_mm in FRAME_TM_MM:
        bench.frame(tm_mm)
    bench.live()
    for mm in sizes:
        bench.preprocessing_and_warp(mm)
    for spacing in QUICK_OOC["spacings_mm"]:
        bench.out_of_core(QUICK_OOC["phantom_mm"], spacing, QUICK_OOC["budget"],
                          f"2 mm phantom to {spacing:g} mm")
    if args.large:
        # Choose the output spacing that gives ~860M voxels: the posed body's box in mm is the
        # same at every voxel size, so take it from the quick 2 mm run.
        box_mm3 = next(f["voxels"] * 2.0**3 for f in bench.figures
                       if f["figure"].startswith("full deformation") and f["size"] == "2 mm")
        spacing = round((box_mm3 / LARGE_OOC["target_voxels"]) ** (1 / 3), 3)
        bench.out_of_core(LARGE_OOC["phantom_mm"], spacing, LARGE_OOC["budget"],
                          f"{LARGE_OOC['phantom_mm']:g} mm phantom to {spacing:g} mm", proxy=True)
    results = {"machine": bench.machine(), "mode": "large" if args.large else "quick",
               "seconds": time.time() - start, "figures": bench.figures,
               "seed_table_1": [dict(zip(("model", "voxels", "cage_vertices", "fps",
                                          "tm_vertices", "ct"), r)) for r in SEED_TABLE]}
    (bench.out / "results.json").write_text(json.dumps(results, indent=1))
    (bench.out / "results.md").write_text(bench.markdown())
    bench.plot(bench.out / "bench_scaling.png")
    if args.plot:
        shutil.copy(bench.out / "bench_scaling.png", args.plot)
    print()
    print(bench.table())
    print(f"\nbench: {len(bench.figures)} figures in {results['seconds'] / 60:.1f} min; "
          f"{bench.out / 'results.json'}, {bench.out / 'bench_scaling.png'}")


if __name__ == "__main__":
    main()
