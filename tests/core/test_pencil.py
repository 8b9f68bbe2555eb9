"""Pencil and multi-pencil (core.footprint.pencil, the Surface's pattern 'pencil'): outline offsets at the radius
and the passes' spacing, seed 003's footprint file and its refusals, the creases a ball finds in the cavity of
tests/core/cavity.py against the cavity's own geometry, and seed 003's experiment on a sign of our own: finishing
with a radiused cutter then a pencil with a small ball at most the seed's ratio of the average scallop (0.56), in
less time than the small ball over the whole sign."""
from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np
import pytest

from tests.core.cavity import DRAFT, cavity_mesh
from tmm_workbench.core import polygons
from tmm_workbench.core.errors import TmmError
from tmm_workbench.core.footprint import pencil
from tmm_workbench.core.linking import LinkPolicy, link
from tmm_workbench.core.query.drop import DropSurface
from tmm_workbench.core.sim.grid import Grid
from tmm_workbench.core.sim.simulate import simulate
from tmm_workbench.core.sim.stock import box_heights, mesh_heights
from tmm_workbench.core.strategies import raster_drop
from tmm_workbench.core.strategies.surface.params import SurfaceParams
from tmm_workbench.core.tools.cutter import Cutter

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "benchmarks"))


def distance_to_square(p: np.ndarray, half: float) -> np.ndarray:
    """Distance from points to the outline of the square |x|, |y| <= half (unsigned)."""
    d = np.abs(p) - half
    outside = np.hypot(*np.clip(d, 0, None).T)
    return np.where((d <= 0).all(axis=1), -d.max(axis=1), outside)


def test_outline_passes_are_the_radius_and_the_step_away_from_the_loops() -> None:
    square = polygons.rectangle(0, 0, 10, 10)
    out = pencil.outline_curves([square], [], 1.5, pencil.OUTSIDE, passes=3, step=0.4)
    assert len(out) == 3
    for k, c in enumerate(out):
        assert np.allclose(c[0], c[-1])                            # closed
        assert np.abs(distance_to_square(c - 5.0, 5.0) - (1.5 + 0.4 * k)).max() < 0.01
    inside = pencil.outline_curves([square], [], 1.5, pencil.INSIDE)
    assert len(inside) == 1 and np.abs(distance_to_square(inside[0] - 5.0, 5.0) - 1.5).max() < 1e-6   # inside
    assert len(pencil.outline_curves([square], [], 1.5, pencil.BOTH)) == 2
    band = pencil.outline_curves([], [np.array([[0.0, 0.0], [10.0, 0.0]])], 1.0, pencil.BOTH)
    assert len(band) == 1 and polygons.bounds([band[0]]) == pytest.approx((-1, -1, 11, 1), abs=0.01)
    with pytest.raises(TmmError, match=r"pencil side 'outside' needs closed loops .* an open curve from \(0, 0\) to \(10, 0\)"):
        pencil.outline_curves([], [np.array([[0.0, 0.0], [10.0, 0.0]])], 1.0, pencil.OUTSIDE)
    with pytest.raises(TmmError, match="pencil side must be one of outside, inside, both"):
        pencil.outline_curves([square], [], 1.0, "around")
    with pytest.raises(TmmError, match=r"pencil passes must be a whole number in \[1, 50\], got 0"):
        pencil.outline_curves([square], [], 1.0, pencil.OUTSIDE, passes=0)
    with pytest.raises(TmmError, match="pencil step must be a length > 0 mm"):
        pencil.outline_curves([square], [], 1.0, pencil.OUTSIDE, passes=2, step=0.0)


def test_the_footprint_file_splits_at_its_lifts(tmp_path: Path) -> None:
    f = tmp_path / "sign.fp"
    f.write_text("# x y lift\n0 0 0\n1 0 0\n2 0 0\n5, 5, 1\n6, 5, 0\n\n9 9 1\n")
    curves = pencil.read_footprint(f)
    assert [c.tolist() for c in curves] == [[[0, 0], [1, 0], [2, 0]], [[5, 5], [6, 5]]]   # a lone point: no cut
    for text, said in (("0 0 0\n1 nan 0\n", "line 2: x and y must be finite"), ("0 0\n", "line 1: x, y and a lift"),
                       ("0 0 0\n1 1 2\n", "line 2: the lift flag must be 0 or 1"), ("0 a 0\n", "line 1: not numbers")):
        f.write_text(text)
        with pytest.raises(TmmError, match=said):
            pencil.read_footprint(f)
    with pytest.raises(TmmError, match="pencil footprint file not found"):
        pencil.read_footprint(tmp_path / "none.fp")


def test_the_creases_a_ball_finds_in_the_cavity_are_its_floors_feet() -> None:
    mesh = cavity_mesh()
    ball = Cutter.ball(3)
    curves = pencil.crease_curves(DropSurface(mesh), ball, (-50, -50, 50, 50), 0.25, 0.01, -41.0)
    pts = np.vstack(curves)
    # the ball in the floor's corner with a wall drafted 3 deg touches both: its centre 1.5 mm above the floor and
    # 1.5 mm from the wall, so its XY lies r (1 - sin a) / cos a... within a cell of the wall's foot less r
    a = math.atan(DRAFT)
    inset = 1.5 * (1 + math.sin(a)) / math.cos(a) - 1.5 * math.tan(a)   # centre's XY from the foot line
    pocket = distance_to_square(pts, 35 - 40 * DRAFT - inset)
    boss = distance_to_square(pts, 10 + 20 * DRAFT + inset)
    near = (np.abs(pocket) < 0.5) | (np.abs(boss) < 0.5)
    corner = np.abs(np.abs(pts[:, 0]) - np.abs(pts[:, 1])) < 0.6   # the walls' corners fold too, on the diagonals
    assert (near | corner).mean() > 0.97
    assert pencil.curve_length(max(curves, key=len)) > 4 * 60          # the pocket's foot chained around


