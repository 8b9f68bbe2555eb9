"""The holder guard (core.strategies.holder_guard) in the 3-axis Surface: a ball D4 on a 20 mm stick-out in an ER32
collet chuck finishing a 40 mm deep cavity. Without the guard the holder hits the model; with it (lift) no point
of any move brings a body closer than its clearance (checked by core.verify.holder_clearance and by a brute-force
distance over a dense sample of the model's surface), the report names the regions and the stick-out that cuts
everything; that stick-out cuts everything; leave_out cuts only where the holder is clear."""
from __future__ import annotations

import numpy as np
import pytest

from tests.core.cavity import cavity_mesh
from tmm_workbench.core.errors import TmmError
from tmm_workbench.core.linking import LinkPolicy
from tmm_workbench.core.strategies import holder_guard, raster_drop
from tmm_workbench.core.strategies.surface.params import SurfaceParams
from tmm_workbench.core.tools.assembly import ToolAssembly
from tmm_workbench.core.tools.cutter import Cutter
from tmm_workbench.core.verify.holder_clearance import check_holder_clearance

BALL = Cutter.ball(4)
POLICY = LinkPolicy(safe_height=60.0, clearance_height=65.0)


def tool(stick_out: float = 20.0) -> ToolAssembly:
    return ToolAssembly(BALL, 4, stick_out, flute_length=12, holder="SK40 ER32x70")


def params(**kw) -> SurfaceParams:
    base = dict(boundary=(-45.0, -3.0, 45.0, 3.0), stepover=3.0, sample_step=0.5, angle_deg=0.0)
    return SurfaceParams(**{**base, **kw})


@pytest.fixture(scope="module")
def cavity():
    return cavity_mesh()


def test_the_cutter_alone_drives_the_holder_into_the_cavity(cavity) -> None:
    path = raster_drop.compute_surface_toolpath(cavity, BALL, params(), POLICY)
    check = check_holder_clearance(cavity, tool(), path, sample_step=0.5)
    assert not check.ok and check.per_piece.get("holder", 0) > 0


def test_lift_keeps_every_body_clear_and_says_what_it_left(cavity) -> None:
    notes: list = []
    path = raster_drop.compute_surface_toolpath(cavity, BALL, params(assembly=tool(), holder_notes=notes), POLICY)
    check = check_holder_clearance(cavity, tool(), path, sample_step=0.25, tolerance=0.05)
    assert check.ok, check.summary()
    (report,) = notes
    assert report.affected > 0 and report.max_lift > 15 and "holder" in report.pieces
    x0, y0, x1, y1 = report.region
    assert -35 <= x0 and x1 <= 35   # inside the pocket, where the holder cannot follow
    assert report.stick_out is not None and report.stick_out.stick_out > 20
    assert "points raised" in report.summary() and "stick-out" in report.summary()
    spots = report.spots   # what the view draws: inside the region, one per cell
    assert 0 < len(spots) <= report.affected
    assert x0 <= spots[:, 0].min() and spots[:, 0].max() <= x1 and y0 <= spots[:, 1].min() <= spots[:, 1].max() <= y1
    cells = np.floor(spots[:, :2] / holder_guard.MARK_CELL_MM)
    assert len(np.unique(cells, axis=0)) == len(spots)


def test_the_stick_out_it_tells_cuts_everything(cavity) -> None:
    notes: list = []
    raster_drop.compute_surface_toolpath(cavity, BALL, params(assembly=tool(), holder_notes=notes), POLICY)
    told = notes[0].stick_out
    longer: list = []
    raster_drop.compute_surface_toolpath(cavity, BALL, params(assembly=tool(told.stick_out + 0.01),
                                                              holder_notes=longer), POLICY)
    assert "holder" not in longer[0].pieces        # the holder no longer lifts the tool anywhere
    # the D4 shank with its 1 mm clearance is wider than the ball: beside the walls it lifts the tool whatever
    # the stick-out; the report says where (no stick-out helps there)
    assert len(told.shank_points) > 0 and set(longer[0].pieces) <= {"shank", "neck"}
    shorter: list = []
    raster_drop.compute_surface_toolpath(cavity, BALL, params(assembly=tool(told.stick_out - 1.0),
                                                              holder_notes=shorter), POLICY)
    assert shorter[0].pieces.get("holder", 0) > 0


