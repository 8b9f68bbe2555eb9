"""Z-level roughing verified by simulation (core.sim, the real kernel): a block with a rectangular pocket and a
boss in it roughed with a flat and a bull-nose cutter, sphere_on_plate.stl with a ball. For each:
  - no cell of the simulated stock lies below the model offset by the stock to leave by more than 1e-3 mm
    (the design: the drop of a ball of radius s raised by s, the exact top of the offset model);
  - no more material is left than the best any z-level roughing at the same layers can leave (a reference
    that visits every gouge-free tool-centre position of a dense grid, with a tool a little smaller so the
    reference never out-reaches by the rim of the tool) plus the floor cusp of the step-over;
  - no rapid removes material, and no vertical move goes down into material (every vertical descent is
    simulated as a rapid: the simulator reports any that cuts); rapids stay at or above the safe height;
  - the pocket keeps exactly the stock to leave on its floor and walls, and the boss survives.
Then: entries (helix in a closed pocket, from the air beside the stock in an open region, ramp when no helix
fits), climb and conventional senses, zig-zag, a stock that is not a box, progress and cancel, and every bad
input refused by name before any work."""
from __future__ import annotations

import math

import numpy as np
import pytest

from tests.conftest import SHARED_STL
from tmm_workbench.core import limits
from tmm_workbench.core import polygons as P
from tmm_workbench.core.errors import Cancelled, TmmError
from tmm_workbench.core.geometry.mesh import TriMesh, load_stl
from tmm_workbench.core.linking import HELIX, PLUNGE, RAMP, LinkPolicy
from tmm_workbench.core.query.drop import DropSurface
from tmm_workbench.core.sim.grid import Grid
from tmm_workbench.core.sim.simulate import simulate
from tmm_workbench.core.sim.stock import NEEDLE_RADIUS, box_heights
from tmm_workbench.core.strategies import zlevel_rough as zr
from tmm_workbench.core.strategies.zlevel_rough import RoughingParams, compute, compute_roughing_toolpath
from tmm_workbench.core.toolpath import MoveKind, Toolpath
from tmm_workbench.core.tools.cutter import Cutter

BOX = (0.0, 0.0, 0.0, 60.0, 50.0, 22.0)
SAFE, CLEAR = 30.0, 35.0


def blocks_mesh(xb, yb, heights, name="blocks") -> TriMesh:
    """Cells [xb[i], xb[i+1]] x [yb[j], yb[j+1]] with flat tops at heights[i][j], vertical walls between
    them and round the outside down to z = 0, and a bottom."""
    H = np.asarray(heights, float)
    tris: list = []

    def quad(a, b, c, d):
        tris.extend([[a, b, c], [a, c, d]])

    nx, ny = len(xb) - 1, len(yb) - 1
    for i in range(nx):
        for j in range(ny):
            h = H[i, j]
            x0, x1, y0, y1 = xb[i], xb[i + 1], yb[j], yb[j + 1]
            quad((x0, y0, h), (x1, y0, h), (x1, y1, h), (x0, y1, h))
            quad((x0, y0, 0), (x0, y1, 0), (x1, y1, 0), (x1, y0, 0))
            hl = H[i - 1, j] if i > 0 else 0.0
            if hl != h:
                quad((x0, y0, hl), (x0, y1, hl), (x0, y1, h), (x0, y0, h))
            hb = H[i, j - 1] if j > 0 else 0.0
            if hb != h:
                quad((x0, y0, hb), (x1, y0, hb), (x1, y0, h), (x0, y0, h))
            if i == nx - 1:
                quad((x1, y0, 0), (x1, y1, 0), (x1, y1, h), (x1, y0, h))
            if j == ny - 1:
                quad((x0, y1, 0), (x1, y1, 0), (x1, y1, h), (x0, y1, h))
    v = np.asarray(tris, float).reshape(-1, 3)
    return TriMesh(v, np.arange(len(v), dtype=np.int32).reshape(-1, 3), name)


def pocket_with_boss() -> TriMesh:
    """A 60 x 50 x 20 block; a pocket x 10..50, y 10..40 down to 8; a boss x 26..34, y 21..29 up to 15."""
    H = np.full((5, 5), 20.0)
    H[1:4, 1:4] = 8.0
    H[2, 2] = 15.0
    return blocks_mesh([0, 10, 26, 34, 50, 60], [0, 10, 21, 29, 40, 50], H, "pocket with boss")


