"""The tool assembly's drop (native.drop_assembly: cutter + shank/neck + holder, each kept its clearance away
from the mesh) through the binding, against a numpy brute force that knows nothing of the kernel's pieces:
the mesh sampled densely (vertices, edges, interiors), each sample at distance d from the tool axis holding the
tool's tip at least sample.z - lowest(d) high, lowest(d) the lowest point at d of the body grown by its
clearance (closed form: the lowest of the capsules around its meridian trapezoid's edges). The drop must clear
every sample (no gouge) and rest on one (touch, to the sampling's resolution)."""
from __future__ import annotations

import numpy as np
import pytest

from tests.conftest import SHARED_STL, grid_mesh
from tmm_workbench.core.geometry.mesh import load_stl
from tmm_workbench.core.kernel import native


def capsule_lowest(ax, az, bx, bz, c, d):
    """Lowest point at abscissa d (array) of the meridian segment (ax, az)-(bx, bz) grown by c; inf where the
    capsule does not reach d."""
    low = np.full(d.shape, np.inf)
    for px, pz in ((ax, az), (bx, bz)):
        u = d - px
        low = np.where(np.abs(u) <= c, np.minimum(low, pz - np.sqrt(np.maximum(c * c - u * u, 0.0))), low)
    tx, tz = bx - ax, bz - az
    length = np.hypot(tx, tz)
    if length == 0.0 or tx == 0.0:  # a point, or a vertical edge: its ends' discs are its lowest points
        return low
    nx, nz = tz / length, -tx / length
    if nz > 0:
        nx, nz = -nx, -nz
    px, pz, qx, qz = ax + c * nx, az + c * nz, bx + c * nx, bz + c * nz
    on = (d >= min(px, qx)) & (d <= max(px, qx))
    return np.where(on, np.minimum(low, pz + (d - px) / (qx - px) * (qz - pz)), low)


def body_lowest(body, d):
    """Lowest height above the tip of the frustum (z0, z1, r0, r1, c) grown by c at distance d from the axis."""
    z0, z1, r0, r1, c = body
    corners = [(-r0, z0), (r0, z0), (r1, z1), (-r1, z1)]
    return np.min([capsule_lowest(*corners[k], *corners[(k + 1) % 4], c, d) for k in range(4)], axis=0)


def ball_lowest(radius, d):
    return np.where(d <= radius, radius - np.sqrt(np.maximum(radius * radius - d * d, 0.0)), np.inf)


def mesh_samples(vertices, triangles, spacing):
    """Points of every triangle on a barycentric lattice no coarser than `spacing` along its longest edge
    (corners and edges included)."""
    tri = vertices[triangles]
    longest = np.max(np.linalg.norm(tri - np.roll(tri, 1, axis=1), axis=2), axis=1)
    steps = np.maximum(np.ceil(longest / spacing), 1).astype(int)
    out = []
    for k in np.unique(steps):
        lattice = np.array([(i, j) for i in range(k + 1) for j in range(k + 1 - i)], dtype=float) / k
        w = np.column_stack([1.0 - lattice.sum(1), lattice])
        out.append(np.einsum("sk,tkd->tsd", w, tri[steps == k]).reshape(-1, 3))
    return np.concatenate(out)


def reference(samples, xy, ball_radius, bodies, z, tol):
    """Per point: the highest tip any sample allows for each piece ((n, 1 + k): the ball, then the bodies), -inf
    where none comes within 10 tol of the drop z: a sample below z + lowest(0) - 10 tol can neither be gouged
    by the piece nor hold it that close to z (lowest(d) >= lowest(0)), so only the samples above count."""
    pieces = [(ball_radius, 0.0, lambda d: ball_lowest(ball_radius, d))]
    pieces += [(max(b[2], b[3]) + b[4], b[0] - b[4], lambda d, b=b: body_lowest(b, d)) for b in bodies]
    out = np.full((len(xy), len(pieces)), -np.inf)
    for i, (x, y) in enumerate(xy):
        for k, (reach, bottom, lowest) in enumerate(pieces):
            near = samples[(np.abs(samples[:, 0] - x) <= reach) & (np.abs(samples[:, 1] - y) <= reach) &
                           (samples[:, 2] >= z[i] + bottom - 10 * tol - 1e-6)]
            if len(near):
                out[i, k] = np.max(near[:, 2] - lowest(np.hypot(near[:, 0] - x, near[:, 1] - y)))
    return out


