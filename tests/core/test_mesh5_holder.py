"""The whole tool on the 5-axis mesh finish (core.strategies.mesh5.holder, finish with params.assembly): a flat
D 10 in an ER16 nut on a short stick-out finishing a floor that ends at a 60 mm wall. The shank and holder bound
every C-space, so the tool tilts away from the wall or leaves the strip for clean-up; the linked path keeps them
their clearance from the model all along (core.verify.holder_clearance, another code path); the same plan
without the assembly drives the holder into the wall. A cut move that would sweep the holder past a corner is
left out and reported."""
from __future__ import annotations

import numpy as np
import pytest

from tests.conftest import grid_mesh
from tmm_workbench.core.geometry.mesh import TriMesh
from tmm_workbench.core.errors import TmmError
from tmm_workbench.core.linking import LinkPolicy, link
from tmm_workbench.core.segments import CutSegment
from tmm_workbench.core.sim.grid import Grid
from tmm_workbench.core.sim.simulate import simulate
from tmm_workbench.core.strategies.mesh5 import cleanup, finish, holder
from tmm_workbench.core.strategies.mesh5.finish import Mesh5Params
from tmm_workbench.core.strategies.mesh5.stepover import AdaptivePlan
from tmm_workbench.core.strategies.multipoint import link_policy
from tmm_workbench.core.tools.assembly import ToolAssembly
from tmm_workbench.core.tools.cutter import Cutter
from tmm_workbench.core.verify.holder_clearance import check_holder_clearance

WALL_Y, WALL_TOP = 12.0, 60.0
PARAMS = dict(tolerance=0.3, tilt_max_deg=30.0, yaw_limit_deg=90.0, grid_step_deg=6.0, forward_step=5.0)


def floor_and_wall(half: float = 5.0) -> TriMesh:
    """A floor z = 0 (x -half..half, y -6..12) and a vertical wall on its y = 12 edge up to z = 60."""
    floor = grid_mesh(lambda x, y: 0.0 * x, 4, 10, (-half, -6.0, half, WALL_Y), "floor")
    n = len(floor.vertices)
    wall = np.array([[-half, WALL_Y, 0], [half, WALL_Y, 0], [half, WALL_Y, WALL_TOP], [-half, WALL_Y, WALL_TOP]])
    return TriMesh(np.vstack([floor.vertices, wall]), np.vstack([floor.triangles, [[n, n + 1, n + 2],
                                                                                    [n, n + 2, n + 3]]]), "wall")


def er16(cutter: Cutter) -> ToolAssembly:
    return ToolAssembly(cutter, 10.0, 32.0, flute_length=30.0, holder="ER16 nut")   # holder radius 16 + 1 mm


@pytest.fixture(scope="module")
def planned():
    mesh, cutter = floor_and_wall(), Cutter.flat(10.0)
    assembly = er16(cutter)
    params = Mesh5Params(**PARAMS)
    params.assembly, params.holder_notes = assembly, []
    whole = finish.compute(mesh, cutter, params)
    bare = finish.compute(mesh, cutter, Mesh5Params(**PARAMS))
    policy = link_policy(cutter, WALL_TOP + 20.0, WALL_TOP + 30.0, 5.0)
    return mesh, assembly, whole, link(whole.segments, policy), link(bare.segments, policy), params


def test_the_tool_tilts_away_from_the_wall_and_the_holder_keeps_its_clearance(planned):
    mesh, assembly, whole, path, bare_path, params = planned
    axes = np.vstack([s.axes for s in whole.segments])
    # upright, the nut (radius 17 with its clearance) reaches the wall from y = -5 on: the tool leans away (-y)
    assert axes[:, 1].min() < -np.sin(np.radians(10.0))
    check = check_holder_clearance(mesh, assembly, path, sample_step=0.25, surface_step=0.2, tolerance=0.01)
    assert check.ok, check.summary()
    # the same plan without the assembly drives the shank and holder into the wall
    assert not check_holder_clearance(mesh, assembly, bare_path, sample_step=0.25, surface_step=0.2,
                                      tolerance=0.01).ok
    note = whole.diagnostics["holder"]
    assert params.holder_notes == [note]
    assert len(note.tilted) > 0 and note.most_tilt_deg >= 10.0
    text = finish.report(whole.diagnostics)
    assert "ER16 nut" in text and f"at {len(note.tilted)} of {note.cc_points} CC points" in text
    assert "tool tilts away" in text


