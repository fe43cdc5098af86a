"""Plane-wave SAR of a body model written by `repose export-fdtd`, with openEMS (docs/DOSIMETRY.md).

    import repose.openems as oe
    oe.require_csxcad_fix()                       # or run the script through oe.reexec_with_csxcad_fix
    r = oe.plane_wave_sar("posed.h5", propagation="-y", polarization="z")
    print(r.whole_body_sar_w_kg, r.peak_10g_sar_w_kg, r.balance)

The model (MODEL.h5 + MODEL.csx.xml + MODEL.json) is loaded as a CSXCAD discrete material, meshed
on its own cells (one FDTD cell per model cell, each cell one material: openEMS's cell-constant
material mode), surrounded by air, a total-field/scattered-field plane wave and PML, and run with
a Gaussian pulse around the model's frequency. The results are normalised to an incident power
density of 1 W/m^2 (the plane wave's S = |E|^2 / (2 eta0), E the peak phasor).

- Absorbed power: from the E field on the cells' edges (the Yee grid's own unknowns), per cell
  P = 1/2 sigma_cell sum_c mean_{4 edges along c} |E_c|^2 V_cell. Summed over the body this is
  the FDTD's own dissipation, which the net inflow through a closed box around the body must
  equal (`balance`: inflow / absorbed; the physics check of Testing/Python/test_openems_sar.py).
- Whole-body SAR: absorbed power / body mass (cells with a density).
- Peak 10 g SAR: the peak spatial-average SAR by IEC/IEEE 62704-1's cube rules
  (repose.average_sar, Core's dosimetry/SarAveraging.h: cubes of 10 g to 1e-6 centred on each
  tissue cell with at most 10 % air and every face touching tissue; cells no such cube holds get
  the cube behind one of their faces). Debian 12's openEMS cannot do it: its 10 g averaging (SAR
  dump 22) aborts the process on body models (its cube search divides by a zero mass step:
  "invalid averaging box size!! EXIT", fixed upstream in 2025). The simple cube of IEEE C95.3
  (cube_averaged_sar, which matches openEMS's IEEE_C95_3 averaging, Testing/Python) is kept
  beside it for comparison.
- openEMS's local SAR dump is kept for comparison (`openems_absorbed_w`): it takes the field
  interpolated to cell centres, which under-resolved cells (a few per wavelength in tissue)
  underestimate.

Debian 12's CSXCAD cannot read discrete materials without libReposeCsxcadFix preloaded
(Dosimetry/CsxcadDiscMaterialRead.cpp): require_csxcad_fix() says so in one line.
"""

from __future__ import annotations

import json
import os
import pathlib
import sys
import tempfile
import time
from typing import NamedTuple, Optional, Sequence

import numpy as np

ETA0 = 376.730313668  # impedance of free space, ohm
FIX_LIBRARY = "libReposeCsxcadFix.so"


def csxcad_fix_library() -> Optional[str]:
    """The path of libReposeCsxcadFix: $REPOSE_CSXCAD_FIX, else beside the build or install tree."""
    given = os.environ.get("REPOSE_CSXCAD_FIX")
    if given:
        return given if os.path.exists(given) else None
    here = pathlib.Path(__file__).resolve().parent
    for candidate in (here.parents[1] / "lib" / FIX_LIBRARY,        # build/python/repose
                      here.parents[2] / "repose" / FIX_LIBRARY):    # <prefix>/lib/python3/...
        if candidate.exists():
            return str(candidate)
    return None


def csxcad_fix_loaded() -> bool:
    with open("/proc/self/maps") as maps:
        return any(FIX_LIBRARY in line for line in maps)


def require_csxcad_fix() -> None:
    if not csxcad_fix_loaded():
        lib = csxcad_fix_library() or FIX_LIBRARY
        raise RuntimeError(
            "openEMS's CSXCAD (Debian 12) reads discrete materials only with the fix preloaded: "
            f"run with LD_PRELOAD={lib}")


def reexec_with_csxcad_fix(argv: Sequence[str] = None) -> None:
    """For scripts: restart this interpreter with the fix preloaded, unless it already is."""
    if csxcad_fix_loaded():
        return
    lib = csxcad_fix_library()
    if lib is None:
        raise RuntimeError(f"{FIX_LIBRARY} not found: build Repose with libopenems-dev installed, "
                           "or set REPOSE_CSXCAD_FIX")
    env = dict(os.environ)
    env["LD_PRELOAD"] = ":".join(p for p in (env.get("LD_PRELOAD"), lib) if p)
    args = [sys.executable] + list(argv if argv is not None else sys.argv)
    os.execve(sys.executable, args, env)