def check_drop(vertices, triangles, xy, ball_radius, bodies, spacing, touch_tol):
    index = native.MeshIndex(vertices, triangles)
    floor = float(vertices[:, 2].min()) - 50.0
    z, set_by = native.drop_assembly(index, native.Cutter(ball_radius, ball_radius), np.asarray(bodies, float),
                                     xy, floor)
    # Only triangles near the points and high enough to hold a piece near the lowest drop need samples.
    reach = max([ball_radius] + [max(b[2], b[3]) + b[4] for b in bodies])
    lowest = min([0.0] + [b[0] - b[4] for b in bodies])
    tri = vertices[triangles]
    near = ((tri[:, :, 0].max(1) >= xy[:, 0].min() - reach) & (tri[:, :, 0].min(1) <= xy[:, 0].max() + reach) &
            (tri[:, :, 1].max(1) >= xy[:, 1].min() - reach) & (tri[:, :, 1].min(1) <= xy[:, 1].max() + reach) &
            (tri[:, :, 2].max(1) >= z.min() + lowest - 1.0))
    ref = reference(mesh_samples(vertices, triangles[near], spacing), xy, ball_radius, bodies, z, touch_tol)
    best = np.maximum(ref.max(axis=1), floor)
    assert np.all(z >= best - 1e-9), "the assembly comes closer to the mesh than its clearance"
    assert np.all(z - best <= touch_tol), f"not resting on the mesh: {np.max(z - best)}"
    # Who set it, where the reference's winner is clear.
    winner = np.where(ref.max(axis=1) > floor, np.argmax(ref, axis=1) - 1, -2)
    second = np.sort(ref, axis=1)[:, -2]
    clear = (best - second > 10 * touch_tol) & (best > floor)
    np.testing.assert_array_equal(set_by[clear], winner[clear])
    return z, set_by


@pytest.mark.skipif(not (SHARED_STL / "mount_rush.stl").exists(), reason="shared STL files absent")
def test_real_stl_against_brute_force():
    """mount_rush (a relief 27 mm deep): a ball d6 on a 12 mm stick-out, a shank with a clearance, a neck cone
    and a holder; points over the whole part, many lifted by the bodies."""
    mesh = load_stl(SHARED_STL / "mount_rush.stl")
    rng = np.random.default_rng(3)
    xy = rng.uniform([-12.0, 4.0], [28.0, 18.0], size=(60, 2))  # over the faces, where the relief is deepest
    bodies = [[8.0, 12.0, 3.0, 3.0, 0.5], [12.0, 16.0, 3.0, 9.0, 1.0], [16.0, 80.0, 16.0, 16.0, 2.0]]
    z, set_by = check_drop(mesh.vertices, mesh.triangles, xy, 3.0, bodies, spacing=0.1, touch_tol=0.03)
    assert np.sum(set_by >= 0) >= 10, "the bodies should set many heights here"


def test_deep_cavity_the_holder_sets_the_height():
    """A pocket 12 x 12 mm and 30 deep in a plate: the ball on a 10 mm stick-out cannot reach its floor, the
    holder (radius 12, clearance 2, from 15 above the tip) rests on the plate: tip = 30 - (15 - 2) = 17."""
    mesh = grid_mesh(lambda x, y: np.where((np.abs(x) < 6.01) & (np.abs(y) < 6.01), 0.0, 30.0), 60, 60,
                     (-30, -30, 30, 30), "pocket")
    bodies = [[10.0, 15.0, 3.0, 3.0, 0.5], [15.0, 60.0, 12.0, 12.0, 2.0]]
    index = native.MeshIndex(mesh.vertices, mesh.triangles)
    cutter = native.Cutter(3.0, 3.0)
    z, set_by = native.drop_assembly(index, cutter, np.array(bodies), np.array([[0.0, 0.0], [1.5, -2.0]]), -10.0)
    np.testing.assert_allclose(z, 17.0, atol=1e-12)
    np.testing.assert_array_equal(set_by, [1, 1])
    assert native.drop_cutter(index, cutter, np.array([[0.0, 0.0]]), -10.0)[0] == pytest.approx(0.0, abs=1e-12)
    g = np.linspace(-12, 12, 9)
    xy = np.stack(np.meshgrid(g, g), -1).reshape(-1, 2)
    z, set_by = check_drop(mesh.vertices, mesh.triangles, xy, 3.0, bodies, spacing=0.2, touch_tol=0.01)
    assert np.sum(set_by == 1) >= 9


