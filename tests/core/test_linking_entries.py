"""The linker's HELIX and RAMP entries: the helix lies on its circle through the first tip, descends at the
ramp angle from where the material starts (entry_z; the tool fed straight down through air to it, below the
safe height), ends with a flat circle at depth on the first tip, in the requested sense; the ramp follows a
closed loop backwards (around it more than once when it is short) or an open pass out and back, at the ramp
angle, ending on the first tip; a segment's own entry overrides the policy's; bad entries refused by name;
5-axis linking refuses them. The simulator sees no move straight down into material with either entry."""
from __future__ import annotations

import math

import numpy as np
import pytest

from tmm_workbench.core.errors import TmmError
from tmm_workbench.core.linking import ALONG_AXIS, HELIX, PLUNGE, RAMP, LinkPolicy, link
from tmm_workbench.core.segments import CutSegment
from tmm_workbench.core.sim.grid import Grid
from tmm_workbench.core.sim.simulate import simulate
from tmm_workbench.core.sim.stock import box_heights
from tmm_workbench.core.toolpath import MoveKind, Toolpath
from tmm_workbench.core.tools.cutter import Cutter


def square_loop(z: float, a: float = 10.0) -> np.ndarray:
    xy = np.array([[0, 0], [a, 0], [a, a], [0, a], [0, 0]], dtype=float)
    return np.column_stack([xy, np.full(5, z)])


def descent(tp: Toolpath) -> np.ndarray:
    """The fed moves from the first PLUNGE (at the material's top) to the end, without the last lift."""
    pts = tp.points()
    kinds = [m.kind for m in tp.moves]
    k = kinds.index(MoveKind.PLUNGE)
    assert kinds[-1] is MoveKind.RAPID
    return pts[k:-1]


def test_helix_geometry():
    z, top, angle = -3.0, 2.0, 5.0
    seg = CutSegment(square_loop(z), entry=HELIX, entry_z=top, helix_centre=(0.0, 3.0), helix_ccw=True)
    pol = LinkPolicy(20.0, 25.0, ramp_angle_deg=angle, arc_tol=0.001)
    tp = link([seg], pol)
    moves = tp.moves
    assert [m.kind for m in moves[:4]] == [MoveKind.RAPID, MoveKind.RAPID, MoveKind.RAPID, MoveKind.PLUNGE]
    assert moves[2].z == top + pol.entry_clearance               # a rapid down to just above the material,
    assert moves[3].z == top                                     # fed from there to where it starts
    pts = descent(tp)
    k_end = next(i for i in range(1, len(pts)) if np.allclose(pts[i], seg.tips[1]))   # the loop's second tip
    helix = pts[:k_end]
    assert np.allclose(helix[-1], seg.tips[0])                    # ends on the first tip
    r = np.hypot(helix[:, 0] - 0.0, helix[:, 1] - 3.0)
    assert np.allclose(r, 3.0, atol=1e-12)
    # descending at the ramp angle along the circle's arc (chords: slightly steeper than on the arc)
    d = np.diff(helix, axis=0)
    arc = np.hypot(d[:, 0], d[:, 1])
    going_down = d[:, 2] < -1e-12
    slope = -d[going_down, 2] / arc[going_down]
    assert np.all(slope <= math.tan(math.radians(angle)) * 1.001)
    assert np.all(slope >= math.tan(math.radians(angle)) * 0.999)
    assert helix[:, 2].max() == top and np.all(np.diff(helix[:, 2]) <= 1e-12)
    # the last full turn is flat at depth
    flat = helix[helix[:, 2] == z]
    ang = np.unwrap(np.arctan2(flat[:, 1] - 3.0, flat[:, 0]))
    assert ang[-1] - ang[0] == pytest.approx(2 * math.pi, abs=1e-9)
    # the sense: counter-clockwise
    th = np.unwrap(np.arctan2(helix[:, 1] - 3.0, helix[:, 0]))
    assert np.all(np.diff(th) > 0)
    total = (th[-1] - th[0] - 2 * math.pi) * 3.0
    assert total == pytest.approx((top - z) / math.tan(math.radians(angle)), rel=1e-9)
    cw = link([CutSegment(square_loop(z), entry=HELIX, entry_z=top, helix_centre=(0.0, 3.0), helix_ccw=False)],
              pol)
    th = np.unwrap(np.arctan2(descent(cw)[:20, 1] - 3.0, descent(cw)[:20, 0]))
    assert np.all(np.diff(th) < 0)


def test_ramp_along_a_closed_loop_and_an_open_pass():
    z, top, angle = 0.0, 4.0, 3.0
    pol = LinkPolicy(20.0, 25.0, entry=RAMP, ramp_angle_deg=angle)
    need = (top - z) / math.tan(math.radians(angle))          # 76.3 mm: nearly twice round the 40 mm loop
    tp = link([CutSegment(square_loop(z), entry_z=top, closed=True)], pol)
    pts = descent(tp)
    ramp = pts[:len(pts) - 4]                                 # the loop after the ramp: 4 more tips
    assert np.allclose(ramp[-1], [0, 0, 0])
    d = np.diff(ramp, axis=0)
    length = np.hypot(d[:, 0], d[:, 1]).sum()
    assert length == pytest.approx(need, rel=1e-9)
    assert np.allclose(-d[:, 2], np.hypot(d[:, 0], d[:, 1]) * math.tan(math.radians(angle)))
    on_loop = (np.isclose(ramp[:, 0], 0) | np.isclose(ramp[:, 0], 10) | np.isclose(ramp[:, 1], 0)
               | np.isclose(ramp[:, 1], 10))
    assert on_loop.all()                                      # on the loop's own path
    # open pass: out and back, ending on the first tip
    line = np.array([[0.0, 0.0, z], [30.0, 0.0, z]])
    tp = link([CutSegment(line, entry=RAMP, entry_z=top)], LinkPolicy(20.0, 25.0, ramp_angle_deg=angle))
    pts = descent(tp)
    ramp = pts[:-1]
    assert np.allclose(ramp[-1], line[0]) and np.allclose(ramp[:, 1], 0.0)
    assert ramp[:, 0].max() <= 30.0 + 1e-12
    assert np.hypot(*np.diff(ramp[:, :2], axis=0).T).sum() == pytest.approx(need, rel=1e-9)


