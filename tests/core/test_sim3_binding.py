"""The z-map stock and the exact 3-axis simulation through the binding: the heights view, the report,
refusals by name, and cancel.

Runs against the package's kernel (tmm_workbench.core.kernel.native); with TMM_SIM3_BUILD=<build folder>
set, against the `_native` module built there instead (a side build, before the package's is rebuilt).
"""
from __future__ import annotations

import importlib
import os
import sys
import time

import numpy as np
import pytest


@pytest.fixture(scope="module")
def nat():
    build = os.environ.get("TMM_SIM3_BUILD")
    if build:
        sys.path.insert(0, os.path.abspath(build))
        try:
            return importlib.import_module("_native")
        finally:
            sys.path.pop(0)
    from tmm_workbench.core.kernel import native
    return native.load()


def test_heights_is_a_writable_view_that_keeps_the_zmap_alive(nat):
    z = nat.ZMap(-1.0, 2.0, 0.5, 4, 3, 7.0)
    assert (z.x0, z.y0, z.cell, z.nx, z.ny) == (-1.0, 2.0, 0.5, 4, 3)
    h = z.heights
    assert h.shape == (3, 4) and h.dtype == np.float64 and h.flags.writeable
    assert np.all(h == 7.0)
    h[1, 3] = -2.0                     # row j = 1 (y), column i = 3 (x)
    assert z.heights[1, 3] == -2.0     # the same storage
    del z
    h[0, 0] = 1.5                      # the view keeps the ZMap alive
    assert h[0, 0] == 1.5 and h[1, 3] == -2.0
    assert nat.ZMap.bytes_for(1000, 1000) == 8_000_000
    assert nat.ZMap.DEFAULT_MAX_CELLS == 1 << 28


def test_stock_set_from_python_is_cut(nat):
    z = nat.ZMap(0.0, 0.0, 0.1, 100, 100, 0.0)
    z.heights[:, :50] = -5.0           # the left half already below the move
    tips = np.array([[1.0, 5.0, -1.0], [8.0, 5.0, -1.0]])
    r = nat.cut_3axis(z, nat.Cutter(1.0, 0.0), tips, np.array([0], np.uint8))
    assert r["moves_cut"] == 1
    row = z.heights[50]                # y = 5.05: within the flat's radius of the move
    assert np.all(row[:50] == -5.0)
    assert np.all(row[50:90] == -1.0) and np.all(row[90:] == 0.0)  # x <= 8 + sqrt(1 - 0.05^2)
    assert r["cells_lowered"] == int(np.count_nonzero(z.heights == -1.0))


def test_report_and_collisions(nat):
    z = nat.ZMap(-5.05, -5.05, 0.1, 101, 101, 0.0)
    tips = np.array([[-3, 0, 1.0], [-3, 0, -0.5], [3, 0, -0.5], [3, 0, 1.0], [3, 3, 1.0], [3, 3, -0.25],
                     [-3, 3, -0.25]])
    kinds = np.array([0, 0, 1, 1, 1, 2], np.uint8)
    r = nat.cut_3axis(z, nat.Cutter(1.0, 1.0), tips, kinds, collision_tol=0.01, threads=2)
    assert set(r) == {"moves_cut", "cells_lowered", "collisions"}
    assert r["moves_cut"] == 5 and r["cells_lowered"] > 0
    c = r["collisions"]
    assert c.shape == (1, 2) and c.dtype == np.float64
    assert c[0, 0] == 4 and c[0, 1] == pytest.approx(0.25, abs=1e-12)
    empty = nat.cut_3axis(z, nat.Cutter(1.0, 1.0), np.zeros((0, 3)), np.zeros(0, np.uint8))
    assert empty["moves_cut"] == 0 and empty["collisions"].shape == (0, 2)