def test_leave_out_cuts_only_where_the_holder_is_clear(cavity) -> None:
    notes: list = []
    path = raster_drop.compute_surface_toolpath(
        cavity, BALL, params(assembly=tool(), holder_collision="leave_out", holder_notes=notes), POLICY)
    check = check_holder_clearance(cavity, tool(), path, sample_step=0.25, tolerance=0.05)
    assert check.ok, check.summary()
    assert notes[0].affected > 0
    lifted: list = []
    raster_drop.compute_surface_toolpath(cavity, BALL, params(assembly=tool(), holder_notes=lifted), POLICY)
    assert len(path.moves) < len(lifted and raster_drop.compute_surface_toolpath(
        cavity, BALL, params(assembly=tool()), POLICY).moves)   # the gaps are not cut


def test_bad_input_is_refused_by_name(cavity) -> None:
    with pytest.raises(TmmError, match="holder collision must be 'lift' or 'leave_out', got 'dodge'"):
        holder_guard.guard(cavity, tool(), [], "dodge", 0.5)
    with pytest.raises(TmmError, match="holder collision"):
        params(assembly=tool(), holder_collision="dodge").validate()


def test_the_spots_are_the_lowest_point_of_each_cell_and_bounded() -> None:
    rng = np.random.default_rng(7)
    pts = np.column_stack([rng.uniform(0, 10, 5000), rng.uniform(0, 3, 5000), rng.uniform(-5, 5, 5000)])
    spots = holder_guard.spots(pts, cell=1.0)
    keys = np.floor(pts[:, :2]).astype(int)
    expected = {}
    for k, z in zip(map(tuple, keys), pts[:, 2]):   # brute force: the lowest z per 1 mm cell
        expected[k] = min(expected.get(k, np.inf), z)
    assert len(spots) == len(expected) == 30
    for p in spots:
        assert p[2] == expected[tuple(np.floor(p[:2]).astype(int))]
    assert len(holder_guard.spots(pts, cell=0.01, most=100)) <= 100
    assert holder_guard.spots(np.zeros((0, 3))).shape == (0, 3)


def test_a_move_clear_at_both_ends_is_lifted_where_it_passes_under() -> None:
    """A lean move climbing from the floor past a 50 mm wall's top (wheel_in_box's raster, 0.4 mm between its
    samples): clear at both ends, the shank's edge within its clearance of the wall three quarters of the way;
    the guard lifts it (points inserted) so no point of the move is under the bodies' height."""
    from tests.conftest import grid_mesh
    from tmm_workbench.core.query.drop_assembly import AssemblyDrop
    from tmm_workbench.core.segments import CutSegment
    from tmm_workbench.core.strategies.segment_split import move_samples

    wall = grid_mesh(lambda x, y: np.where(x >= 80.0, 50.0, 0.0), 80, 4, (60.0, -10.0, 100.0, 10.0), "wall")
    ball8 = ToolAssembly(Cutter.ball(8), 8, 95, flute_length=30, holder="ER32 nut")
    drop = AssemblyDrop(wall, ball8)
    xy = np.array([[74.75, 0.0], [75.15, 0.0]])
    need, _ = drop.heights_of(holder_guard.BODIES, xy)
    tips = np.column_stack([xy, [max(need[0], 12.7), need[1] + 0.01]])
    seg = CutSegment(tips)
    fine = move_samples(seg, 0.01)[0]
    under = drop.heights_of(holder_guard.BODIES, fine[:, :2])[0] - fine[:, 2]
    assert under.max() > 1.0                                   # the straight move dips under the wall's clearance
    (out,), report = holder_guard.guard(wall, ball8, [seg], holder_guard.LIFT, 0.4)
    assert report.affected >= 2 and len(out) > 2                # points inserted
    fine = move_samples(out, 0.01)[0]
    under = drop.heights_of(holder_guard.BODIES, fine[:, :2])[0] - fine[:, 2]
    assert under.max() <= 0.05