class Model(NamedTuple):
    """A model written by `repose export-fdtd`, read back: cells along R, A, S (x fastest)."""
    h5: str
    xml: str
    report: dict
    index: np.ndarray          # [x, y, z] material index
    spacing_mm: np.ndarray
    corner_mm: np.ndarray
    sigma: np.ndarray          # per material, S/m
    density: np.ndarray        # per material, kg/m^3
    frequency_hz: float

    def lines_mm(self, axis: int, first: int, last: int) -> np.ndarray:
        """Cell boundaries `first`..`last` (model cell indices, may lie outside the model)."""
        return self.corner_mm[axis] + np.arange(first, last + 1) * self.spacing_mm[axis]


def read_model(h5_path: str) -> Model:
    import h5py
    h5 = pathlib.Path(h5_path)
    stem = str(h5)[:-len(".h5")]
    with open(stem + ".json") as f:
        report = json.load(f)
    with h5py.File(h5, "r") as f:
        index = np.asarray(f["/DiscData"]).transpose(2, 1, 0)
    materials = report["materials"]
    return Model(str(h5), stem + ".csx.xml", report, index,
                 np.array(report["grid"]["spacing_mm"], float),
                 np.array(report["grid"]["corner_ras_mm"], float),
                 np.array([m["sigma_s_m"] for m in materials], float),
                 np.array([m["density_kg_m3"] for m in materials], float),
                 float(report["frequency_hz"]))


class PlaneWaveResult(NamedTuple):
    frequency_hz: float
    propagation: str
    polarization: str
    cells: int                    # FDTD cells, PML included
    seconds: float
    mass_kg: float                # cells with a density
    absorbed_w: float             # per W/m^2 incident, from the edge fields
    inflow_w: float               # per W/m^2 incident, net Poynting flux into a box round the body
    openems_absorbed_w: float     # per W/m^2 incident, openEMS's SAR dump (cell-centre field)
    whole_body_sar_w_kg: float    # per W/m^2 incident
    peak_10g_sar_w_kg: float      # per W/m^2 incident, IEC/IEEE 62704-1 (repose.average_sar)
    peak_10g_ras_mm: list         # the centre of the cell whose cube that is (RAS mm)
    peak_10g_rule: str            # how that cell was averaged: centred, covered or face_cube
    peak_10g_c95_3_w_kg: float    # per W/m^2 incident, the simple cube (cube_averaged_sar)
    averaging_counts: dict        # tissue cells per averaging rule (repose.average_sar's counts)
    local_sar_w_kg: np.ndarray    # per W/m^2 incident, per model cell [x, y, z] (edge-based)

    @property
    def balance(self) -> float:
        """Net inflow / absorbed power: 1 when the energy balance holds."""
        return self.inflow_w / self.absorbed_w

    def as_dict(self) -> dict:
        d = self._asdict()
        d.pop("local_sar_w_kg")
        d["balance"] = self.balance
        return d


_AXES = {"x": 0, "y": 1, "z": 2}


def cube_averaged_sar(power_w: np.ndarray, mass_kg: np.ndarray, target_kg: float = 0.010):
    """Per cell with mass: the mean SAR (W/kg) over the cube centred on it that holds target_kg.

    Cubes of (2h+1)^3 cells grow until they hold the target; the last shell is taken in the
    fraction that completes the target (its cells in proportion), so the mean is power over
    exactly target_kg. Cubes reaching the grid's border are clipped there. Cells without mass
    get 0."""
    def box_sums(a):
        c = np.zeros(tuple(n + 1 for n in a.shape))
        c[1:, 1:, 1:] = a.cumsum(0).cumsum(1).cumsum(2)
        return c

    cp, cm = box_sums(power_w), box_sums(mass_kg)
    shape = np.array(mass_kg.shape)
    tissue = np.argwhere(mass_kg > 0)
    result = np.zeros(mass_kg.shape)
    if tissue.size == 0:
        return result

    def within(h):
        lo = np.maximum(tissue - h, 0)
        hi = np.minimum(tissue + h + 1, shape)
        def s(c):
            return (c[hi[:, 0], hi[:, 1], hi[:, 2]] - c[lo[:, 0], hi[:, 1], hi[:, 2]]
                    - c[hi[:, 0], lo[:, 1], hi[:, 2]] - c[hi[:, 0], hi[:, 1], lo[:, 2]]
                    + c[lo[:, 0], lo[:, 1], hi[:, 2]] + c[lo[:, 0], hi[:, 1], lo[:, 2]]
                    + c[hi[:, 0], lo[:, 1], lo[:, 2]] - c[lo[:, 0], lo[:, 1], lo[:, 2]])
        return s(cp), s(cm)

    done = np.zeros(len(tissue), bool)
    mean = np.zeros(len(tissue))
    p_in, m_in = np.zeros(len(tissue)), np.zeros(len(tissue))
    for h in range(int(shape.max())):
        p, m = within(h)
        reach = (~done) & (m >= target_kg)
        t = (target_kg - m_in[reach]) / np.maximum(m[reach] - m_in[reach], 1e-300)
        mean[reach] = (p_in[reach] + t * (p[reach] - p_in[reach])) / target_kg
        done |= reach
        p_in, m_in = p, m
        if done.all():
            break
    mean[~done] = p_in[~done] / np.maximum(m_in[~done], 1e-300)  # the whole grid holds less
    result[tuple(tissue.T)] = mean
    return result