def test_entry_overrides_and_plunge_unchanged():
    a = CutSegment(square_loop(0.0))
    b = CutSegment(square_loop(-2.0), entry=PLUNGE)
    plain = link([CutSegment(square_loop(0.0)), CutSegment(square_loop(-2.0))], LinkPolicy(20.0, 25.0))
    assert link([a, b], LinkPolicy(20.0, 25.0)).moves == plain.moves
    assert [m.kind for m in plain.moves[:3]] == [MoveKind.RAPID, MoveKind.RAPID, MoveKind.PLUNGE]
    # helix facts are ignored by a plunge; its entry_z (the material's top) ends the rapid down 1 mm above it
    c = CutSegment(square_loop(0.0), entry_z=5.0, helix_centre=(1.0, 1.0))
    moves = link([c], LinkPolicy(20.0, 25.0)).moves
    assert [(m.kind, m.z) for m in moves[:4]] == [(MoveKind.RAPID, 25.0), (MoveKind.RAPID, 20.0),
                                                  (MoveKind.RAPID, 6.0), (MoveKind.PLUNGE, 0.0)]
    assert moves[4:] == link([CutSegment(square_loop(0.0))], LinkPolicy(20.0, 25.0)).moves[3:]


def test_bad_entries_refused_by_name():
    for bad in (0.0, 1e-6, 0.4, 46.0, 90.0, math.nan):  # 90 deg made NaN heights, 1e-6 deg gigabytes of ramp
        with pytest.raises(TmmError, match=f"ramp angle must be in \\[0.5, 45\\] deg, got {bad:g}"):
            link([CutSegment(square_loop(0.0))], LinkPolicy(20.0, 25.0, entry=RAMP, ramp_angle_deg=bad))
    for bad in (0.0, 0.05, 51.0):
        with pytest.raises(TmmError, match=f"entry clearance must be in \\[0.1, 50\\] mm, got {bad:g}"):
            link([CutSegment(square_loop(0.0))], LinkPolicy(20.0, 25.0, entry_clearance=bad))
    with pytest.raises(TmmError, match="helix centre"):
        link([CutSegment(square_loop(0.0), entry=HELIX, entry_z=3.0)], LinkPolicy(20.0, 25.0))
    with pytest.raises(TmmError, match="entry must be one of plunge, helix, ramp, got 'dive'"):
        link([CutSegment(square_loop(0.0), entry="dive")], LinkPolicy(20.0, 25.0))
    cut = Cutter.bull(10, 2)
    with pytest.raises(TmmError, match="3-axis only"):
        link([CutSegment(square_loop(0.0))], LinkPolicy(20.0, 25.0, ALONG_AXIS, entry=HELIX,
                                                        lowest_below_tip=cut.lowest_below_tip))
    with pytest.raises(TmmError, match="3-axis only"):
        link([CutSegment(square_loop(0.0), entry=RAMP)],
             LinkPolicy(20.0, 25.0, ALONG_AXIS, lowest_below_tip=cut.lowest_below_tip))


def test_no_vertical_move_into_material_with_helix_or_ramp():
    """A 40 x 40 x 10 block; a loop 2 mm deep in it entered by helix and by ramp: simulated with every
    vertical descent as a rapid, the simulator reports no such move removing material (a plunge does)."""
    grid = Grid.covering(-5, -5, 45, 45, 0.2)
    stock = box_heights(grid, 10.0)
    tool = Cutter.flat(6)
    loop = np.column_stack([np.array([[15, 15], [25, 15], [25, 25], [15, 25], [15, 15]], float), np.full(5, 8.0)])

    def vertical_as_rapid(tp: Toolpath) -> Toolpath:
        out = Toolpath()
        for i, m in enumerate(tp.moves):
            p = tp.moves[i - 1] if i else None
            vertical = p is not None and m.z < p.z and m.x == p.x and m.y == p.y
            out.add(MoveKind.RAPID if vertical else m.kind, m.x, m.y, m.z)
        return out

    pol = LinkPolicy(20.0, 25.0)
    for seg in (CutSegment(loop, entry=HELIX, entry_z=10.5, helix_centre=(17.0, 15.0)),
                CutSegment(loop, entry=RAMP, entry_z=10.5, closed=True)):
        res = simulate(vertical_as_rapid(link([seg], pol)), tool, grid, stock)
        assert len(res.collisions) == 0 and res.removed_volume > 100
    res = simulate(vertical_as_rapid(link([CutSegment(loop)], pol)), tool, grid, stock)
    assert len(res.collisions) == 1 and res.collisions[0, 1] == pytest.approx(2.0)
