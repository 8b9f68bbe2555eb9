"""The C-space at CC points (core.strategies.mesh5): the lift against a brute-force reference, the seed's five
contact cases on constructed meshes, the top bound against the seed's eq. 3.84 and the empty C-space."""
from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.optimize import minimize

from tests.conftest import grid_mesh
from tmm_workbench.core.errors import TmmError
from tmm_workbench.core.geometry.mesh import TriMesh
from tmm_workbench.core.strategies.mesh5.cc_paths import cc_paths
from tmm_workbench.core.strategies.mesh5.cspace import build_cspace
from tmm_workbench.core.strategies.mesh5.lift import MeshReach, lifts
from tmm_workbench.core.strategies.mesh5.posture import PostureGrid
from tmm_workbench.core.tools.cutter import Cutter

R = 5.0
POSTURES = [(0, 0), (9, 0), (21, 15), (33, -30), (45, 42)]
ORIGIN, IDENTITY = np.zeros((1, 3)), np.eye(3)[None]


def seed_rotation(lam_deg: float, omg_deg: float) -> np.ndarray:
    """Eq. 3.8 written out: rows TX, TY, TZ in LCS coordinates."""
    cl, sl = math.cos(math.radians(lam_deg)), math.sin(math.radians(lam_deg))
    cw, sw = math.cos(math.radians(omg_deg)), math.sin(math.radians(omg_deg))
    return np.array([[cl * cw, cl * sw, -sl], [-sw, cw, 0.0], [sl * cw, sl * sw, cl]])


def lower_profile(cutter: Cutter, rho: np.ndarray) -> np.ndarray:
    """Height of the lower surface above the tip at radius rho (inf outside the cutter)."""
    r, rp = cutter.corner_radius, cutter.radius - cutter.corner_radius
    d = np.clip(rho - rp, 0.0, None)
    with np.errstate(invalid="ignore"):
        h = np.where(d > 0, r - np.sqrt(np.maximum(r * r - d * d, 0.0)), 0.0)
    return np.where(rho <= cutter.radius + 1e-12, h, np.inf)


def tool_samples(cutter: Cutter, n_rho: int = 40, n_phi: int = 720) -> np.ndarray:
    """Points of the lower surface in the tool frame, the outer circle included."""
    rho = cutter.radius * np.sqrt(np.linspace(0, 1, n_rho))
    phi = np.linspace(0, 2 * math.pi, n_phi, endpoint=False)
    P, F = np.meshgrid(rho, phi, indexing="ij")
    return np.column_stack([(P * np.cos(F)).ravel(), (P * np.sin(F)).ravel(), lower_profile(cutter, P.ravel())])


def mesh_samples(corners: np.ndarray, k: int) -> np.ndarray:
    """Barycentric grid of k + 1 points a side on each triangle (vertices and edges included)."""
    i, j = np.meshgrid(np.arange(k + 1), np.arange(k + 1), indexing="ij")
    ok = i + j <= k
    u, v = i[ok] / k, j[ok] / k
    w = 1 - u - v
    return (corners[:, None, 0] * w[:, None] + corners[:, None, 1] * u[:, None]
            + corners[:, None, 2] * v[:, None]).reshape(-1, 3)