def vertical_as_rapid(tp: Toolpath) -> Toolpath:
    """The path with every straight-down move made a rapid: the simulator reports any that removes material."""
    out = Toolpath()
    for i, m in enumerate(tp.moves):
        p = tp.moves[i - 1] if i else None
        vertical = p is not None and m.z < p.z and abs(m.x - p.x) < 1e-9 and abs(m.y - p.y) < 1e-9
        out.add(MoveKind.RAPID if vertical else m.kind, m.x, m.y, m.z)
    return out


def design_offset(surface: DropSurface, grid: Grid, s: float) -> np.ndarray:
    """Top of the model offset by s on each cell centre: a ball of radius s dropped, raised by s (s = 0: the
    model's own top, a needle's drop: core.sim.stock's NEEDLE_RADIUS)."""
    lo = float(surface.mesh.bounds[0][2])
    probe = Cutter.ball(2 * s) if s > 0 else Cutter.flat(2 * NEEDLE_RADIUS)
    return (surface.drop(probe, grid.centres(), lo - 1.0) + s).reshape(grid.ny, grid.nx)


def reference_path(surface: DropSurface, cutter: Cutter, zs, s_r: float, s_a: float, box, step: float = 0.25
                   ) -> Toolpath:
    """Every tool-centre position of a `step` grid where the cutter grown by s_r dropped plus s_a is at most the
    layer, visited by straight runs along the rows at each layer (independent of polygons and waterlines)."""
    R = cutter.radius
    xs = np.arange(box[0] - R - 1, box[3] + R + 1 + 1e-9, step)
    ys = np.arange(box[1] - R - 1, box[4] + R + 1 + 1e-9, step)
    X, Y = np.meshgrid(xs, ys)
    lo = float(surface.mesh.bounds[0][2])
    drop = surface.drop(cutter.offset(s_r), np.column_stack([X.ravel(), Y.ravel()]), lo - 100).reshape(X.shape)
    drop += s_a
    tp = Toolpath()
    high = box[5] + 5
    tp.add(MoveKind.RAPID, xs[0], ys[0], high)
    for z in zs:
        ok = drop <= z
        for j in range(len(ys)):
            e = np.flatnonzero(np.diff(np.concatenate([[False], ok[j], [False]]).astype(np.int8)))
            for a, b in zip(e[::2], e[1::2]):
                tp.add(MoveKind.RAPID, xs[a], ys[j], high)
                tp.add(MoveKind.FEED, xs[a], ys[j], z)
                tp.add(MoveKind.FEED, xs[b - 1], ys[j], z)
                tp.add(MoveKind.FEED, xs[b - 1], ys[j], high)
    return tp


def check_roughing(mesh: TriMesh, cutter: Cutter, params: RoughingParams, cell: float = 0.1, safe: float = SAFE,
                   clear: float = CLEAR) -> dict:
    surface = DropSurface(mesh)
    result = compute(mesh, cutter, params, surface=surface)
    tp = compute_roughing_toolpath(mesh, cutter, params, LinkPolicy(safe, clear), surface=surface)
    box = params.stock_box
    grid = Grid.covering(box[0], box[1], box[3], box[4], cell)
    stock = box_heights(grid, box[5]) if params.stock_heights is None else np.asarray(params.stock_heights[1])
    sim = simulate(vertical_as_rapid(tp), cutter, grid, stock)
    assert sim.collisions.shape[0] == 0, f"moves through material: {sim.collisions[:5]}"
    design = design_offset(surface, grid, params.stock_to_leave)
    dev = sim.heights - design
    assert np.nanmin(dev) >= -1e-3, f"gouge {np.nanmin(dev):.4g} mm"
    # the reference: a tool 0.05 mm smaller in radius at every gouge-free position of a 0.25 mm grid
    small = Cutter(cutter.diameter - 0.1, min(cutter.corner_radius, cutter.radius - 0.05))
    ref = simulate(reference_path(surface, cutter, result.diagnostics["layer_z"], params.stock_to_leave,
                                  params.axial, box), small, grid, stock)
    cusp = zr._profile_height(cutter, min(params.stepover(cutter), cutter.radius))
    excess = sim.heights - np.maximum(ref.heights, design)
    assert np.nanmax(excess) <= cusp + 1e-3, f"left {np.nanmax(excess):.4g} mm more than possible"
    # below the safe height the only rapids are the straight descents to just above the material (the
    # simulation above, every vertical descent a rapid, sees none of them cut)
    for a, b in zip(tp.moves, tp.moves[1:]):
        if b.kind is MoveKind.RAPID and b.z < safe - 1e-12:
            assert (a.x, a.y) == (b.x, b.y) and b.z < a.z
    assert result.diagnostics["layers"] == len(result.diagnostics["layer_z"]) >= 1
    return {"result": result, "path": tp, "sim": sim, "design": design, "grid": grid, "dev": dev}