def test_same_heights_for_any_thread_count(nat):
    rng = np.random.default_rng(5)
    tips = np.column_stack([rng.uniform(0, 20, (200, 2)), rng.uniform(-2, 1, 200)])
    kinds = np.zeros(199, np.uint8)
    out = []
    for threads in (1, 2):
        z = nat.ZMap(0.0, 0.0, 0.1, 200, 200, 0.5)
        nat.cut_3axis(z, nat.Cutter(2.0, 0.5), tips, kinds, threads=threads)
        out.append(z.heights.copy())
    assert np.array_equal(out[0], out[1])


def test_errors_by_name(nat):
    z = nat.ZMap(0.0, 0.0, 1.0, 10, 10, 0.0)
    c = nat.Cutter(1.0, 1.0)
    tips = np.array([[1.0, 1, 0], [2, 2, 0], [3, 3, 0]])
    with pytest.raises(ValueError, match=r"kinds must have shape \(n - 1,\) = \(2,\)"):
        nat.cut_3axis(z, c, tips, np.zeros(3, np.uint8))
    with pytest.raises(ValueError, match="kind of move 1 is 7"):
        nat.cut_3axis(z, c, tips, np.array([0, 7], np.uint8))
    with pytest.raises(ValueError, match="kind of move 0 is 256"):  # not wrapped to 0 by a cast
        nat.cut_3axis(z, c, tips, np.array([256, 0]))
    with pytest.raises(TypeError, match="integer"):
        nat.cut_3axis(z, c, tips, np.array([0.0, 1.0]))
    bad = tips.copy()
    bad[2, 1] = np.nan
    with pytest.raises(ValueError, match="tip 2 is not finite"):
        nat.cut_3axis(z, c, bad, np.zeros(2, np.uint8))
    with pytest.raises(ValueError, match=r"tips must have shape \(n, 3\)"):
        nat.cut_3axis(z, c, tips[:, :2], np.zeros(2, np.uint8))
    with pytest.raises(ValueError, match="collision_tol"):
        nat.cut_3axis(z, c, tips, np.zeros(2, np.uint8), collision_tol=-1.0)
    assert np.all(z.heights == 0.0)  # refused before cutting
    for cell in (0.0, -1.0, float("nan")):
        with pytest.raises(ValueError, match="cell size"):
            nat.ZMap(0.0, 0.0, cell, 10, 10, 0.0)
    with pytest.raises(ValueError, match="nx must be at least 1"):
        nat.ZMap(0.0, 0.0, 1.0, 0, 10, 0.0)
    with pytest.raises(ValueError, match="top"):
        nat.ZMap(0.0, 0.0, 1.0, 10, 10, float("inf"))


def test_too_large_a_grid_is_refused_quickly_without_allocating(nat):
    t = time.perf_counter()
    with pytest.raises(ValueError, match="above the limit"):
        nat.ZMap(0.0, 0.0, 0.001, 1_000_000, 1_000_000, 0.0)   # 8 TB of heights
    with pytest.raises(ValueError, match="above the limit of 100 cells"):
        nat.ZMap(0.0, 0.0, 1.0, 11, 10, 0.0, max_cells=100)
    assert time.perf_counter() - t < 0.5
    with pytest.raises(ValueError, match="overflow"):
        nat.ZMap.bytes_for(1 << 40, 1 << 40)


def test_progress_false_cancels(nat):
    z = nat.ZMap(0.0, 0.0, 0.1, 300, 300, 0.0)
    tips = np.array([[1.0, 1, -1], [29, 29, -1], [1, 29, -1]])
    seen = []

    def stop(fraction):
        seen.append(fraction)
        return False

    with pytest.raises(nat.Cancelled):
        nat.cut_3axis(z, nat.Cutter(1.0, 1.0), tips, np.zeros(2, np.uint8), progress=stop)
    assert seen and all(0.0 <= f <= 1.0 for f in seen)
    r = nat.cut_3axis(z, nat.Cutter(1.0, 1.0), tips, np.zeros(2, np.uint8), progress=lambda f: None)
    assert r["moves_cut"] == 2
