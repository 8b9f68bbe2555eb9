"""The tool holder clearance: the assembly drop's pieces by name, the check of finished tool paths (a raster
dropped with the cutter alone collides in a deep cavity, the same raster dropped with the whole assembly is
clear), an independent brute force (a dense point sample of the model and each point's exact distance to
every body frustum), the shortest stick-out, tilted poses, and bad inputs."""
from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest

from tmm_workbench.core.arcs import Arc
from tmm_workbench.core.errors import Cancelled, TmmError
from tmm_workbench.core.geometry.axes import slerp
from tmm_workbench.core.geometry.mesh import TriMesh
from tests.core.cavity import cavity_mesh
from tmm_workbench.core.query.drop import DropSurface
from tmm_workbench.core.query.drop_assembly import AssemblyDrop, body_pieces
from tmm_workbench.core.toolpath import MoveKind, Toolpath
from tmm_workbench.core.tools.assembly import ToolAssembly
from tmm_workbench.core.tools.cutter import Cutter
from tmm_workbench.core.verify.body_distance import SurfacePoints, signed_distance
from tmm_workbench.core.verify.holder_clearance import check_holder_clearance, minimum_stick_out, sample_moves

STEP = 0.5
ROWS = np.arange(-30.0, 30.1, 6.0)
BRUTE_ROWS = (-30.0, 0.0, 12.0)   # near a wall, across the boss, beside it


@pytest.fixture(scope="module")
def cavity() -> TriMesh:
    return cavity_mesh()


@pytest.fixture(scope="module")
def assembly() -> ToolAssembly:
    """Ball D4, 12 mm flutes, D4 shank 20 mm out of an ER32 collet chuck (D50 nose), 1 mm clearances."""
    return ToolAssembly(Cutter.ball(4), 4, 20, flute_length=12, holder="SK40 ER32x70")


@pytest.fixture(scope="module")
def surface(cavity) -> DropSurface:
    return DropSurface(cavity)


@pytest.fixture(scope="module")
def raster() -> np.ndarray:
    """Zig-zag rows across the pocket, STEP apart along the rows."""
    xs = np.arange(-34.0, 34.01, STEP)
    return np.vstack([np.column_stack([xs if k % 2 == 0 else xs[::-1], np.full(xs.size, y)])
                      for k, y in enumerate(ROWS)])


def path_of(xy: np.ndarray, z: np.ndarray) -> Toolpath:
    tp = Toolpath()
    for (x, y), h in zip(xy, z):
        tp.add(MoveKind.FEED, x, y, h)
    return tp


# ---- an independent brute force: a dense sample of the model, exact distances to every body frustum ----

def dense_sample(mesh: TriMesh, spacing: float) -> np.ndarray:
    """Points on every triangle on a (u, v) grid folded into the triangle, `spacing` apart or closer."""
    out = []
    for a, b, c in mesh.vertices[mesh.triangles]:
        n = max(1, int(math.ceil(max(np.linalg.norm(b - a), np.linalg.norm(c - a), np.linalg.norm(c - b))
                                 / spacing)))
        u, v = np.meshgrid(np.linspace(0, 1, n + 1), np.linspace(0, 1, n + 1))
        ok = u + v <= 1 + 1e-12
        out.append(a + u[ok, None] * (b - a) + v[ok, None] * (c - a))
    return np.vstack(out)


def frustum_distance(q: np.ndarray, tip: np.ndarray, axis: np.ndarray, body) -> np.ndarray:
    """Signed distance from the points q to the solid frustum (minus the depth inside)."""
    w = q - tip
    h = w @ axis
    return trapezoid_distance(np.linalg.norm(w - h[:, None] * axis, axis=1), h, body)