@pytest.fixture(scope="module")
def pocket() -> TriMesh:
    return pocket_with_boss()


@pytest.mark.parametrize("cutter", [Cutter.flat(6), Cutter.bull(6, 1)], ids=["flat", "bull"])
def test_box_pocket_leaves_exactly_the_stock_to_leave(pocket, cutter):
    s = 0.5
    out = check_roughing(pocket, cutter, RoughingParams(stock_box=BOX, step_down=3.0, stock_to_leave=s))
    grid, h = out["grid"], out["sim"].heights
    X, Y = np.meshgrid(grid.xs(), grid.ys())
    floor = (X > 16) & (X < 44) & (Y > 13) & (Y < 18)                # the pocket floor beside the boss
    assert np.abs(h[floor] - (8.0 + s)).max() <= 1e-3 + zr._profile_height(cutter, 0.4 * cutter.diameter)
    if cutter.kind == "flat":
        assert np.abs(h[floor] - (8.0 + s)).max() <= 1e-3
    # the boss survives with s on top and on its walls; the block's top keeps s too
    boss = np.hypot(np.maximum(np.abs(X - 30) - 4, 0), np.maximum(np.abs(Y - 25) - 4, 0)) < s - 0.05
    assert h[boss].min() >= 15.0 + s - 1e-3 and h[(np.abs(X - 30) < 3) & (np.abs(Y - 25) < 3)].max() <= 15.0 + s + 1e-3
    assert np.abs(h[(X < 9) | (X > 51)] - (20.0 + s)).max() <= 1e-3
    # the pocket walls: cut to within the stock to leave plus the wall margin (horizontally)
    row = h[np.argmin(np.abs(grid.ys() - 15.05))]
    xs = grid.xs()
    down = xs[(row < 8.0 + s + 0.1) & (xs < 25)]
    wall = 10.0 + s
    assert wall <= down.min() <= wall + zr.wall_margin(RoughingParams()) + grid.cell + (cutter.corner_radius)
    d = out["result"].diagnostics
    assert d["regions"] >= 3 and d["unreachable"] > 0                 # the pocket's corners are out of reach
    assert set(d["entries"]) <= {HELIX, PLUNGE}


def test_sphere_on_plate_with_a_ball():
    mesh = load_stl(SHARED_STL / "sphere_on_plate.stl")
    lo, hi = mesh.bounds
    box = (float(lo[0]), float(lo[1]), float(lo[2]), float(hi[0]), float(hi[1]), float(hi[2]) + 2.0)
    params = RoughingParams(stock_box=box, step_down=3.0, stock_to_leave=0.5, stepover_percent=30.0)
    out = check_roughing(mesh, Cutter.ball(6), params, cell=0.2, safe=hi[2] + 10, clear=hi[2] + 15)
    d = out["result"].diagnostics
    # the region round the sphere is open to the air beside the stock: entered from there
    assert d["entries"].get(PLUNGE, 0) >= 1 and d["layers"] >= 10
    # a sphere and a plate: the design is reached within the cusp everywhere the tool fits
    assert np.nanpercentile(out["dev"], 50) < 1.0


