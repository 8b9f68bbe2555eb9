"""Bad input to the strategies and the linker: work estimated and refused before anything is allocated
(in under a second, with bounded memory), NaN and infinity refused by name, the message naming the
parameter, its value and the allowed range."""
from __future__ import annotations

import math
import time
import tracemalloc
from dataclasses import fields, replace

import numpy as np
import pytest

from tests.conftest import SEED_JSON, grid_mesh
from tmm_workbench.core import limits
from tmm_workbench.core.errors import TmmError
from tmm_workbench.core.geometry import bezier
from tmm_workbench.core.linking import LinkPolicy, link
from tmm_workbench.core.segments import CutSegment
from tmm_workbench.core.strategies import multipoint, raster_drop
from tmm_workbench.core.strategies.multipoint import BezierFace, MultipointParams
from tmm_workbench.core.strategies.raster_drop import SurfaceParams
from tmm_workbench.core.tools.cutter import Cutter

PLATE = grid_mesh(lambda x, y: 0.1 * np.sin(x) * np.cos(y), 20, 20, (0, 0, 100, 100), "plate")
BALL = Cutter.ball(6.0)
TORUS = Cutter.torus(6.7, 6.0)


def refused_quickly(call, *fragments: str) -> str:
    """Runs `call`, which must raise TmmError within a second having allocated under 50 MB; returns the
    message, checked for `fragments`."""
    tracemalloc.start()
    t0 = time.perf_counter()
    try:
        with pytest.raises(TmmError) as info:
            call()
        seconds = time.perf_counter() - t0
        _, peak = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    assert seconds < 1.0, f"refused after {seconds:.2f} s"
    assert peak < 50e6, f"{peak / 1e6:.0f} MB allocated before the refusal"
    message = str(info.value)
    for f in fragments:
        assert f in message, message
    return message


def test_tiny_sample_step_is_refused_before_allocating():
    p = SurfaceParams(boundary=(0, 0, 100, 100), stepover=1.0, sample_step=1e-6)
    refused_quickly(lambda: raster_drop.compute(PLATE, BALL, p), "sample step 1e-06 mm", "CL points", "GB")


def test_huge_boundary_margin_is_refused_before_allocating():
    p = SurfaceParams(boundary=(-5e4, -5e4, 5e4, 5e4), stepover=1.0, sample_step=0.5)
    refused_quickly(lambda: raster_drop.compute(PLATE, BALL, p), "100000 x 100000 mm boundary")


def test_the_limit_is_a_setting():
    p = SurfaceParams(boundary=(0, 0, 100, 100), stepover=1.0, sample_step=0.5)
    previous = limits.set_limits(max_points=1000)
    try:
        refused_quickly(lambda: raster_drop.compute(PLATE, BALL, p), "limit of 1e+03 CL points")
    finally:
        limits.set_limits(previous.max_points, previous.max_memory_bytes / 1e9, previous.max_positions)
    assert len(raster_drop.compute(PLATE, BALL, p).segments) > 0


@pytest.fixture(scope="module")
def convex_face() -> BezierFace:
    return BezierFace.from_net(bezier.load_seed_patch(SEED_JSON, "convex"))


def test_fine_multipoint_footprint_is_refused_before_allocating(convex_face):
    p = MultipointParams(side_step=0.01, forward_step=0.01)
    refused_quickly(lambda: multipoint.compute(convex_face, TORUS, p), "side step 0.01 mm", "tool positions")


NUMBERS = (math.nan, math.inf, -math.inf)


def numeric_fields(cls):
    return [f.name for f in fields(cls) if f.metadata.get("spec") and f.metadata["spec"].choices is None]


@pytest.mark.parametrize("name", numeric_fields(SurfaceParams))
@pytest.mark.parametrize("bad", NUMBERS)
def test_non_finite_surface_params_are_refused_by_name(name, bad):
    p = replace(SurfaceParams(boundary=(0, 0, 100, 100)), **{name: bad})
    label = SurfaceParams.__dataclass_fields__[name].metadata["spec"].label
    with pytest.raises(TmmError, match=f"^{label} must be"):
        raster_drop.compute(PLATE, BALL, p)