def trapezoid_distance(rho: np.ndarray, h: np.ndarray, body) -> np.ndarray:
    """In the point's (radius, height) half plane, to the trapezoid r <= r0 + (r1 - r0) t, z0 <= h <= z1: the
    nearest of the bottom, side and top edges by projection."""
    z0, z1, r0, r1, _ = body
    t = np.clip((h - z0) / (z1 - z0), 0, 1)
    inside = (h >= z0) & (h <= z1) & (rho <= r0 + (r1 - r0) * t)
    best = np.full(len(rho), np.inf)
    for p0, p1 in (((0, z0), (r0, z0)), ((r0, z0), (r1, z1)), ((r1, z1), (0, z1))):
        p0, p1 = np.array(p0, float), np.array(p1, float)
        e = p1 - p0
        s = np.clip(((rho - p0[0]) * e[0] + (h - p0[1]) * e[1]) / (e @ e), 0, 1)
        best = np.minimum(best, np.hypot(rho - p0[0] - s * e[0], h - p0[1] - s * e[1]))
    return np.where(inside, -best, best)


def brute_closest(points: np.ndarray, tip, axis, bodies) -> tuple[float, int]:
    """(distance - clearance, body) of the body coming closest to the points relative to its clearance; each
    body sees only the points in its height range grown by its clearance (the others are further)."""
    tip, axis = np.asarray(tip, float), np.asarray(axis, float)
    w = points - tip
    h = w @ axis
    rho = np.linalg.norm(w - h[:, None] * axis, axis=1)
    worst, which = math.inf, -1
    for b, body in enumerate(bodies):
        z0, z1, r0, r1, c = body
        keep = (h > z0 - c) & (h < z1 + c) & (rho < max(r0, r1) + c)
        if keep.any():
            d = trapezoid_distance(rho[keep], h[keep], body).min() - c
            if d < worst:
                worst, which = d, b
    return worst, which


@pytest.fixture(scope="module")
def dense(cavity) -> np.ndarray:
    pts = dense_sample(cavity, 0.4)
    return pts[np.argsort(pts[:, 0])]   # sorted by x: a tool's neighbourhood is a slice


def brute_over_raster(dense: np.ndarray, assembly: ToolAssembly, xy: np.ndarray, z: np.ndarray) -> np.ndarray:
    """Per CL point: the smallest distance - clearance over the shank and holder bodies (vertical tool)."""
    bodies = [b for b, p in zip(assembly.bodies(), body_pieces(assembly)) if p != "cutter"]
    reach = max(max(b[2], b[3]) + b[4] for b in bodies) + 1.0
    lo_z, hi_z = bodies[0][0] - bodies[0][4], bodies[-1][1] + bodies[-1][4]
    out = np.full(len(xy), math.inf)
    for k, ((x, y), h) in enumerate(zip(xy, z)):
        near = dense[np.searchsorted(dense[:, 0], x - reach):np.searchsorted(dense[:, 0], x + reach)]
        near = near[(np.abs(near[:, 1] - y) < reach) & (near[:, 2] > h + lo_z) & (near[:, 2] < h + hi_z)]
        if len(near):
            out[k] = brute_closest(near, (x, y, h), (0.0, 0.0, 1.0), bodies)[0]
    return out


# ---- the pieces and the drop ----

def test_bodies_are_named_by_piece() -> None:
    a = ToolAssembly(Cutter.ball(4), 6, 40, flute_length=8, neck_diameter=3.5, neck_length=10, shank_cone_deg=30,
                     holder="ER16 nut")
    assert body_pieces(a) == ("neck", "shank", "shank", "holder")
    v = ToolAssembly(Cutter.vbit(6, 90), 6, 25, flute_length=10, holder="SK40 ER32x70")
    assert body_pieces(v) == ("cutter", "shank", "holder", "holder", "holder")
    assert body_pieces(ToolAssembly(Cutter.flat(6), 6, 30, flute_length=20)) == ("shank",)