def iec62704_peak(power_w: np.ndarray, density: np.ndarray, spacing_mm, mass_kg: float = 0.010,
                  threads: int = 0):
    """The peak spatial-average SAR (W/kg) of per-cell power (W) on a uniform grid of density
    (kg/m^3), by IEC/IEEE 62704-1's cube rules (repose.average_sar, which counts all beyond the
    grid as air); the cell whose cube that is; the rule that cell was averaged by ("centred",
    "covered", "face_cube"); and the tissue cells per rule."""
    from . import average_sar
    spacing_m = np.asarray(spacing_mm, float) * 1e-3
    volume = float(np.prod(spacing_m))
    with np.errstate(divide="ignore", invalid="ignore"):
        sar = np.where(density > 0, power_w / (density * volume), 0.0)
    edges = [np.arange(density.shape[a] + 1) * spacing_m[a] for a in range(3)]
    r = average_sar(density, sar, *edges, mass_kg=mass_kg, threads=threads)
    if r["peak_cell"] is None:
        raise ValueError("iec62704_peak: no tissue")
    counts = {k: int(v) for k, v in r["counts"].items() if k != "background"}
    cell = tuple(int(v) for v in r["peak_cell"])
    rule = ["background", "centred", "covered", "face_cube", "none"][int(r["kind"][cell])]
    return float(r["peak"]), cell, rule, counts


def _direction(text: str) -> np.ndarray:
    sign = -1.0 if text.startswith("-") else 1.0
    v = np.zeros(3)
    v[_AXES[text.lstrip("+-")]] = sign
    return v


def _excitation_phasor(sim: pathlib.Path, frequency_hz: float) -> complex:
    """The excitation signal at the frequency, with the FD dumps' convention (2 dt sum)."""
    t, e = np.loadtxt(sim / "et", unpack=True)
    dt = t[1] - t[0]
    return complex(2 * dt * np.sum(e * np.exp(-2j * np.pi * frequency_hz * t)))


