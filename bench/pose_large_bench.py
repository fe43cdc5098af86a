#!/usr/bin/python3
"""The whole pose job at the seed's scale and beyond (issue 56; docs/PERFORMANCE.md, "The pose
job out of core"): `repose pose` of the arms-resting phantom on the adult male reference grid
(2.137 x 2.137 x 8 mm, with its CT), the suite's elbow flexion, written at 1 mm
and at 0.5 mm, in core (a budget that holds the frame), slab by slab (a 2 GiB budget) and slab
by slab over 2 MPI ranks (`--mpi`, 1 GiB each), and slab by slab as DICOM SEG (written in
pieces, or refused before the work beyond DICOM's 4 GiB; its voxels, read back, compared with the
streamed NIfTI's). Each run is one `repose pose` command timed with
its peak resident memory (/usr/bin/time -v; over MPI each rank's, the largest and their sum); the
rig is built once into a scene folder and reused, so the runs time the frame. The streamed files are
compared with the in-core ones where both exist (byte for byte; the colour tables after their
first line, which names the file).

    make bench-large    (runs this after bench/run_bench.py --large)
    /usr/bin/python3 bench/pose_large_bench.py --build build --out build/bench-pose-large

Prints and writes OUT/pose_large_bench.json. A 0.5 mm frame in core needs about 50 GiB: it is
listed as refused (the machine's 24 GiB), not run.
"""
import argparse
import json
import re
import subprocess
import sys
import time
from pathlib import Path

GRID = "2.137,2.137,8"


def run(args, check=True):
    started = time.monotonic()
    done = subprocess.run(["/usr/bin/time", "-v"] + [str(a) for a in args], capture_output=True,
                          text=True)
    seconds = time.monotonic() - started
    if check and done.returncode != 0:
        sys.exit(f"pose_large_bench: {' '.join(map(str, args[:3]))} failed:\n"
                 f"{done.stderr[-3000:]}")
    peak = re.search(r"Maximum resident set size \(kbytes\): (\d+)", done.stderr)
    return done, seconds, int(peak.group(1)) * 1024 if peak else None


def same_files(a, b):
    """The files of folder a in folder b, equal (colour tables after their first line)."""
    for f in sorted(Path(a).iterdir()):
        if f.name == "report.json":
            continue
        x, y = f.read_bytes(), (Path(b) / f.name).read_bytes()
        if f.suffix == ".ctbl":
            x, y = x[x.index(b"\n"):], y[y.index(b"\n"):]
        if x != y:
            return False
    ra = json.loads((Path(a) / "report.json").read_text())
    rb = json.loads((Path(b) / "report.json").read_text())
    ra.pop("streamed", None)
    rb.pop("streamed", None)
    return ra == rb


def number_of_frames(dcm):
    """A SEG's NumberOfFrames (0028,0008), from its header (explicit VR little endian)."""
    with open(dcm, "rb") as f:
        head = f.read(1 << 20)
    at = head.find(b"\x28\x00\x08\x00IS")
    length = head[at + 6] | head[at + 7] << 8
    return int(head[at + 8:at + 8 + length])