def test_block_in_a_thin_margin():
    """A block filling its stock but for a 2 mm margin, a flat D16 at a 50 % step-over: no tool-centre position
    inside the stock clears the model, so the walls are cut from beside the stock, taking what the margin holds
    (ktoolcav of the shared benchmarks: "no material to remove")."""
    mesh = blocks_mesh([0.0, 40.0], [0.0, 20.0], [[30.0]])
    s = 0.3
    params = RoughingParams(stock_box=(-2.0, -2.0, 0.0, 42.0, 22.0, 31.0), step_down=10.0, stock_to_leave=s,
                            stepover_percent=50.0)
    out = check_roughing(mesh, Cutter.flat(16), params, cell=0.2, safe=40.0, clear=45.0)
    grid, h = out["grid"], out["sim"].heights
    X, Y = np.meshgrid(grid.xs(), grid.ys())
    gap = np.maximum(np.maximum(-X, X - 40.0), np.maximum(-Y, Y - 20.0))   # outside the block by this much
    ring = gap > s + zr.wall_margin(params) + grid.cell
    assert ring.any() and h[ring].max() <= min(out["result"].diagnostics["layer_z"]) + 1e-3
    assert h[gap < 0].min() >= 30.0 - 1e-3                                 # the block untouched


def test_tolerance_layers_on_the_sphere():
    mesh = load_stl(SHARED_STL / "sphere_on_plate.stl")
    lo, hi = mesh.bounds
    box = (float(lo[0]), float(lo[1]), float(lo[2]), float(hi[0]), float(hi[1]), float(hi[2]) + 2.0)
    fixed = RoughingParams(stock_box=box, step_down=3.0, stock_to_leave=0.5, stepover_percent=30.0)
    tol = RoughingParams(stock_box=box, step_down=3.0, stock_to_leave=0.5, stepover_percent=30.0,
                         layer_mode="tolerance", remaining_height=0.3)
    cutter = Cutter.ball(6)
    zf = zr.layer_heights(mesh, cutter, fixed, *zr._check(mesh, cutter, fixed))
    zt = zr.layer_heights(mesh, cutter, tol, *zr._check(mesh, cutter, tol))
    assert len(zt) > len(zf) and np.all(-np.diff(zt) <= 3.0 + 1e-9)
    check_roughing(mesh, cutter, tol, cell=0.25, safe=hi[2] + 10, clear=hi[2] + 15)


def test_the_seeds_step_over_of_0_95_d(pocket):
    """Seed 000 section 3.4.5: step-over c D, c = 0.95: past the radius the offsets alone would leave islands
    between loops and the stock's corners; the gaps are cleared (zlevel_clearing.fill_gaps)."""
    out = check_roughing(pocket, Cutter.flat(6), RoughingParams(stock_box=BOX, step_down=4.0, stepover_percent=95.0),
                         cell=0.2)
    assert out["sim"].heights.max() < BOX[5]                          # the stock's corners too


def test_zigzag_conventional_and_senses(pocket):
    flat = Cutter.flat(6)
    check_roughing(pocket, flat, RoughingParams(stock_box=BOX, step_down=4.0, pattern="zigzag",
                                                stepover_percent=45.0), cell=0.2)
    # the pocket's outermost loop at the floor: counter-clockwise for climb (material on the right of the
    # travel when cutting from the middle outwards), clockwise for conventional
    for direction, sign in (("climb", 1.0), ("conventional", -1.0)):
        params = RoughingParams(stock_box=BOX, step_down=4.0, direction=direction)
        segs = compute(pocket, flat, params).segments
        floor = [s for s in segs if abs(s.tips[0, 2] - 8.5 - 1e-5) < 1e-9 and len(s) > 4]
        widest = max(floor, key=lambda s: abs(P.signed_area(s.tips[:, :2])))
        assert math.copysign(1.0, P.signed_area(widest.tips[:, :2])) == sign
        helices = [s for s in segs if s.entry == HELIX]
        assert helices and all(s.helix_ccw == (direction == "climb") for s in helices)