def test_assembly_drop_lifts_over_the_cutter_and_names_the_owner(cavity, surface, assembly, raster) -> None:
    drop = AssemblyDrop(cavity, assembly, surface)
    assert drop.pieces == ("shank", "holder", "holder", "holder")
    assert drop.surface.index is surface.index
    z, owner = drop.heights(raster, -40.0)
    zc = surface.drop(assembly.cutter, raster, -40.0)
    assert np.all(z >= zc - 1e-9)
    by_cutter = owner == -1
    np.testing.assert_allclose(z[by_cutter], zc[by_cutter], atol=1e-9)
    names = drop.piece_names(owner)
    assert set(names) == {"cutter", "shank", "holder"}
    assert np.all(z[names != "cutter"] > zc[names != "cutter"] + 1e-9)
    z2, owner2 = AssemblyDrop(cavity, assembly).heights(raster, -40.0)   # its own index
    np.testing.assert_array_equal(z, z2)
    np.testing.assert_array_equal(owner, owner2)
    assert drop.piece(-2) == "floor" and drop.piece(1) == "holder"


# ---- the check: (a) cutter-only raster flagged, (b) assembly raster clear, (c) the brute force agrees ----

def test_cutter_only_raster_collides_and_assembly_raster_is_clear(cavity, surface, assembly, raster, dense) -> None:
    zc = surface.drop(assembly.cutter, raster, -40.0)
    za, _ = AssemblyDrop(cavity, assembly, surface).heights(raster, -40.0)
    step = STEP + 1e-6      # the samples are the CL points: between them the drop's height is not linear
    bad = check_holder_clearance(cavity, assembly, path_of(raster, zc), surface, sample_step=step)
    good = check_holder_clearance(cavity, assembly, path_of(raster, za), surface, sample_step=step)
    assert good.ok and good.count == 0 and good.deepest == 0.0
    assert "clear" in good.summary() and f"{good.samples:,} positions" in good.summary()
    assert not bad.ok and bad.per_piece.keys() == {"shank", "holder"}
    row_change = int(round(np.diff(ROWS)[0] / STEP))           # the moves between rows: 12 samples each
    assert bad.count == sum(bad.per_piece.values()) and bad.samples == len(raster) + (len(ROWS) - 1) * (row_change - 1)
    # vertical intrusion: how far the tool must rise, the assembly drop minus the path's height
    at_cl = np.all(bad.tip[:, :2] == raster[bad.move], axis=1)   # the samples at CL points (move ends)
    np.testing.assert_allclose(bad.intrusion[at_cl], (za - zc)[bad.move[at_cl]], atol=1e-9)
    assert bad.deepest == pytest.approx(21.0, abs=1e-6)   # holder face 1 mm above the plate, tip on the floor
    located = np.isfinite(bad.contact).all(axis=1)       # the deepest max_contacts (1000) are located
    assert located.sum() == min(bad.count, 1000)
    assert bad.intrusion[located].min() >= bad.intrusion[~located].max()
    assert "holder collision" in bad.summary() and "holder 21.000 mm too low" in bad.summary()

    rows = np.isin(raster[:, 1], BRUTE_ROWS) & (np.arange(len(raster)) % 2 == 0)
    brute_good = brute_over_raster(dense, assembly, raster[rows], za[rows])
    assert brute_good.min() >= -1e-6           # no sample point closer to a body than its clearance
    brute_bad = brute_over_raster(dense, assembly, raster[rows], zc[rows])
    flagged = np.zeros(len(raster), bool)
    flagged[bad.move[at_cl]] = True
    assert np.any(brute_bad < -0.5)
    assert np.all(flagged[rows][brute_bad < -1e-6])     # every brute-force collision is flagged
    assert np.all(brute_bad[flagged[rows]] < 0.4)        # and every flagged point is near enough (sample spacing)