def same_voxels_as_dicom(nifti_folder, dcm_folder, build):
    """posed_G and posed_S of nifti_folder (NIfTI) voxel for voxel those of dcm_folder (DICOM SEG,
    read by Repose's Python module from `build`)."""
    import nibabel
    import numpy
    sys.path.insert(0, str(Path(build).resolve() / "python"))
    import repose
    for stem in ("posed_G", "posed_S"):
        a = numpy.asanyarray(nibabel.load(Path(nifti_folder) / f"{stem}.nii.gz").dataobj)
        b = repose.read_volume(str(Path(dcm_folder) / f"{stem}.dcm")).array
        if a.shape != b.shape or not numpy.array_equal(a, b):
            return False
        del a, b
    return True


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--build", default="build")
    p.add_argument("--out", default="build/bench-pose-large")
    p.add_argument("--spacings", default="1,0.5,0.45",
                   help="output voxel sizes in mm (0.45: beyond 2G voxels on this phantom)")
    p.add_argument("--streamed-memory", default="2G")
    p.add_argument("--in-core-memory", default="20G")
    p.add_argument("--ranks", type=int, default=2,
                   help="also run each frame slab by slab over this many MPI ranks (--mpi; 1: not)")
    p.add_argument("--ranks-memory", default="1G",
                   help="each rank's --memory over MPI (1G: the ranks share the 2 GiB)")
    p.add_argument("--in-core-below-voxels", type=float, default=1.2e9,
                   help="frames above this many output voxels are not run in core")
    a = p.parse_args()
    repose = str((Path(a.build) / "bin" / "repose").resolve())
    pose = Path(__file__).resolve().parent / "poses" / "elbow90.pose.json"
    out = Path(a.out).resolve()
    out.mkdir(parents=True, exist_ok=True)
    body = out / "body"
    if not (body / "G.nii.gz").exists():
        run([repose, "phantom", "--arms-resting", "--spacing", GRID, "--image", "--out", body])
    job = [repose, "pose", "--input", body / "G.nii.gz", "--parts", body / "S.nii.gz", "--image",
           body / "CT.nii.gz", "--pose", pose, "--scene", out / "scene", "--json"]
    # The rig, built once (a frame at the input's spacing), then reused by every run.
    run(job + ["--out", out / "rig_frame"])
    results = []
    for spacing in [float(s) for s in a.spacings.split(",")]:
        folders = {}
        runs = [("streamed", a.streamed_memory, 1)]
        if a.ranks > 1:
            runs.append(("streamed", a.ranks_memory, a.ranks))
        runs.append(("in core", a.in_core_memory, 1))
        # DICOM SEG slab by slab: written in pieces, or refused before the work when its frames
        # would pass DICOM's 4 GiB of pixel data.
        runs.append(("streamed dcmseg", a.streamed_memory, 1))
        for mode, memory, ranks in runs:
            name = f"frame_{spacing:g}mm_{mode.replace(' ', '_')}" + (
                f"_{ranks}ranks" if ranks > 1 else "")
            folder = out / name
            row = {"spacing_mm": spacing, "mode": mode, "memory": memory, "ranks": ranks}
            if mode == "in core" and any(r["spacing_mm"] == spacing and r.get(
                    "output_voxels", 0) > a.in_core_below_voxels for r in results):
                row["refused"] = "beyond this machine's memory in core"
                results.append(row)
                print(json.dumps(row), flush=True)
                continue
            args = job + ["--spacing-mm", spacing, "--memory", memory, "--out", folder]
            if mode == "streamed dcmseg":
                args += ["--output-format", "dcmseg"]
            if ranks > 1:
                # Each rank's own peak, as the ranks' /usr/bin/time print it.
                args = ["/usr/bin/mpirun", "-np", ranks, "--oversubscribe", "--allow-run-as-root",
                        "/usr/bin/time", "-f", "rank peak %M"] + args + ["--mpi"]
            done, seconds, peak = run(args, check=False)
            row.update({"seconds": round(seconds, 1), "peak_resident_bytes": peak,
                        "exit": done.returncode})
            if ranks > 1:
                peaks = [int(k) * 1024 for k in re.findall(r"rank peak (\d+)", done.stderr)]
                row["peak_resident_bytes"] = max(peaks) if peaks else None
                row["peak_resident_bytes_all_ranks"] = sum(peaks) if peaks else None
            if done.returncode in (0, 4):
                report = json.loads((folder / "report.json").read_text())
                dims = report["grid"]["dims"]
                row["output_voxels"] = dims[0] * dims[1] * dims[2]
                row["streamed"] = "streamed" in report
                if "streamed" in report:
                    row["slabs"] = report["streamed"]["slabs"]
                row["relabelled_voxels"] = report["label_volumes"]["relabelled_voxels"]
                row["targets_met"] = report["targets"]["met"]
                if "dicom_seg" in report:
                    # The frames checkDicomSegFits bounded before the work, and those written.
                    for name in ("posed_G.dcm", "posed_S.dcm"):
                        bound = report["dicom_seg"][name]["frames_bound"]
                        written = number_of_frames(folder / name)
                        row[name] = {"frames_bound": bound, "frames": written,
                                     "bound_over_frames": round(bound / written, 3)}
                folders[(mode, ranks)] = folder
            else:
                row["error"] = done.stderr.strip().splitlines()[-1][:300] if done.stderr else ""
            results.append(row)
            print(json.dumps(row), flush=True)
            if ranks > 1 and ("streamed", 1) in folders and (mode, ranks) in folders:
                same = same_files(folders[("streamed", 1)], folders[(mode, ranks)])
                row["same_as_one_rank"] = same
                print(f"{spacing:g} mm: {ranks} ranks' files {'equal' if same else 'DIFFER from'}"
                      " one rank's", flush=True)
        if ("streamed", 1) in folders and ("streamed dcmseg", 1) in folders:
            same = same_voxels_as_dicom(folders[("streamed", 1)], folders[("streamed dcmseg", 1)],
                                        a.build)
            next(r for r in results if r["spacing_mm"] == spacing and
                 r["mode"] == "streamed dcmseg")["same_voxels_as_streamed"] = same
            print(f"{spacing:g} mm: DICOM SEG's voxels {'equal' if same else 'DIFFER from'} the"
                  " streamed NIfTI's", flush=True)
        if ("in core", 1) in folders and ("streamed", 1) in folders:
            same = same_files(folders[("in core", 1)], folders[("streamed", 1)])
            next(r for r in results if r["spacing_mm"] == spacing and r["mode"] == "in core" and
                 r["ranks"] == 1)["same_as_in_core"] = same
            print(f"{spacing:g} mm: streamed files {'equal' if same else 'DIFFER from'} in core",
                  flush=True)
    (out / "pose_large_bench.json").write_text(json.dumps({"runs": results}, indent=2) + "\n")


if __name__ == "__main__":
    main()