def plane_wave_sar(model_h5: str, *, propagation: str = "-y", polarization: str = "z",
                   air_cells: int = 2, end_criteria: float = 1e-4, sim_path: str = None,
                   threads: int = 0, keep: bool = False) -> PlaneWaveResult:
    """Expose the model to a plane wave at its frequency (default: from the front, travelling
    anterior to posterior (-y), E along the body's axis (z)); results per W/m^2 incident."""
    require_csxcad_fix()
    from CSXCAD import ContinuousStructure
    from openEMS import openEMS
    import h5py

    k, e = _direction(propagation), _direction(polarization)
    if abs(float(k @ e)) > 0:
        raise ValueError("polarization must be perpendicular to propagation")
    model = read_model(os.path.abspath(model_h5))
    f0 = model.frequency_hz
    tissue = np.argwhere(model.index > 0)
    if tissue.size == 0:
        raise ValueError(f"{model_h5}: no tissue")
    lo, hi = tissue.min(axis=0), tissue.max(axis=0) + 1  # tissue cells [lo, hi) per axis
    # Outwards from the body: air, the flux box, air, the plane-wave (TF/SF) box, air, PML 8.
    flux_gap, tfsf_gap, pml = air_cells, air_cells + 2, 8
    outer = tfsf_gap + 2 + pml

    csx = ContinuousStructure()
    err = csx.ReadFromXML(model.xml)
    if "Unknown" in err or "Error" in err:
        raise RuntimeError(f"{model.xml}: CSXCAD did not read the model ({err.strip()})")
    fdtd = openEMS(EndCriteria=end_criteria)
    fdtd.SetGaussExcite(f0, 0.5 * f0)
    fdtd.SetBoundaryCond(["PML_8"] * 6)
    fdtd.SetCellConstantMaterial(1)  # each cell one material, as the voxel model is
    fdtd.SetCSX(csx)
    grid = csx.GetGrid()
    grid.SetDeltaUnit(1e-3)
    for a, name in enumerate("xyz"):
        grid.SetLines(name, model.lines_mm(a, int(lo[a]) - outer, int(hi[a]) + outer))

    def box(gap):
        return ([model.corner_mm[a] + (lo[a] - gap) * model.spacing_mm[a] for a in range(3)],
                [model.corner_mm[a] + (hi[a] + gap) * model.spacing_mm[a] for a in range(3)])

    wave = csx.AddExcitation("plane_wave", exc_type=10, exc_val=list(e))
    wave.SetPropagationDir(list(k))
    wave.SetFrequency(f0)
    wave.AddBox(*box(tfsf_gap))
    body = box(0)
    edges = csx.AddDump("E_edges", dump_type=10, dump_mode=0, file_type=1, frequency=[f0])
    edges.AddBox(*box(1))
    sar_local = csx.AddDump("SAR_local", dump_type=20, file_type=1, frequency=[f0])
    sar_local.AddBox(*body)
    flux = fdtd.CreateNF2FFBox("flux", *box(flux_gap), frequency=[f0])

    sim = pathlib.Path(sim_path or tempfile.mkdtemp(prefix="repose-openems-")).resolve()
    start = time.time()
    cwd = os.getcwd()
    try:  # openEMS's Run changes the working directory to the simulation's
        fdtd.Run(str(sim), cleanup=True, verbose=0, numThreads=threads)
    finally:
        os.chdir(cwd)
    seconds = time.time() - start

    # The incident plane wave's power density, in the dumps' units.
    s_inc = abs(_excitation_phasor(sim, f0)) ** 2 / (2 * ETA0)

    # Edge fields -> per-cell power. Dump nodes are mesh lines (m); E_c[i,j,k] lies on the edge
    # from node (i,j,k) one cell along c.
    with h5py.File(sim / "E_edges.h5", "r") as f:
        nodes = [np.asarray(f["/Mesh/" + a], float) * 1e3 for a in "xyz"]
        field = (np.asarray(f["/FieldData/FD/f0_real"]) +
                 1j * np.asarray(f["/FieldData/FD/f0_imag"])).transpose(0, 3, 2, 1)
    first = [int(round((nodes[a][0] - model.corner_mm[a]) / model.spacing_mm[a])) for a in range(3)]
    n = [len(nodes[a]) - 1 for a in range(3)]  # cells between the dump's nodes
    e2 = np.abs(field) ** 2
    mean_sq = (
        (e2[0, :-1, :-1, :-1] + e2[0, :-1, 1:, :-1] + e2[0, :-1, :-1, 1:] + e2[0, :-1, 1:, 1:]) +
        (e2[1, :-1, :-1, :-1] + e2[1, 1:, :-1, :-1] + e2[1, :-1, :-1, 1:] + e2[1, 1:, :-1, 1:]) +
        (e2[2, :-1, :-1, :-1] + e2[2, 1:, :-1, :-1] + e2[2, :-1, 1:, :-1] + e2[2, 1:, 1:, :-1])
    ) / 4.0  # sum over components of the mean of |E_c|^2 over the cell's 4 c-edges
    cells = np.zeros(n, dtype=np.uint8)  # material per dump cell (outside the model: background)
    src = [slice(max(first[a], 0), min(first[a] + n[a], model.index.shape[a])) for a in range(3)]
    dst = [slice(s.start - first[a], s.stop - first[a]) for a, s in enumerate(src)]
    cells[tuple(dst)] = model.index[tuple(src)]
    volume_m3 = float(np.prod(model.spacing_mm)) * 1e-9
    power = 0.5 * model.sigma[cells] * mean_sq * volume_m3 / s_inc
    density = model.density[cells]
    tissue_cells = density > 0
    absorbed = float(power[tissue_cells].sum())
    mass = float(density[tissue_cells].sum() * volume_m3)
    local = np.zeros(model.index.shape)
    with np.errstate(divide="ignore", invalid="ignore"):
        sar = np.where(tissue_cells, power / (density * volume_m3), 0.0)
    local[tuple(src)] = sar[tuple(dst)]

    with h5py.File(sim / "SAR_local.h5", "r") as f:
        openems_absorbed = float(f["/FieldData/FD/f0"].attrs["power"][0]) / s_inc
    peak10, peak_cell, rule, counts = iec62704_peak(power, density, model.spacing_mm, 0.010,
                                                    threads)
    peak_at = [float(model.corner_mm[a] + (first[a] + peak_cell[a] + 0.5) * model.spacing_mm[a])
               for a in range(3)]
    peak_c95 = float(cube_averaged_sar(power, density * volume_m3, 0.010).max())
    inflow = -float(flux.CalcNF2FF(str(sim), f0, [90.0], [0.0]).Prad[0]) / s_inc
    if not keep and sim_path is None:
        import shutil
        shutil.rmtree(sim, ignore_errors=True)
    total_cells = int(np.prod([hi[a] - lo[a] + 2 * outer for a in range(3)]))
    return PlaneWaveResult(f0, propagation, polarization, total_cells, seconds, mass, absorbed,
                           inflow, openems_absorbed, absorbed / mass, peak10, peak_at, rule,
                           peak_c95, counts, local)