def test_no_bodies_is_drop_cutter_exactly(wavy_mesh):
    index = native.MeshIndex(wavy_mesh.vertices, wavy_mesh.triangles)
    g = np.linspace(-3, 43, 120)
    xy = np.stack(np.meshgrid(g, g[:80]), -1).reshape(-1, 2)
    for cutter in (native.Cutter(3.0, 3.0), native.Cutter(4.0, 0.0), native.Cutter.apt(4.0, 1.0, 10.0, 0.0, 0.1)):
        z0 = native.drop_cutter(index, cutter, xy, -20.0)
        for empty in (np.zeros((0, 5)), []):
            z, set_by = native.drop_assembly(index, cutter, empty, xy, -20.0)
            np.testing.assert_array_equal(z, z0)
            np.testing.assert_array_equal(set_by, np.where(z0 > -20.0, -1, -2))
            assert z.dtype == np.float64 and set_by.dtype == np.int32 and z.shape == set_by.shape == (len(xy),)


def test_threads_agree_and_cancel(wavy_mesh):
    index = native.MeshIndex(wavy_mesh.vertices, wavy_mesh.triangles)
    rng = np.random.default_rng(5)
    xy = rng.uniform([0, 0], [40, 30], size=(20000, 2))
    bodies = np.array([[2.0, 4.0, 2.0, 2.0, 0.5], [4.0, 40.0, 8.0, 8.0, 1.0]])
    cutter = native.Cutter(2.0, 2.0)
    one = native.drop_assembly(index, cutter, bodies, xy, -20.0, threads=1)
    two = native.drop_assembly(index, cutter, bodies, xy, -20.0, threads=2)
    np.testing.assert_array_equal(one[0], two[0])
    np.testing.assert_array_equal(one[1], two[1])
    assert np.sum(one[1] >= 0) > 100
    fractions = []
    native.drop_assembly(index, cutter, bodies, xy, -20.0, progress=lambda f: fractions.append(f) or True)
    assert fractions and fractions[-1] == pytest.approx(1.0) and fractions == sorted(fractions)
    with pytest.raises(native.Cancelled):
        native.drop_assembly(index, cutter, bodies, xy, -20.0, progress=lambda f: False)


@pytest.mark.parametrize("bodies, words", [
    ([[5, 5, 1, 1, 0]], "tool body 0 (z0 5, z1 5, r0 1, r1 1, clearance 0): z1 must be above z0"),
    ([[2, 5, -1, 1, 0]], "radii must be >= 0"),
    ([[2, 5, 1, 1, -0.5]], "clearance must be >= 0"),
    ([[2, np.nan, 1, 1, 0]], "outside the kernel's range"),
    ([[2, 6, 1, 1, 0], [5, 9, 3, 3, 0]], "tool body 1"),
    ([[2, 6, 1, 1, 0], [5, 9, 3, 3, 0]], "z ranges not overlapping"),
    ([[-1, 5, 1, 1, 0]], "z0 must be >= 0"),
    ([[2, 5, 0, 0, 0]], "positive radius or a positive clearance"),
    ([[2, 5, 1, 1]], "bodies must have shape (k, 5)"),
])
def test_bad_bodies_are_refused_by_name(wavy_mesh, bodies, words):
    index = native.MeshIndex(wavy_mesh.vertices, wavy_mesh.triangles)
    with pytest.raises(ValueError) as err:
        native.drop_assembly(index, native.Cutter(2.0, 2.0), np.array(bodies, float), np.zeros((3, 2)), 0.0)
    assert words in str(err.value)


def test_bad_clearance_and_points_are_refused(wavy_mesh):
    index = native.MeshIndex(wavy_mesh.vertices, wavy_mesh.triangles)
    none = np.zeros((0, 5))
    with pytest.raises(ValueError, match="cutter clearance must be >= 0"):
        native.drop_assembly(index, native.Cutter(2.0, 2.0), none, np.zeros((3, 2)), 0.0, cutter_clearance=-1.0)
    with pytest.raises(ValueError, match="flat-bottomed cutter"):
        native.drop_assembly(index, native.Cutter.apt(3.0, 0.0, 10.0, 0.5, 0.0), none, np.zeros((3, 2)), 0.0,
                             cutter_clearance=0.5)
    with pytest.raises(ValueError, match="points"):
        native.drop_assembly(index, native.Cutter(2.0, 2.0), none, np.array([[0.0, np.nan]]), 0.0)
    with pytest.raises(ValueError, match=r"shape \(n, 2\)"):
        native.drop_assembly(index, native.Cutter(2.0, 2.0), none, np.zeros((3, 3)), 0.0)