def test_contacts_lie_on_the_model_inside_the_clearance(cavity, surface, assembly, raster) -> None:
    zc = surface.drop(assembly.cutter, raster, -40.0)
    bad = check_holder_clearance(cavity, assembly, path_of(raster, zc), surface, sample_step=STEP + 1e-6,
                                 max_contacts=50)
    located = np.isfinite(bad.contact).all(axis=1)
    assert located.sum() == 50
    bodies = AssemblyDrop(cavity, assembly, surface).bodies
    for tip, q, piece in zip(bad.tip[located], bad.contact[located], bad.piece[located]):
        d = min(frustum_distance(q[None], tip, np.array([0.0, 0.0, 1.0]), b)[0] - b[4] for b in bodies[1:]) \
            if piece == "holder" else frustum_distance(q[None], tip, np.array([0.0, 0.0, 1.0]), bodies[0])[0] - 1
        assert d < 0.2


# ---- (d) the shortest stick-out ----

def test_minimum_stick_out_makes_the_holder_set_no_height(cavity, surface, assembly, raster) -> None:
    found = minimum_stick_out(cavity, assembly, raster, surface, floor_z=-40.0)
    assert found.stick_out == pytest.approx(41.0, abs=1e-6)    # the plate (+1 mm clearance) from the floor
    assert found.limiting >= 0 and found.needed[found.limiting] == found.stick_out
    assert found.current == 20 and found.fits
    free, _ = AssemblyDrop(cavity, replace(assembly, holder=None), surface).heights(raster, -40.0)
    z, owner = AssemblyDrop(cavity, replace(assembly, stick_out=found.stick_out), surface).heights(raster, -40.0)
    np.testing.assert_allclose(z, free, atol=1e-9, rtol=0)
    shorter, _ = AssemblyDrop(cavity, replace(assembly, stick_out=found.stick_out - 1.0), surface).heights(
        raster, -40.0)
    assert np.max(shorter - free) == pytest.approx(1.0, abs=1e-6)
    # where the shank itself lifts the tool (1 mm clearance, 3 degree walls), no stick-out helps: reported
    zc = surface.drop(assembly.cutter, raster, -40.0)
    lifted = np.flatnonzero(free > zc + 1e-9)
    np.testing.assert_array_equal(found.shank_points, lifted)
    assert "shank itself" in found.summary() and "41.000 mm" in found.summary()
    as_path = minimum_stick_out(cavity, assembly, path_of(raster, zc), surface, floor_z=-40.0)
    assert as_path.stick_out == found.stick_out


def test_minimum_stick_out_within_the_tool_length(cavity, surface, assembly, raster) -> None:
    short = replace(assembly, overall_length=35.0)
    found = minimum_stick_out(cavity, short, raster[:40], surface, floor_z=-40.0)
    assert not found.fits and "longer tool" in found.summary()
    shallow = minimum_stick_out(cavity, assembly, np.array([[0.0, 0.0]]), surface)   # on the boss top
    assert shallow.stick_out == assembly.minimum_stick_out and shallow.limiting == -1


# ---- (e) tilted tool ----

def tilted(deg: float) -> np.ndarray:
    a = math.radians(deg)
    return np.array([math.sin(a), 0.0, math.cos(a)])


def test_tilted_poses_against_the_brute_force(cavity, assembly, dense) -> None:
    tip = np.array([-20.0, 0.0, -10.0])
    toward, away = tilted(-30.0), tilted(30.0)   # toward the -X wall's rim, away from it
    bodies = [b for b, p in zip(assembly.bodies(), body_pieces(assembly)) if p != "cutter"]
    gap_toward, body_toward = brute_closest(dense, tip, toward, bodies)
    gap_away, _ = brute_closest(dense, tip, away, bodies)
    assert gap_toward < -2.0 and gap_away > 2.0
    for axis, expect in ((toward, True), (away, False)):
        tp = Toolpath()
        tp.add(MoveKind.FEED, *tip, axis=tuple(axis))
        r = check_holder_clearance(cavity, assembly, tp, surface_step=0.25)
        assert r.samples == 1 and r.tilted_samples == 1 and (not r.ok) == expect
    tp = Toolpath()
    tp.add(MoveKind.FEED, *tip, axis=tuple(toward))
    r = check_holder_clearance(cavity, assembly, tp, surface_step=0.25)
    assert r.piece[0] == body_pieces(assembly)[assembly.bodies().index(bodies[body_toward])]
    # both measure to a point sample: each at most its spacing / sqrt(3) short of the surface's distance
    assert r.intrusion[0] == pytest.approx(-gap_toward, abs=(0.25 + 0.4) / math.sqrt(3))
    assert frustum_distance(r.contact, tip, toward, bodies[body_toward])[0] - bodies[body_toward][4] \
        == pytest.approx(-r.intrusion[0], abs=1e-9)


