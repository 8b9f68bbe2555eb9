"""The tool assembly dropped along a direction (native.drop_assembly_along, AssemblyDrop.along) against a numpy
brute force that knows nothing of the kernel's convex solids: the mesh sampled densely, each sample's entry
into each grown piece found on its own line of motion (the ball: a quadratic; the cylinder above it and each
body grown by its clearance: the first zero of the signed distance to its meridian section, convex along the
line). The kernel's travel must come before every sample's (no gouge) and after the earliest one by no more
than the sampling allows (touch)."""
from __future__ import annotations

import numpy as np
import pytest

from tests.conftest import grid_mesh
from tmm_workbench.core.errors import TmmError
from tmm_workbench.core.kernel import native
from tmm_workbench.core.query.drop_assembly import AssemblyDrop
from tmm_workbench.core.tools.assembly import ToolAssembly
from tmm_workbench.core.tools.cutter import Cutter
from tests.core.test_drop_assembly import mesh_samples

BALL = 3.0
BODIES = np.array([[12.0, 20.0, 3.0, 3.0, 0.5], [20.0, 24.0, 3.0, 8.0, 1.0], [24.0, 70.0, 16.0, 16.0, 2.0]])
GOLDEN = (np.sqrt(5.0) - 1.0) / 2.0


def frame(axis):
    """Orthonormal (e1, e2, axis) rows."""
    a = np.asarray(axis, float)
    ref = np.array([1.0, 0.0, 0.0]) if abs(a[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    e1 = ref - ref.dot(a) * a
    e1 /= np.linalg.norm(e1)
    return np.array([e1, np.cross(a, e1), a])


def signed_distance(poly, x, z):
    """Signed distance (negative inside) of the points (x, z) to the convex counter-clockwise polygon."""
    d = np.full(x.shape, np.inf)
    inside = np.ones(x.shape, bool)
    for (ax, az), (bx, bz) in zip(poly, poly[1:] + poly[:1]):
        tx, tz = bx - ax, bz - az
        if tx == 0.0 and tz == 0.0:
            continue
        s = np.clip(((x - ax) * tx + (z - az) * tz) / (tx * tx + tz * tz), 0.0, 1.0)
        d = np.minimum(d, np.hypot(ax + s * tx - x, az + s * tz - z))
        inside &= tx * (z - az) - tz * (x - ax) >= 0.0
    return np.where(inside, -d, d)


def convex_entry(poly, clearance, q, w, before=np.inf, lo=-150.0, hi=150.0):
    """First t with q - t w within `clearance` of the solid of revolution of section `poly` (tool frame), inf
    where the line passes by: golden section for the convex signed distance's minimum, then bisection. Only the
    samples whose line meets the solid's bounding ball before `before` are solved."""
    (zs, rs) = zip(*[(z, abs(x)) for x, z in poly])
    centre = np.array([0.0, 0.0, 0.5 * (min(zs) + max(zs))])
    radius = np.hypot(max(rs), 0.5 * (max(zs) - min(zs))) + clearance + 1e-6
    out = np.full(len(q), np.inf)
    near = (np.linalg.norm(np.cross(q - centre, w), axis=1) <= radius) & ((q - centre) @ w - radius <= before)
    q = q[near]

    def g(t):
        p = q - t[:, None] * w
        return signed_distance(poly, np.hypot(p[:, 0], p[:, 1]), p[:, 2]) - clearance
    a, b = np.full(len(q), lo), np.full(len(q), hi)
    x1, x2 = b - GOLDEN * (b - a), a + GOLDEN * (b - a)
    f1, f2 = g(x1), g(x2)
    for _ in range(50):  # each step keeps one of the two inner points
        left = f1 < f2
        a, b = np.where(left, a, x1), np.where(left, x2, b)
        new = np.where(left, b - GOLDEN * (b - a), a + GOLDEN * (b - a))
        f_new = g(new)
        x1, x2, f1, f2 = (np.where(left, new, x2), np.where(left, x1, new),
                          np.where(left, f_new, f2), np.where(left, f1, f_new))
    t_min = 0.5 * (a + b)
    hits = g(t_min) <= 0.0
    a, b = np.full(len(q), lo), t_min
    for _ in range(45):
        m = 0.5 * (a + b)
        inside = g(m) <= 0.0
        b = np.where(inside, m, b)
        a = np.where(inside, a, m)
    out[near] = np.where(hits, b, np.inf)
    return out


def cylinder_entry(poly, clearance, q, w):
    """A lower bound of each line's entry into the solid grown by `clearance` (inf where it passes by): its entry
    into the capped cylinder around it (1e-6 wider, as the bounding ball)."""
    (zs, rs) = zip(*[(z, abs(x)) for x, z in poly])
    grow = clearance + 1e-6
    r, z0, z1 = max(rs) + grow, min(zs) - grow, max(zs) + grow
    a, b = w[0] * w[0] + w[1] * w[1], q[:, 0] * w[0] + q[:, 1] * w[1]
    c = q[:, 0] ** 2 + q[:, 1] ** 2 - r * r
    if a < 1e-12:   # along the axis: in the cylinder for every t or none
        r_lo, r_hi = np.where(c <= 0.0, -np.inf, np.inf), np.where(c <= 0.0, np.inf, -np.inf)
    else:
        root = np.sqrt(np.maximum(b * b - a * c, 0.0))
        r_lo, r_hi = np.where(b * b >= a * c, (b - root) / a, np.inf), (b + root) / a
    if w[2] == 0.0:
        inside = (q[:, 2] >= z0) & (q[:, 2] <= z1)
        z_lo, z_hi = np.where(inside, -np.inf, np.inf), np.where(inside, np.inf, -np.inf)
    else:
        t0, t1 = (q[:, 2] - z1) / w[2], (q[:, 2] - z0) / w[2]
        z_lo, z_hi = np.minimum(t0, t1), np.maximum(t0, t1)
    lo, hi = np.maximum(r_lo, z_lo), np.minimum(r_hi, z_hi)
    return np.where(lo <= hi, lo, np.inf)


def first_entry(poly, clearance, q, w, before=np.inf, chunk=4096):
    """The least of convex_entry over the samples: solved in the order of their cylinder_entry (a lower bound),
    until the next one's bound is past the best so far (the same least: a sample's entry is its own)."""
    bound = cylinder_entry(poly, clearance, q, w)
    order = np.argsort(bound, kind="stable")
    order = order[np.isfinite(bound[order])]
    best = np.inf
    for k in range(0, len(order), chunk):
        part = order[k:k + chunk]
        if bound[part[0]] > best:
            break
        best = min(best, convex_entry(poly, clearance, q[part], w, before).min(initial=np.inf))
    return best


def ball_entry(q, w):
    """First t with q - t w in the ball of radius BALL centred BALL up the axis (a quadratic)."""
    d = q - np.array([0.0, 0.0, BALL])
    wd = d @ w
    disc = wd * wd - (np.einsum("ij,ij->i", d, d) - BALL * BALL)
    return np.where(disc >= 0.0, wd - np.sqrt(np.maximum(disc, 0.0)), np.inf)


def reference(samples, start, axis, direction):
    """(travel, piece, sorted travels of the pieces) of the earliest sample entry: piece -1 the cutter (the ball,
    and the cylinder of its radius up to the first body), i body i."""
    f = frame(axis)
    q, w = (samples - start) @ f.T, f @ direction
    ball = ball_entry(q, w).min(initial=np.inf)
    best = [min(ball, first_entry([(-BALL, BALL), (BALL, BALL), (BALL, BODIES[0, 0]), (-BALL, BODIES[0, 0])],
                                  0.0, q, w, ball + 1.0))]
    for z0, z1, r0, r1, c in BODIES:  # samples met 1 mm past the best so far cannot win nor come second close
        best.append(first_entry([(-r0, z0), (r0, z0), (r1, z1), (-r1, z1)], c, q, w, min(best) + 1.0))
    best = np.array(best)
    return best.min(), int(np.argmin(best)) - 1, np.sort(best)


@pytest.fixture(scope="module")
def step_mesh():
    """Waves with a 40 mm step beyond x = 28 (a wall the bodies meet sideways)."""
    return grid_mesh(lambda x, y: np.where(x > 28.0, 40.0, 3.0 * np.sin(x / 4.0) * np.cos(y / 5.0)), 40, 40,
                     (0.0, 0.0, 40.0, 40.0), "step")


@pytest.fixture(scope="module")
def coarse_step():
    """The same on a coarser grid (fewer samples for the brute force)."""
    return grid_mesh(lambda x, y: np.where(x > 28.0, 40.0, 3.0 * np.sin(x / 4.0) * np.cos(y / 5.0)), 20, 20,
                     (0.0, 0.0, 40.0, 40.0), "step")


def test_against_brute_force(coarse_step):
    step_mesh = coarse_step
    samples = mesh_samples(step_mesh.vertices, step_mesh.triangles, 0.3)
    rng = np.random.default_rng(7)
    cutter = native.Cutter(BALL, BALL)
    pieces = []
    for k in range(9):
        direction = np.array([rng.uniform(-0.4, 0.4), rng.uniform(-0.4, 0.4), -1.0]) if k % 3 else \
            np.array([1.0, rng.uniform(-0.3, 0.3), rng.uniform(-0.5, 0.0)])
        direction /= np.linalg.norm(direction)
        index = native.DirectionalIndex(step_mesh.vertices, step_mesh.triangles, direction)
        axis = np.array([rng.uniform(-0.8, 0.8), rng.uniform(-0.8, 0.8), 1.0])
        axis /= np.linalg.norm(axis)
        starts = np.column_stack([rng.uniform(8, 32, 2), rng.uniform(8, 32, 2), np.full(2, 15.0)])
        travel, set_by = native.drop_assembly_along(index, cutter, BODIES, starts, axis)
        for s, t, by in zip(starts, travel, set_by):
            ref, ref_by, order = reference(samples, s, axis, direction)
            if ref == np.inf:  # the tool passes the mesh by
                assert t == np.inf and by == -2
                continue
            assert t <= ref + 1e-7, f"a sample is met {t - ref} before the kernel's contact"
            assert ref - t <= 0.08, f"not touching: {ref - t}"
            if order[1] - order[0] > 0.1:  # a clear winner (a second within 1 mm is seen)
                assert by == ref_by
            pieces.append(by)
    assert sum(p >= 0 for p in pieces) >= 4 and sum(p == -1 for p in pieces) >= 4  # both matter here


def test_assembly_drop_along(step_mesh):
    """AssemblyDrop.along: along the tool's axis the vertical heights(); tilted the kernel's answer with the
    assembly's bodies; bad input named."""
    tool = ToolAssembly(Cutter.ball(6.0), shank_diameter=6.0, stick_out=25.0, flute_length=12.0,
                        holder="SK40 ER32x70", shank_clearance=0.5, holder_clearance=1.0)
    drop = AssemblyDrop(step_mesh, tool)
    rng = np.random.default_rng(2)
    xy = rng.uniform(2, 38, size=(300, 2))
    z, owner = drop.heights(xy, floor_z=-40.0)
    starts = np.column_stack([xy, np.full(len(xy), 60.0)])
    travel, owner_along = drop.along(starts, [0, 0, 1], [0, 0, -1], max_travel=100.0)
    np.testing.assert_array_equal(travel, 60.0 - z)
    np.testing.assert_array_equal(owner_along, owner)
    axis = np.array([0.5, 0.0, 1.0]) / np.hypot(0.5, 1.0)
    direction = np.array([0.2, 0.1, -1.0]) / np.linalg.norm([0.2, 0.1, -1.0])
    travel, owner = drop.along(starts, axis, direction)
    index = native.DirectionalIndex(step_mesh.vertices, step_mesh.triangles, direction)
    expect = native.drop_assembly_along(index, tool.cutter.native, np.array(tool.bodies()), starts, axis,
                                        np.inf, tool.cutter_clearance)
    np.testing.assert_array_equal(travel, expect[0])
    np.testing.assert_array_equal(owner, expect[1])
    hit = np.isfinite(travel)
    assert hit.sum() > 250 and set(drop.piece_names(owner[hit])) <= {"cutter", "shank", "holder"}
    assert np.all(owner[~hit] == -2)
    with pytest.raises(TmmError, match="unit vector"):
        drop.along(starts, [0, 0, 2], direction)
    with pytest.raises(TmmError, match="shape"):
        drop.along(xy, axis, direction)


def test_threads_agree_and_cancel(step_mesh):
    index = native.DirectionalIndex(step_mesh.vertices, step_mesh.triangles, [0.0, 0.6, -0.8])
    rng = np.random.default_rng(4)
    starts = np.column_stack([rng.uniform(0, 40, (400, 2)), np.full(400, 20.0)])
    axis = np.array([0.0, -0.28, 0.96])
    cutter = native.Cutter(BALL, BALL)
    one = native.drop_assembly_along(index, cutter, BODIES, starts, axis, threads=1)
    two = native.drop_assembly_along(index, cutter, BODIES, starts, axis, threads=2)
    np.testing.assert_array_equal(one[0], two[0])
    np.testing.assert_array_equal(one[1], two[1])
    with pytest.raises(native.Cancelled):
        native.drop_assembly_along(index, cutter, BODIES, starts, axis, progress=lambda f: False)
    with pytest.raises(ValueError, match="finite cutting length or a body above it"):
        native.drop_assembly_along(index, cutter, np.zeros((0, 5)), starts, axis)