def test_nan_floor_is_refused():
    """floor_z = NaN used to give a path with NaN heights and no error."""
    p = SurfaceParams(boundary=(0, 0, 100, 100), floor_z=math.nan)
    with pytest.raises(TmmError, match="floor must be a finite number of mm, got nan"):
        raster_drop.compute(PLATE, BALL, p)


def test_non_finite_boundary_is_refused():
    with pytest.raises(TmmError, match="boundary"):
        raster_drop.compute(PLATE, BALL, SurfaceParams(boundary=(0, 0, math.nan, 100)))


@pytest.mark.parametrize("name", [n for n in numeric_fields(MultipointParams)])
@pytest.mark.parametrize("bad", NUMBERS)
def test_non_finite_multipoint_params_are_refused_by_name(convex_face, name, bad):
    p = replace(MultipointParams(), **{name: bad})
    label = MultipointParams.__dataclass_fields__[name].metadata["spec"].label
    with pytest.raises(TmmError, match=f"^{label} must be"):
        multipoint.compute(convex_face, TORUS, p)


@pytest.mark.parametrize("change,message", [
    (dict(beta_max_deg=90.0), r"tilt limit must be in \(0, 90\) deg, got 90"),
    (dict(tol=0.0), r"tolerance must be in \[1e-09, 1\] mm, got 0"),
    (dict(divisions=1), r"VCRF divisions must be a whole number in \[2, 1000\], got 1"),
    (dict(anchor_iterations=2.5), r"anchor iterations must be a whole number"),
    (dict(method="newton"), r"method must be 'vcrf' or 'drd', got 'newton'"),
])
def test_multipoint_ranges_are_named(convex_face, change, message):
    with pytest.raises(TmmError, match=message):
        multipoint.compute(convex_face, TORUS, MultipointParams(**change))


@pytest.mark.parametrize("bad", NUMBERS)
def test_non_finite_tool_radii_are_refused(bad):
    with pytest.raises(TmmError, match="major radius Ro|minor radius Ri"):
        Cutter.torus(bad, 6.0)
    with pytest.raises(TmmError, match="minor radius Ri"):
        Cutter.torus(6.7, bad)
    with pytest.raises(TmmError, match="diameter"):
        Cutter.ball(bad)


def test_flat_end_mill_is_refused_by_multipoint(convex_face):
    with pytest.raises(TmmError, match=r"flat end mill \(Ri = 0\)"):
        multipoint.compute(convex_face, Cutter.flat(12.0), MultipointParams())


@pytest.mark.parametrize("name", ["safe_height", "clearance_height", "axis_retract"])
def test_linker_refuses_non_finite_heights(name):
    policy = replace(LinkPolicy(10.0, 20.0), **{name: math.nan})
    with pytest.raises(TmmError, match=name.replace("_", " ")):
        link([CutSegment(np.zeros((2, 3)))], policy)


def test_no_nan_reaches_a_path():
    p = SurfaceParams(boundary=(0, 0, 100, 100), stepover=5.0, sample_step=1.0)
    path = raster_drop.compute_surface_toolpath(PLATE, BALL, p, LinkPolicy(10.0, 20.0))
    assert np.isfinite(path.points()).all()


def test_indices_beyond_int32_are_refused_not_wrapped():
    """2**32 + 1 used to wrap silently to 1 (a valid index) in the cast to int32."""
    from tmm_workbench.core.geometry.mesh import TriMesh

    v = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0]], dtype=float)
    f = np.array([[0, 2**32 + 1, 2]], dtype=np.int64)
    with pytest.raises(TmmError, match="4294967297 does not fit the kernel's 32-bit indices"):
        TriMesh(v, f, "wrap")


def test_cone_cutter_is_refused_by_multipoint_with_its_reason(convex_face):
    with pytest.raises(TmmError, match="not supported by multipoint positioning .supported: ball, bull"):
        multipoint.compute(convex_face, Cutter.vbit(6.0, 90.0), MultipointParams())