def test_five_axis_move_samples_by_slerp_and_flags_its_end(cavity, assembly) -> None:
    tip = (-20.0, 0.0, -10.0)
    tp = Toolpath()
    tp.add(MoveKind.FEED, *tip, axis=tuple(tilted(30.0)))
    tp.add(MoveKind.FEED, *tip, axis=tuple(tilted(-30.0)))
    tips, axes, move = sample_moves(tp, 0.5, 100.0)
    s = np.arange(len(axes) - 1) / (len(axes) - 1) + 1 / (len(axes) - 1)
    np.testing.assert_allclose(axes[1:], slerp(tilted(30.0), tilted(-30.0), s), atol=1e-12)
    assert len(axes) - 1 == math.ceil(math.radians(60) * 100.0 / 0.5)    # the point 100 mm up moves <= 0.5 mm
    r = check_holder_clearance(cavity, assembly, tp)
    assert not r.ok and r.tilted_samples == r.samples - 1   # the vertical axis midway is checked by the drop
    assert np.all(r.axis[:, 0] < 0)                          # only the poses leaning toward the wall collide


def test_samples_follow_lines_and_arcs() -> None:
    tp = Toolpath()
    tp.add(MoveKind.FEED, 0, 0, 0)
    tp.add(MoveKind.FEED, 3, 4, -1)                                   # 5 mm in XY
    tp.add(MoveKind.FEED, 13, 4, -1, arc=Arc((8.0, 4.0, -1.0), True, "XY"))   # a half circle of radius 5
    tips, axes, move = sample_moves(tp, 0.5, 50.0)
    line = move == 1
    assert line.sum() == 10 and np.allclose(tips[line][-1], (3, 4, -1))
    on_arc = tips[move == 2]
    np.testing.assert_allclose(np.hypot(on_arc[:, 0] - 8, on_arc[:, 1] - 4), 5.0, atol=1.1e-3)
    assert np.all(on_arc[:, 1] >= 4 - 1e-9)                           # clockwise from (3, 4): over the top
    gaps = np.linalg.norm(np.diff(tips[:, :2], axis=0), axis=1)    # a vertical tool: apart in XY
    assert gaps.max() <= 0.5 + 1e-9 and np.all(axes == (0, 0, 1))


def test_signed_distance_of_a_cone() -> None:
    body = (10.0, 20.0, 2.0, 7.0, 0.0)
    rho = np.array([0.0, 1.0, 10.0, 4.5, 0.0, 3.0])
    h = np.array([5.0, 15.0, 20.0, 15.0, 25.0, 10.0])
    d = signed_distance(rho, h, body)
    cos = 10 / math.hypot(5, 10)   # the side's normal has this horizontal part
    # below the tip's disc; inside, nearest the side; beside the top rim; on the side; above; beside the bottom rim
    np.testing.assert_allclose(d, [5.0, -3.5 * cos, 3.0, 0.0, 5.0, 1.0 * cos], atol=1e-12)