def ray_heights(origins: np.ndarray, corners: np.ndarray) -> np.ndarray:
    """Highest z of the triangles above each origin's (x, y) (-inf where none), brute force."""
    a, b, c = corners[:, 0], corners[:, 1], corners[:, 2]
    det = (b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (c[:, 0] - a[:, 0]) * (b[:, 1] - a[:, 1])
    out = np.full(len(origins), -np.inf)
    for s in range(0, len(origins), 2000):
        o = origins[s:s + 2000]
        px, py = o[:, None, 0] - a[None, :, 0], o[:, None, 1] - a[None, :, 1]
        with np.errstate(divide="ignore", invalid="ignore"):
            u = (px * (c[:, 1] - a[:, 1]) - (c[:, 0] - a[:, 0]) * py) / det
            v = ((b[:, 0] - a[:, 0]) * py - px * (b[:, 1] - a[:, 1])) / det
        z = a[:, 2] + u * (b[:, 2] - a[:, 2]) + v * (c[:, 2] - a[:, 2])
        z = np.where((u >= 0) & (v >= 0) & (u + v <= 1), z, -np.inf)
        out[s:s + 2000] = z.max(axis=1)
    return out


def reference_lift(mesh: TriMesh, cutter: Cutter, point: np.ndarray, frame: np.ndarray, lam: float,
                   omg: float) -> float:
    """The least lift along the axis without penetration, brute force: the tool placed with its lowest
    point (along -LZ) at the CC point, found among dense samples; penetration measured both ways (mesh
    samples under the tool's lower surface, tool samples under the mesh along the axis)."""
    rot = seed_rotation(lam, omg)
    tool = tool_samples(cutter)
    lz = tool @ rot[:, 2]                                           # LZ of each sample, tip at the origin
    best = tool[int(np.argmin(lz))]
    x0 = [math.hypot(best[0], best[1]), math.atan2(best[1], best[0])]

    def on_tool(x):
        return np.array([x[0] * math.cos(x[1]), x[0] * math.sin(x[1]), lower_profile(cutter, np.array(x[0]))])

    res = minimize(lambda x: on_tool(x) @ rot[:, 2], x0, bounds=[(0, cutter.radius), (x0[1] - 0.1, x0[1] + 0.1)],
                   method="L-BFGS-B", options={"ftol": 1e-15, "gtol": 1e-12})
    tip = -(rot.T @ on_tool(res.x))                                    # the lowest point at the CC point
    corners = (mesh.vertices[mesh.triangles] - point) @ frame.T      # LCS
    near = np.linalg.norm(corners.mean(axis=1), axis=1) < 3 * cutter.radius
    q = (corners[near] - tip) @ rot.T                                # tool frame, tip at the origin
    c = q.mean(axis=1)
    reach = cutter.radius + np.linalg.norm(q - c[:, None], axis=2).max(axis=1)
    q = q[np.hypot(c[:, 0], c[:, 1]) <= reach]                       # only what the footprint can meet
    pts = mesh_samples(q, 24)
    under = pts[:, 2] - lower_profile(cutter, np.hypot(pts[:, 0], pts[:, 1]))
    above = ray_heights(tool, q) - tool[:, 2]
    return max(0.0, float(under.max()), float(above.max()))


def kernel_lift(mesh, cutter, point, frame, lam, omg, limit=20.0) -> float:
    out = lifts(MeshReach(mesh), cutter, np.asarray(point)[None], np.asarray(frame)[None],
                np.radians([lam]), np.radians([omg]), limit)
    return float(out[0, 0])


def sphere_cap() -> TriMesh:
    return grid_mesh(lambda x, y: np.sqrt(40.0 ** 2 - x * x - y * y), 48, 48, (-12, -12, 12, 12), "convex")


def trough() -> TriMesh:
    return grid_mesh(lambda x, y: 30.0 - np.sqrt(30.0 ** 2 - y * y), 24, 60, (-12, -12, 12, 12), "concave")


@pytest.mark.parametrize("cutter", [Cutter.flat(2 * R), Cutter.bull(2 * R, 2.0)], ids=["flat", "bull"])
@pytest.mark.parametrize("shape", ["convex", "concave"])
def test_lift_against_the_brute_force_reference(shape, cutter):
    if shape == "convex":
        mesh = sphere_cap()
        path = cc_paths(mesh, (1, 0), np.array([-3.0]), 1.0, 0.005)[0]
        i = int(np.argmin(np.abs(path.points[:, 0] + 4.0)))           # a tilted normal (about 7 deg)
        point, frame = path.points[i], path.frames[i]
    else:
        mesh = trough()
        point, frame = np.array([0.0, 0.0, 0.0]), np.eye(3)
    got = [kernel_lift(mesh, cutter, point, frame, lam, omg) for lam, omg in POSTURES]
    ref = [reference_lift(mesh, cutter, point, frame, lam, omg) for lam, omg in POSTURES]
    for (lam, omg), g, r in zip(POSTURES, got, ref):
        assert g >= r - 1e-6, (lam, omg, g, r)                      # every sample is a witness: never lower
        assert g - r <= 3e-4, (lam, omg, g, r)
    if shape == "concave":                                           # the heel gouges the rising wall
        assert max(got) > 0.1


# --- the seed's five contact cases (section 3.5.5.1, Figure 3-27), flat end mill, built in the seed's tool
# frame T: origin at the CC point (the rim point), cutter centre at (-R, 0, 0), axis TZ; LCS = rot^T T at
# delta = 0 (eq. 3.9). The CC point's own facet is left out: only the obstacle can lift the tool.

FLAT = Cutter.flat(2 * R)


def seed_mesh(lam: float, omg: float, tris_T: np.ndarray) -> TriMesh:
    """Triangles given in the seed's T frame, as a mesh in LCS coordinates (= world here)."""
    rot = seed_rotation(lam, omg)
    return TriMesh((np.asarray(tris_T, dtype=float) @ rot).reshape(-1, 3),
                   np.arange(3 * len(tris_T)).reshape(-1, 3), "obstacle")


def flat_lift(mesh: TriMesh, lam: float, omg: float) -> float:
    return kernel_lift(mesh, FLAT, np.zeros(3), np.eye(3), lam, omg)


def in_T(lam: float, omg: float, p_lcs: np.ndarray) -> np.ndarray:
    return seed_rotation(lam, omg) @ p_lcs


def test_vtcbt_vertex_on_the_bottom():
    lam, omg = 18.0, -12.0
    apex = np.array([-0.6 * R, 0.5 * R, 1.3])                         # inside the footprint (eq. 3.88)
    needle = [[apex, apex + [0.02, 0, -2.5], apex + [-0.02, 0.01, -2.5]]]
    mesh = seed_mesh(lam, omg, needle)
    P = (np.array(needle[0][0]) @ seed_rotation(lam, omg))           # the vertex in LCS
    cl, sl = math.cos(math.radians(lam)), math.sin(math.radians(lam))
    cw, sw = math.cos(math.radians(omg)), math.sin(math.radians(omg))
    delta = sl * cw * P[0] + sl * sw * P[1] + cl * P[2]                # eq. 3.87
    assert (cl * cw * P[0] + cl * sw * P[1] - sl * P[2] + R) ** 2 + (-sw * P[0] + cw * P[1]) ** 2 < R * R
    assert flat_lift(mesh, lam, omg) == pytest.approx(delta, abs=1e-9)
    assert delta == pytest.approx(1.3, abs=1e-12)


def _crossing(f) -> float:
    """The first omega in -80..80 deg where f changes sign."""
    from scipy.optimize import brentq
    w = np.linspace(-80.0, 80.0, 161)
    v = np.array([f(x) for x in w])
    k = int(np.flatnonzero(np.sign(v[:-1]) != np.sign(v[1:]))[0])
    return brentq(f, w[k], w[k + 1], xtol=1e-13)


def test_vtcbd_vertex_on_the_side_is_the_shell_of_the_bottom_case():
    """A vertex high above the bottom: lifted by eq. 3.87 while it lies inside the cutter's radius, not at
    all outside; the switch is where it touches the side (eq. 3.90, |T P - T C| = R), solved here for omega."""
    lam = 15.0
    P = np.array([-2.0, 6.2, 2.0])                                    # LCS, fixed
    speck = [[P, P + [1e-4, 0, 0], P + [0, 1e-4, 0]]]
    mesh = TriMesh(np.asarray(speck, float).reshape(-1, 3), np.arange(3).reshape(1, 3), "vertex")

    def radial(omg):
        t = in_T(lam, omg, P)
        return math.hypot(t[0] + R, t[1]) - R

    shell = _crossing(radial)                                         # omega where the vertex is on the side
    zT = in_T(lam, shell, P)[2]
    assert 0 < zT < 2 * 2 * R                                         # eq. 3.89: on the body, above the bottom
    side = 1 if radial(shell + 1) > 0 else -1
    inside, outside = shell - 0.05 * side, shell + 0.05 * side
    expected = max(in_T(lam, inside, c)[2] for c in speck[0])          # the speck's highest corner
    assert flat_lift(mesh, lam, inside) == pytest.approx(expected, abs=1e-9)
    assert flat_lift(mesh, lam, outside) == 0.0


def test_etcbt_edge_on_the_bottom_rim():
    """An edge rising out of the footprint: the lift puts its crossing with the bottom plane on the rim
    (eq. 3.99-3.102: t from TZ = delta, then |T(t) - T C| = R)."""
    lam, omg = 24.0, 9.0
    A = np.array([-0.5 * R, 0.2 * R, -1.0])                           # below the bottom, inside
    B = np.array([0.8 * R, 0.9 * R, 2.5])                             # above, outside
    fin = [[A, B, A + [0, 0, -2.0]]]
    e = B - A
    # |(A + t e)_xy - C_xy| = R, C = (-R, 0): a quadratic in t; its root in (0, 1) gives delta = TZ there
    d = A[:2] - [-R, 0.0]
    qa, qb, qc = e[:2] @ e[:2], 2 * d @ e[:2], d @ d - R * R
    t = (-qb + math.sqrt(qb * qb - 4 * qa * qc)) / (2 * qa)
    assert 0 < t < 1
    assert flat_lift(seed_mesh(lam, omg, fin), lam, omg) == pytest.approx(A[2] + t * e[2], abs=1e-8)


def test_etcbd_edge_tangent_to_the_side_is_the_shell():
    """An edge high above the bottom, across the cutter: lifted while its shadow crosses the cutter's circle,
    not at all once it passes by; the switch is where it is tangent to the side (eq. 3.104-3.109)."""
    lam = 12.0
    A, B = np.array([-12.0, 7.0, 3.0]), np.array([12.0, 7.5, 3.4])   # LCS, fixed
    fin = TriMesh(np.array([A, B, (A + B) / 2 + [0, 0, -1e-6]]), np.arange(3).reshape(1, 3), "edge")  # a sliver: its edge AB

    def gap(omg):                                                     # edge's distance to the axis - R (in T)
        a, b = in_T(lam, omg, A), in_T(lam, omg, B)
        c = np.array([-R, 0.0])
        u = (b - a)[:2]
        s = np.clip((c - a[:2]) @ u / (u @ u), 0, 1)
        return float(np.linalg.norm(a[:2] + s * u - c)) - R

    shell = _crossing(gap)
    side = 1 if gap(shell + 1) > 0 else -1
    outside = shell + 0.05 * side
    a, b = in_T(lam, shell, A), in_T(lam, shell, B)
    u = (b - a)[:2]
    s = float(np.clip((np.array([-R, 0.0]) - a[:2]) @ u / (u @ u), 0, 1))
    touch = a[2] + s * (b - a)[2]                                     # TZ of the tangent point
    assert 0 < touch

    def chord_top(omg):                                               # highest TZ of the edge inside the side
        a, b = in_T(lam, omg, A), in_T(lam, omg, B)
        e, dd = (b - a)[:2], a[:2] - [-R, 0.0]
        qa, qb, qc = e @ e, 2 * dd @ e, dd @ dd - R * R
        root = math.sqrt(qb * qb - 4 * qa * qc)
        return max(a[2] + t * (b - a)[2] for t in ((-qb - root) / (2 * qa), (-qb + root) / (2 * qa)))

    for off in (0.5, 0.05, 0.002):                                    # converging on the tangent contact
        got = flat_lift(fin, lam, shell - off * side)
        assert got == pytest.approx(chord_top(shell - off * side), abs=1e-5)   # the sliver: 1e-6 wide
    assert got == pytest.approx(touch, abs=0.01)
    assert flat_lift(fin, lam, outside) == 0.0


def test_ttcbt_facet_on_the_bottom_rim():
    """A facet plane under the whole footprint: the rim touches it where the plane is highest (eq. 3.118):
    delta = plane height at the centre + R |gradient|."""
    lam, omg = 30.0, -21.0
    g, z0 = np.array([0.35, -0.2]), 0.8                              # TZ = z0 + g . (T x, T y) over the plane
    corners = np.array([[-40.0, -30.0], [40.0, -30.0], [0.0, 40.0]])
    facet = [np.column_stack([corners, z0 + corners @ g])]
    delta = z0 + g @ [-R, 0.0] + R * float(np.linalg.norm(g))
    assert flat_lift(seed_mesh(lam, omg, facet), lam, omg) == pytest.approx(delta, abs=1e-9)


# --- the top bound (eq. 3.82-3.84) and the C-space

def test_top_bound_on_a_plane_is_the_seeds_eq_3_84():
    """On a plane the surface's section is flat (Z_P(d) = 0): for omega = 0 the rim point at LY = d has
    cos(alpha) = d / R (eq. 3.25) and delta_1 = (tau + sin(lambda) (-R + R sin(alpha))) / cos(lambda)."""
    mesh = grid_mesh(lambda x, y: 0.3 * x - 0.1 * y, 20, 20, (-20, -20, 20, 20), "plane")
    path = cc_paths(mesh, (1, 0), np.array([1.0]), 5.0, 0.01)[0]
    grid = PostureGrid.degrees((0, 45), (0, 0))
    tau, d = 0.05, 2.5
    cs = build_cspace(mesh, FLAT, path.points[2:3], path.frames[2:3], grid, tau, d)
    lam = grid.lambdas
    alpha = np.arccos(d / R)
    seed = (tau + np.sin(lam) * (-R + R * np.sin(alpha))) / np.cos(lam)
    assert np.abs(cs.top[0, :, 0] - np.minimum(seed, tau / np.cos(lam))).max() < 1e-5
    assert np.all(cs.lift[0][cs.top[0] >= 0] < 1e-9)                  # a plane: nothing to clear
    assert cs.available[0, :, 0].tolist() == (seed >= 0).tolist()


def test_top_bound_leaves_the_tolerance_at_the_side_step():
    """On a convex cylinder, for yawed postures too: with the tool lifted by delta_1, the remaining height of
    the swept rim (brute force) at one side step is the tolerance and at the other at most that."""
    rc, tau, d = 30.0, 0.04, 2.0
    mesh = grid_mesh(lambda x, y: np.sqrt(rc * rc - y * y) - rc, 40, 160, (-20, -16, 20, 16), "convex")
    grid = PostureGrid(np.radians([6.0, 15.0]), np.radians([-20.0, 10.0]))
    cs = build_cspace(mesh, FLAT, ORIGIN, IDENTITY, grid, tau, d, all_lifts=True)
    phi = np.linspace(0, 2 * math.pi, 200001)
    for i, lam in enumerate((6.0, 15.0)):
        for j, omg in enumerate((-20.0, 10.0)):
            d1 = cs.top[0, i, j]
            rot = seed_rotation(lam, omg)
            rim_T = np.column_stack([-R + R * np.cos(phi), R * np.sin(phi), np.zeros_like(phi)])
            rim = (rim_T + [0, 0, d1]) @ rot                          # eq. 3.9 with the lift
            left = []
            for y in (d, -d):
                near = np.abs(rim[:, 1] - y) < 2e-4
                surface = math.sqrt(rc * rc - y * y) - rc
                left.append(rim[near, 2].min() - surface)
            assert max(left) == pytest.approx(tau, abs=2e-4), (lam, omg, left)


def test_groove_too_narrow_for_the_cutter_leaves_an_empty_cspace():
    def height(x, y):
        return np.where(np.abs(y) < 2.0, -3.0 * (1 - (y / 2.0) ** 2), 0.0)

    mesh = grid_mesh(height, 30, 240, (-15, -15, 15, 15), "groove")
    paths = cc_paths(mesh, (1, 0), np.array([0.0, 10.0]), 3.0, 0.01)
    bottom, shoulder = paths[0], paths[1]
    pts = np.vstack([bottom.points[4:6], shoulder.points[4:6]])
    frames = np.vstack([bottom.frames[4:6], shoulder.frames[4:6]])
    cs = build_cspace(mesh, FLAT, pts, frames, PostureGrid.degrees(step=9.0), 0.05, 1.5)
    assert cs.empty.tolist() == [True, True, False, False]
    assert np.nanmin(cs.lift[:2]) > 1.0 or not np.isfinite(cs.lift[:2]).any()
    assert "2 of 4 CC points have an empty C-space" in cs.report()


def test_bad_input_is_refused_by_name():
    mesh = trough()
    grid = PostureGrid.degrees(step=15.0)
    with pytest.raises(TmmError, match="tolerance"):
        build_cspace(mesh, FLAT, ORIGIN, IDENTITY, grid, 0.0, 1.0)
    with pytest.raises(TmmError, match="side step"):
        build_cspace(mesh, FLAT, ORIGIN, IDENTITY, grid, 0.05, 3 * R)
    with pytest.raises(TmmError, match="C-space method takes"):
        build_cspace(mesh, Cutter.vbit(6, 90), ORIGIN, IDENTITY, grid, 0.05, 1.0)
    with pytest.raises(TmmError, match="inclination"):
        PostureGrid.degrees((0, 95))


def test_batched_lifts_equal_one_posture_at_a_time():
    """The atlas lays many (CC point, posture) copies side by side: no copy may touch another's triangles."""
    mesh = trough()
    reach = MeshReach(mesh)
    path = cc_paths(mesh, (1, 0), np.array([2.0]), 3.0, 0.01)[0]
    pts, frames = path.points[2:4], path.frames[2:4]
    lam, omg = (np.radians(g.ravel()) for g in np.meshgrid([0.0, 6.0, 20.0, 40.0], [-40.0, -5.0, 0.0, 30.0],
                                                            indexing="ij"))
    batch = lifts(reach, FLAT, pts, frames, lam, omg, 20.0)
    single = np.array([[lifts(reach, FLAT, pts[i:i + 1], frames[i:i + 1], lam[p:p + 1], omg[p:p + 1], 20.0)[0, 0]
                        for p in range(len(lam))] for i in range(len(pts))])
    assert np.abs(batch - single).max() < 1e-12
    assert batch.max() > 0.1                                          # the heel at lambda = 0 is lifted


def test_world_placement_touches_the_cc_point_and_clears_the_mesh():
    """A C-space set turned into a CL point (eq. 3.6-3.9): the axis is lambda from the normal, and the tool
    placed there with the lift S2 touches the mesh without gouging (the kernel's drop along the axis from that
    tip travels nothing)."""
    from tmm_workbench.core.query.drop_direction import drop_along
    from tmm_workbench.core.strategies.mesh5.posture import world_placement

    mesh = trough()
    path = cc_paths(mesh, (1, 0), np.array([3.0]), 3.0, 0.01)[0]
    cutter = Cutter.bull(2 * R, 1.5)
    grid = PostureGrid(np.radians([0.0, 12.0, 30.0]), np.radians([-30.0, 0.0, 25.0]))
    cs = build_cspace(mesh, cutter, path.points[3:4], path.frames[3:4], grid, 0.05, 1.0, all_lifts=True)
    L, W = grid.mesh()
    for i, j in [(0, 1), (1, 0), (2, 2)]:
        tip, axis = world_placement(cutter, path.points[3], path.frames[3], L[i, j], W[i, j], cs.lift[0, i, j])
        angle = math.degrees(math.acos(float(axis[0] @ path.normals[3])))
        assert angle == pytest.approx(math.degrees(L[i, j]), abs=1e-9)
        long = Cutter(cutter.diameter, cutter.corner_radius, cutting_length=4 * R)
        travel, _ = drop_along(mesh, long, tip + 5.0 * axis, axis[0], -axis[0])
        assert travel[0] == pytest.approx(5.0, abs=1e-6)               # it comes down exactly to the CL point


def test_the_holder_bounds_the_lift_as_the_kernels_assembly_drop_along_the_axis():
    """With a ToolAssembly the shank and holder keep their clearances: a wall the cutter never reaches lifts
    the tool when the holder comes over it; each lift equals the kernel's assembly drop along the axis
    (AssemblyDrop.along, another code path) from high above that CL point."""
    from tmm_workbench.core.query.drop_assembly import AssemblyDrop
    from tmm_workbench.core.strategies.mesh5.posture import world_placement
    from tmm_workbench.core.tools.assembly import ToolAssembly

    mesh = grid_mesh(lambda x, y: np.where(y > 9.0, 30.0, 0.0), 60, 120, (-30, -30, 30, 30), "wall")
    tool = ToolAssembly(FLAT, shank_diameter=10.0, stick_out=25.0, flute_length=15.0, holder="SK40 ER32x70")
    lam, omg = np.radians([0.0, 15.0, 15.0, 30.0]), np.radians([0.0, 0.0, 60.0, -45.0])
    reach = MeshReach(mesh)
    bare = lifts(reach, FLAT, ORIGIN, IDENTITY, lam, omg, 40.0)[0]
    held = lifts(reach, FLAT, ORIGIN, IDENTITY, lam, omg, 40.0, assembly=tool)[0]
    assert np.all(bare < 1e-9) and held.min() > 1.0
    drop = AssemblyDrop(mesh, tool)
    for k in range(len(lam)):
        tip, axis = world_placement(FLAT, ORIGIN, IDENTITY, lam[k:k + 1], omg[k:k + 1], np.zeros(1))
        travel, _ = drop.along(tip + 100.0 * axis, axis[0], -axis[0])
        assert held[k] == pytest.approx(100.0 - travel[0], abs=1e-6)