def test_entries_helix_ramp_and_from_the_air():
    # a 20 x 20 boss on a plate: every region round it is open to the air outside the stock
    H = np.full((3, 3), 2.0)
    H[1, 1] = 12.0
    boss = blocks_mesh([0, 20, 40, 60], [0, 15, 35, 50], H, "boss on a plate")
    flat = Cutter.flat(6)
    out = check_roughing(boss, flat, RoughingParams(stock_box=BOX, step_down=4.0), cell=0.2)
    # each layer's first entry: down through air beside the stock (no material within the tool radius)
    firsts: dict = {}
    for seg in out["result"].segments:
        firsts.setdefault(round(float(seg.tips[0, 2]), 6), seg)
    assert len(firsts) >= 5
    for seg in firsts.values():
        x, y = seg.tips[0, :2]
        assert seg.entry == PLUNGE and (x < -3 or x > 63 or y < -3 or y > 53)
    # a slot 7 mm wide: a D6 tool centre has about 1 mm there, no room for a 3 mm helix: a ramp along the loop
    H = np.full((3, 3), 20.0)
    H[1, 1] = 12.0
    slot = blocks_mesh([0, 26.5, 33.5, 60], [0, 15, 35, 50], H, "slot")
    out = check_roughing(slot, flat, RoughingParams(stock_box=BOX, step_down=4.0, stock_to_leave=0.0), cell=0.1)
    assert out["result"].diagnostics["entries"].get(RAMP, 0) >= 2
    pocket = pocket_with_boss()
    out = check_roughing(pocket, flat, RoughingParams(stock_box=BOX, step_down=4.0, entry=RAMP), cell=0.2)
    assert RAMP in out["result"].diagnostics["entries"] and HELIX not in out["result"].diagnostics["entries"]
    # entry 'plunge' plunges straight into the pocket's material (the check above would catch it)
    plunge = RoughingParams(stock_box=BOX, step_down=4.0, entry=PLUNGE)
    tp = compute_roughing_toolpath(pocket, flat, plunge, LinkPolicy(SAFE, CLEAR))
    grid = Grid.covering(0, 0, 60, 50, 0.2)
    assert len(simulate(vertical_as_rapid(tp), flat, grid, box_heights(grid, 22.0)).collisions) > 0


def test_spots_too_small_to_enter_are_left_and_named():
    # a hole 6.3 mm square in a block: a D6 tool centre fits in a spot of about 0.26 mm there, its outline
    # shorter than the quarter diameter a ramp needs and no room for a helix: left uncut, named
    H = np.full((3, 3), 20.0)
    H[1, 1] = 5.0
    hole = blocks_mesh([0, 26.85, 33.15, 60], [0, 21.85, 28.15, 50], H, "small hole")
    result = compute(hole, Cutter.flat(6), RoughingParams(stock_box=BOX, step_down=4.0, stock_to_leave=0.0))
    spots = result.diagnostics["not_entered"]
    assert spots and all(s.startswith("the region at z") and "x 29.8" in s for s in spots)
    assert all(abs(sg.tips[:, 0] - 30).min() > 0.5 or sg.tips[:, 2].min() >= 20 - 1e-9 for sg in result.segments)
    # with entry 'plunge' (a tool that can) the spot is cut
    plunged = compute(hole, Cutter.flat(6), RoughingParams(stock_box=BOX, step_down=4.0, stock_to_leave=0.0,
                                                           entry=PLUNGE))
    assert not plunged.diagnostics["not_entered"]
    assert min(sg.tips[:, 2].min() for sg in plunged.segments) < 10


def test_stock_that_is_not_a_box():
    """Half the stock already down to 21.2 (what an earlier op left): no cutting above it there."""
    pocket = pocket_with_boss()
    grid = Grid.covering(0, 0, 60, 50, 0.5)
    heights = np.where(grid.xs()[None, :] < 30, 22.0, 21.2) * np.ones((grid.ny, 1))
    params = RoughingParams(stock_box=BOX, step_down=0.5, stock_heights=(grid, heights))
    out = check_roughing(pocket, Cutter.flat(6), params, cell=0.5)
    cuts = [m for m in out["path"].moves if m.kind is MoveKind.FEED and 21.2 < m.z < 22.0]
    assert cuts and max(m.x for m in cuts) < 30 + 3 + 1.0           # only over the higher half
    whole = compute(pocket, Cutter.flat(6), RoughingParams(stock_box=BOX, step_down=0.5))
    assert out["result"].diagnostics["points"] < whole.diagnostics["points"]


def test_progress_and_cancel(pocket):
    seen: list[float] = []
    compute(pocket, Cutter.flat(6), RoughingParams(stock_box=BOX, step_down=4.0),
            progress=lambda f: seen.append(f) or True)
    assert seen[0] == 0.0 and seen[-1] == 1.0 and all(0.0 <= f <= 1.0 for f in seen)
    assert all(b >= a - 1e-12 for a, b in zip(seen, seen[1:]))
    for stop_at in (0.3, 0.7):
        with pytest.raises(Cancelled):
            compute(pocket, Cutter.flat(6), RoughingParams(stock_box=BOX, step_down=4.0),
                    progress=lambda f, s=stop_at: f < s)