def test_surface_sample_covers_within_its_error() -> None:
    """Every point of a triangle (a regular one and an obtuse sliver) within step / sqrt(3) of the sample."""
    from scipy.spatial import cKDTree

    v = np.array([[0, 0, 0], [10, 0, 0], [5, 8, 1], [0, 20, 0], [30, 21, 2]], dtype=float)
    mesh = TriMesh(v, np.array([[0, 1, 2], [0, 3, 4]]), "two")
    pts = SurfacePoints(mesh, 0.5)
    rng = np.random.default_rng(3)
    w = rng.dirichlet((1, 1, 1), size=(4000, 2))
    probe = np.einsum("ntk,tkd->ntd", w, v[mesh.triangles]).reshape(-1, 3)
    d, _ = cKDTree(pts.points).query(probe)
    assert d.max() <= pts.error + 1e-9 and pts.error == pytest.approx(0.5 / math.sqrt(3))


# ---- (f) bad inputs and cancel ----

def test_bad_inputs_are_refused_by_name(cavity, surface, assembly, raster) -> None:
    tp = path_of(raster[:3], np.zeros(3))
    cases = [
        (lambda: AssemblyDrop(cavity, "ball 4"), "assembly must be a ToolAssembly"),
        (lambda: AssemblyDrop("cavity.stl", assembly), "mesh must be a TriMesh"),
        (lambda: AssemblyDrop(TriMesh(cavity.vertices, cavity.triangles), assembly, surface), "indexes mesh"),
        (lambda: AssemblyDrop(cavity, assembly, surface).heights(np.array([[0.0, np.nan]])), "drop point 0"),
        (lambda: AssemblyDrop(cavity, assembly, surface).heights(np.zeros((2, 3))), "shape (n, 2)"),
        (lambda: AssemblyDrop(cavity, assembly, surface).heights(raster, math.nan), "floor_z"),
        (lambda: AssemblyDrop(cavity, assembly, surface).heights_of(["holder", "spindle"], raster), "'spindle'"),
        (lambda: AssemblyDrop(cavity, replace(assembly, holder=None), surface).face_heights(raster), "no holder"),
        (lambda: check_holder_clearance(cavity, assembly, raster), "toolpath must be a Toolpath"),
        (lambda: check_holder_clearance(cavity, assembly, Toolpath()), "has no moves"),
        (lambda: check_holder_clearance(cavity, assembly, tp, sample_step=0), "sample step"),
        (lambda: check_holder_clearance(cavity, assembly, tp, tolerance=-1), "tolerance"),
        (lambda: check_holder_clearance(cavity, assembly, tp, surface_step=math.inf), "surface sample step"),
        (lambda: check_holder_clearance(cavity, assembly, tp, max_contacts=-1), "max_contacts"),
        (lambda: minimum_stick_out(cavity, None, raster), "assembly must be a ToolAssembly"),
        (lambda: minimum_stick_out(cavity, assembly, Toolpath()), "no cutting moves"),
    ]
    nan_path = Toolpath()
    nan_path.add(MoveKind.FEED, 0, 0, math.nan)
    cases.append((lambda: check_holder_clearance(cavity, assembly, nan_path), "move 0 is not finite"))
    long_axis = Toolpath()
    long_axis.add(MoveKind.FEED, 0, 0, 0, axis=(0.0, 0.0, 2.0))
    cases.append((lambda: check_holder_clearance(cavity, assembly, long_axis), "not a unit vector"))
    five = Toolpath()
    five.add(MoveKind.FEED, 0, 0, 0, axis=tuple(tilted(10.0)))
    cases.append((lambda: minimum_stick_out(cavity, assembly, five), "3-axis"))
    for call, words in cases:
        with pytest.raises(TmmError) as info:
            call()
            print("did not raise:", words)
        assert words in str(info.value), (words, str(info.value))


def test_cancel_stops_the_check(cavity, surface, assembly, raster) -> None:
    zc = surface.drop(assembly.cutter, raster, -40.0)
    with pytest.raises(Cancelled):
        check_holder_clearance(cavity, assembly, path_of(raster, zc), surface, progress=lambda f: False)