def test_a_multi_pencil_in_the_cavity_leaves_less_than_one_pencil_and_never_gouges() -> None:
    mesh = cavity_mesh()
    grid = Grid.covering(-50, -50, 50, 50, 0.25)
    design = mesh_heights(mesh, grid)
    policy = LinkPolicy(5.0, 10.0)
    box = (-50.0, -50.0, 50.0, 50.0)
    left = simulate(raster_drop.compute_surface_toolpath(mesh, Cutter.ball(10), SurfaceParams(
        boundary=box, stepover=0.6, sample_step=0.25), policy), Cutter.ball(10), grid, box_heights(grid, 0.0)).heights
    volumes = []
    for passes in (1, 4):
        params = SurfaceParams(boundary=box, pattern="pencil", pencil_passes=passes, stepover=0.6, sample_step=0.5)
        tp = link(raster_drop.compute(mesh, Cutter.ball(3), params).segments, policy)
        dev = simulate(tp, Cutter.ball(3), grid, left).heights - design
        assert np.nanmin(dev) > -0.005
        volumes.append(float(np.nansum(np.clip(dev, 0, None))))
    before = float(np.nansum(np.clip(left - design, 0, None)))
    assert before > 1.8 * volumes[0] > 1.8 * volumes[1]


def test_seed_003s_pencil_experiment_on_our_sign() -> None:
    import pencil_sign

    rows = list(pencil_sign.experiment().values())
    (finish, _, low_f, _, _), (penciled, _, low_p, _, t_pencil), (_, _, _, _, t_small) = rows
    assert penciled <= 0.56 * finish          # seed 003: 0.0399 / 0.0711
    assert t_pencil < t_small                 # finishing + pencil beats the small ball everywhere
    assert min(low_f, low_p) > -0.005         # no gouge


def test_the_estimate_counts_the_creases_grid_before_it_runs() -> None:
    from tmm_workbench.core.strategies.surface.estimate import estimate_work

    params = SurfaceParams(boundary=(0, 0, 84, 44), pattern="pencil", pencil_passes=3, stepover=0.5, sample_step=0.5)
    work = estimate_work(params, Cutter.ball(1.5), None)
    assert work.passes == 3 and work.count > (84 / 0.25) * (44 / 0.25)


def test_a_clean_up_of_a_finish_is_a_multi_pencil_over_its_rest() -> None:
    """Seed 000's clean-up (section 3.6) as Region Rest with the pencil: the creases inside the strips a D10 finish
    left, as many passes around them as cover the strips (pencil_passes 0): most of what the D3 reaches is then
    within the tolerance, with no gouge, on a path shorter than the rest raster's; its pieces joined as a rest
    raster's are."""
    from tmm_workbench.core.footprint import rest
    from tmm_workbench.core.linking import StockHeights

    mesh = cavity_mesh()
    grid = Grid.covering(-50, -50, 50, 50, 0.25)
    design = mesh_heights(mesh, grid)
    box = (-50.0, -50.0, 50.0, 50.0)
    d10, d3 = Cutter.ball(10), Cutter.ball(3)
    left = simulate(raster_drop.compute_surface_toolpath(mesh, d10, SurfaceParams(boundary=box, stepover=0.6,
                                                                                  sample_step=0.25),
                                                         LinkPolicy(5.0, 10.0)), d10, grid, box_heights(grid, 0.0)).heights
    envelope = rest.tool_envelope(mesh, d3, grid)
    area = rest.rest_area(left, design, envelope, grid, 0.01, d3.radius)
    policy = LinkPolicy(5.0, 10.0, material_top=StockHeights(grid, left, d3), low_links=True)
    common = dict(boundary=polygons.bounds(area.region), region=area.region, rest=area.stock(left), stepover=0.31,
                  sample_step=0.25)
    pencil = raster_drop.compute(mesh, d3, SurfaceParams(pattern="pencil", pencil_passes=0, **common))
    assert pencil.diagnostics["joins"] > 0   # its pieces reached with the tool down where a join passes its checks
    cleanup = link(pencil.segments, policy)
    raster = link(raster_drop.compute(mesh, d3, SurfaceParams(**common)).segments,
                  LinkPolicy(5.0, 10.0, material_top=StockHeights(grid, left, d3), low_links=True))
    reach = np.isfinite(design) & (envelope - design <= 0.01)
    before = np.sum(reach & (left - design > 0.01))
    dev = simulate(cleanup, d3, grid, left).heights - design
    assert np.sum(reach & (dev > 0.01)) < 0.06 * before
    assert np.nanmin(dev) > -0.005
    length = lambda tp: float(np.linalg.norm(np.diff(tp.points(), axis=0), axis=1).sum())  # noqa: E731
    assert length(cleanup) < 0.6 * length(raster)