@pytest.mark.parametrize("change, message", [
    ({"stock_box": (0, 0, 0, 60, 50, 15)},
     "the stock is not above the model: its top 15 mm is below the model's top 20"),
    ({"final_z": 25.0}, "is not above the final depth 25 mm"),
    ({"step_down": 0.0}, "step-down must be a positive length, got 0"),
    ({"step_down": -1.0}, "step-down must be a positive length, got -1"),
    ({"step_down": math.nan}, "step-down must be a positive length, got nan"),
    ({"stepover_percent": 100.0}, r"step-over must be in \(0, 100\) %, got 100"),
    ({"stepover_percent": 0.0}, r"step-over must be in \(0, 100\) %, got 0"),
    ({"stock_to_leave": -0.1}, "stock to leave must be >= 0 mm, got -0.1"),
    ({"stock_to_leave": 7.0}, r"stock to leave 7 mm is larger than the tool \(diameter 6 mm"),
    ({"stock_to_leave_axial": 6.5}, r"axial stock to leave 6.5 mm is larger than the tool"),
    ({"ramp_angle_deg": 0.0}, r"ramp angle must be in \[0.5, 45\] deg, got 0"),
    ({"ramp_angle_deg": 90.0}, r"ramp angle must be in \[0.5, 45\] deg, got 90"),     # made Z NaN
    ({"ramp_angle_deg": 1e-6}, r"ramp angle must be in \[0.5, 45\] deg, got 1e-06"),  # made gigabytes of ramp
    ({"helix_diameter_percent": 1e-6}, r"helix diameter must be in \[10, 100\] %, got 1e-06"),
    ({"stock_box": (10, 0, 0, 60, 50, 22)}, r"the model \(x 0..60, y 0..50, z 0..20 mm\) lies outside the stock"),
    ({"stock_box": (0, 0, 0, 60, 50, math.inf)}, "stock box .* must be finite numbers"),
    ({"stock_box": (0, 0, 0, 0, 50, 22)}, "stock box is empty"),
    ({"pattern": "spiral"}, "pattern must be 'offset' or 'zigzag', got 'spiral'"),
    ({"entry": "dive"}, "entry must be one of plunge, helix, ramp, got 'dive'|entry must be 'helix' or 'ramp'"),
])
def test_bad_input_refused_by_name(pocket, change, message):
    params = RoughingParams(**{"stock_box": BOX, **change})
    with pytest.raises(TmmError, match=message):
        compute_roughing_toolpath(pocket, Cutter.flat(6), params, LinkPolicy(SAFE, CLEAR))


def test_bad_tools_and_heights(pocket):
    params = RoughingParams(stock_box=BOX)
    with pytest.raises(TmmError, match="cutter is not supported by z-level roughing"):
        compute(pocket, Cutter.vbit(6, 90), params)
    with pytest.raises(TmmError, match="step-down 4 mm is larger than the cutting length 3 mm"):
        compute(pocket, Cutter(6.0, 0.0, cutting_length=3.0), RoughingParams(stock_box=BOX, step_down=4.0))
    with pytest.raises(TmmError, match="safe height 20 mm is not above the stock top 22 mm"):
        compute_roughing_toolpath(pocket, Cutter.flat(6), params, LinkPolicy(20.0, 25.0))


def test_work_above_the_limit_refused_before_any_work(pocket):
    calls: list[float] = []
    old = limits.set_limits(max_points=10_000)
    try:
        with pytest.raises(TmmError, match="roughing loop points"):
            compute(pocket, Cutter.flat(6), RoughingParams(stock_box=BOX, step_down=0.01, stepover_percent=1.0),
                    progress=lambda f: calls.append(f) or True)
    finally:
        limits.set_limits(max_points=old.max_points)
    assert calls == []                                                   # nothing computed
    with pytest.raises(TmmError, match=r"2200 layers \(step-down 0.01 mm\), step-over 1 % of D6"):
        zr.estimate_work(RoughingParams(stock_box=BOX, step_down=0.01, stepover_percent=1.0), Cutter.flat(6), BOX)
    work = zr.estimate_work(RoughingParams(stock_box=BOX), Cutter.flat(6), BOX)
    assert 0 < work.count < 1e7 and work.paces == (("roughing", work.count),)