def test_what_no_posture_reaches_beside_the_wall_is_marked_for_clean_up(planned):
    _, _, whole, *_ = planned
    d = whole.diagnostics
    # the cutter itself cannot finish the last 5 mm before the wall: strips left, covered by points on the floor
    assert d["unfinished"]
    marks = d["cleanup_points"]
    assert len(marks) > 0 and np.allclose(marks[:, 2], 0.0, atol=1e-9)
    assert marks[:, 1].max() > WALL_Y - 5.0
    for x, y, _ in marks:
        assert any(f0 - 1e-9 <= x <= f1 + 1e-9 and a0 - 1e-9 <= y <= a1 + 1e-9 for f0, f1, a0, a1 in d["unfinished"])
    corners = d["strip_corners"]
    assert corners.shape == (len(d["unfinished"]), 4, 2)
    assert f"marked for clean-up ({len(marks)} points on the mesh)" in finish.report(d)


def test_a_move_sweeping_the_holder_past_a_corner_is_left_out_and_reported():
    # a narrow fin (x -1..1 at y = 10): both ends of the move clear the nut (21.5 mm away), its middle does not
    cutter = Cutter.flat(10.0)
    v = np.array([[-1, 10, 0], [1, 10, 0], [1, 10, 60], [-1, 10, 60]], float)
    mesh = TriMesh(v, np.array([[0, 1, 2], [0, 2, 3]]), "fin")
    up = np.tile([0.0, 0.0, 1.0], (3, 1))
    seg = CutSegment(np.array([[-40.0, 0, 0], [-20.0, 0, 0], [20.0, 0, 0]]), axes=up)
    kept, note = holder.optional_guard(mesh, cutter, er16(cutter), AdaptivePlan(), [seg])
    assert len(kept) == 1 and np.allclose(kept[0].tips, seg.tips[:2])     # the lone last position dropped
    assert note.affected == 1 and np.allclose(note.left_out, [[20.0, 0, 0]])
    assert "1 moves left out" in note.summary() and "holder" in note.summary()
    assert holder.optional_guard(mesh, cutter, None, AdaptivePlan(), [seg]) == ([seg], None)


def _above_tau_in_strips(mesh, paths, corners, tol: float, cell: float = 0.2) -> np.ndarray:
    """The simulation's cells (0.2 mm, another grid than the clean-up's) inside the strips that stay more than
    `tol` above the floor after `paths` ((toolpath, cutter) each, from 0.5 mm of stock)."""
    grid = Grid.covering(-5.0, -6.0, 5.0, WALL_Y, cell)
    heights = np.full((grid.ny, grid.nx), 0.5)
    for path, cutter in paths:
        heights = simulate(path, cutter, grid, heights).heights
    xy = grid.centres()
    inside = np.zeros(len(xy), dtype=bool)
    for c in corners:
        (x0, y0), (x1, y1) = c.min(0), c.max(0)
        inside |= (xy[:, 0] > x0) & (xy[:, 0] < x1) & (xy[:, 1] > y0) & (xy[:, 1] < y1)
    return xy[inside & (heights.ravel() > tol)]


def test_the_ball_clean_up_finishes_the_strips_but_the_corner_it_cannot_reach(planned):
    mesh, _, whole, path, _, _ = planned
    cutter, ball, tol = Cutter.flat(10.0), Cutter.ball(4.0), PARAMS["tolerance"]
    corners = whole.diagnostics["strip_corners"]
    segments, note = cleanup.cleanup(mesh, cutter, path, ball, tol, feed_angle_deg=0.0, strips=corners)
    before = _above_tau_in_strips(mesh, [(path, cutter)], corners, tol)
    after = _above_tau_in_strips(mesh, [(path, cutter), (link(segments, LinkPolicy(80.0, 90.0)), ball)], corners, tol)
    # the 5-axis passes leave the strips beside the wall (7 mm wide) above the tolerance
    assert len(before) * 0.04 > 50.0 and before[:, 1].min() < WALL_Y - 5.0
    # the ball D4 takes them down to the tolerance but where it cannot reach: the fillet its radius leaves in the
    # corner, above 0.3 mm within 2 - sqrt(4 - 1.7^2) = 0.946 mm of the wall
    assert len(after) and after[:, 1].min() > WALL_Y - 0.946 - 0.2
    assert note.left * 0.9 < len(before) * 0.04 < note.left * 1.1 and note.outside_strips == 0.0
    assert abs(note.after - 10.0 * 0.946) < 10.0 * 0.3
    assert note.after_points[:, 1].min() > WALL_Y - 0.946 - 0.25
    assert "stay above it (out of the ball's reach too)" in note.summary()
    # a 3-axis ball dropped on the mesh: on the floor where its tip is over it (beside its x = +-5 edges it drops
    # over the edge), never nearer the wall than its radius
    tips = np.vstack([s.tips for s in segments])
    over = np.abs(tips[:, 0]) < 5.0 - 1e-6
    assert over.any() and tips[over, 2].min() > -1e-6 and tips[over, 1].max() <= WALL_Y - ball.radius + 1e-6


def test_a_clean_up_tool_must_be_a_ball():
    with pytest.raises(TmmError, match="clean-up tool must be a ball end mill, got flat D4"):
        cleanup.check_tool(Cutter.flat(4.0))
