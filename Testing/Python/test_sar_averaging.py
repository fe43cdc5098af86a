"""repose.average_sar (IEC/IEEE 62704-1 cube rules; Core's dosimetry/SarAveraging.h, checked
cell by cell against a plain reference in Testing/Cxx/Core/dosimetry/SarAveragingTest.cpp): the binding
keeps the axes of [x, y, z] arrays, all beyond the grid is air, and a callback can cancel."""
import numpy as np
import pytest

import repose
import repose.openems as oe


def edges(n, mm):
    return np.arange(n + 1) * mm * 1e-3


def test_axes_are_kept_on_an_anisotropic_grid_in_either_memory_order():
    shape, mm = (14, 9, 11), (3.0, 4.0, 5.0)
    rho = np.full(shape, 1000.0)
    i, j, k = np.indices(shape)
    sar = 1.0 + 0.2 * i + 0.05 * j - 0.03 * k + 0.5  # linear: centred cubes give the centre value
    e = [edges(n, s) for n, s in zip(shape, mm)]
    r = repose.average_sar(rho, sar, *e)
    centred = r["kind"] == 1
    assert centred.sum() > 20
    assert np.allclose(r["sar"][centred], sar[centred], rtol=1e-9)
    assert r["sar"].shape == shape and r["kind"].dtype == np.uint8
    f = repose.average_sar(np.asfortranarray(rho), np.ascontiguousarray(sar), *e)
    assert np.array_equal(f["sar"], r["sar"])
    assert r["counts"]["none"] == 0 and r["counts"]["background"] == 0
    assert sum(r["counts"].values()) == rho.size
    assert r["peak"] == pytest.approx(r["sar"].max())
    assert r["sar"][r["peak_cell"]] == r["peak"]
    with pytest.raises(repose.Error, match="edges"):
        repose.average_sar(rho, sar, e[1], e[0], e[2])


def test_beyond_the_grid_is_air_so_padding_changes_nothing():
    rng = np.random.default_rng(7)
    rho = np.zeros((12, 10, 16))
    rho[2:10, 2:8, 1:15] = rng.uniform(900, 1900, (8, 6, 14))
    power = np.where(rho > 0, rng.uniform(0, 1e-4, rho.shape), 0.0)
    peak, cell, rule, counts = oe.iec62704_peak(power, rho, (4.0, 4.0, 4.0))
    padded = oe.iec62704_peak(np.pad(power, 5), np.pad(rho, 5), (4.0, 4.0, 4.0))
    assert padded[0] == pytest.approx(peak, rel=1e-7)  # cube sizes met to 1e-8 of the mass
    assert padded[1] == tuple(c + 5 for c in cell)
    assert padded[2] == rule and padded[3] == counts
    tight = oe.iec62704_peak(power[2:10, 2:8, 1:15], rho[2:10, 2:8, 1:15], (4.0, 4.0, 4.0))
    assert tight[0] == pytest.approx(peak, rel=1e-7)
    assert counts["centred"] > 0 and counts["face_cube"] > 0


def test_a_progress_callback_sees_the_stages_and_can_cancel():
    rho = np.full((10, 10, 10), 1000.0)
    sar = np.ones(rho.shape)
    e = edges(10, 4.0)
    stages = []
    repose.average_sar(rho, sar, e, e, e, progress=lambda f, s: stages.append(s))
    assert "SAR averaging: centred cubes" in stages and stages[-1] == "SAR averaging: done"
    with pytest.raises(repose.Cancelled):
        repose.average_sar(rho, sar, e, e, e, progress=lambda f, s: False)
