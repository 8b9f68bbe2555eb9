"""How close the tool's bodies (coaxial frusta, core.tools.assembly) come to the model at any tool pose: a
point sample of the mesh surface, and each point's exact signed distance to each frustum in the tool's frame.

The sample puts a barycentric grid on every triangle, no two grid neighbours further than `step` apart, so
every point of the surface lies within step / sqrt(3) of a sample point (the covering radius of a triangle is
at most its longest edge / sqrt(3)): a distance measured to the sample exceeds the surface's by at most that.
Points are grouped into nested cubic cells (each level 4 times the size of the one below); a cell's points
lie within its radius of its centre and the distance to a convex body is 1-Lipschitz, so each level keeps
only the cells that may hold a point within the clearance and, of those, only the ones that may hold the
deepest (branch and bound), before the points of the finest cells are measured exactly.

Cost, for P poses and B bodies: a k-d tree pair search of P body spheres against the coarsest cells, then
per level the children of the cells kept: a clear pose costs a few cell tests per body; a colliding one about
the points of the finest cells near its deepest point (a band of cells, not all the body swallows).
"""
from __future__ import annotations

import math
from typing import Sequence

import numpy as np

from tmm_workbench.core import cancel
from tmm_workbench.core.errors import TmmError
from tmm_workbench.core.geometry.mesh import TriMesh

Body = tuple[float, float, float, float, float]  # (z0, z1, r0, r1, clearance), tip coordinates
_CHUNK_POINTS = 2_000_000  # point-pose pairs per vectorised step (memory: ~100 MB of float64 temporaries)
_CHUNK_POSES = 1024        # poses per pair search (bounds the pairs a holder near the part makes)
_RATIO = 4                 # cell size ratio between levels


def sample_surface(mesh: TriMesh, step: float) -> np.ndarray:
    """(n, 3) points on every triangle of `mesh`: a barycentric grid whose neighbours are at most `step` apart.
    The mesh's vertices come once; a triangle adds only its grid points off its corners."""
    corners = mesh.vertices[mesh.triangles]                      # (m, 3, 3)
    edges = np.linalg.norm(corners - np.roll(corners, 1, axis=1), axis=2).max(axis=1)
    divisions = np.maximum(1, np.ceil(edges / step)).astype(np.int64)
    out = [mesh.vertices]
    for n in np.unique(divisions[divisions > 1]):
        i, j = np.meshgrid(np.arange(n + 1), np.arange(n + 1), indexing="ij")
        corner = ((i == 0) & (j == 0)) | ((i == n) & (j == 0)) | ((i == 0) & (j == n))
        keep = (i + j <= n) & ~corner
        w = np.column_stack([n - i[keep] - j[keep], i[keep], j[keep]]) / n   # (k, 3) barycentric weights
        tri = corners[divisions == n]                                          # (t, 3, 3)
        out.append(np.einsum("kc,tcd->tkd", w, tri).reshape(-1, 3))
    return np.concatenate(out)


def signed_distance(rho: np.ndarray, h: np.ndarray, body: Body) -> np.ndarray:
    """Signed distance from points at radius `rho` from the axis and height `h` above the tip to the solid
    frustum `body` (its clearance not applied): positive outside, minus the depth inside. In the (rho, h)
    half plane the frustum is the trapezoid (0, z0), (r0, z0), (r1, z1), (0, z1); the axis edge is no face."""
    z0, z1, r0, r1, _ = body
    d = np.full(rho.shape, np.inf)
    for (a0, b0), (a1, b1) in (((0.0, z0), (r0, z0)), ((r0, z0), (r1, z1)), ((r1, z1), (0.0, z1))):
        ex, ey = a1 - a0, b1 - b0
        length2 = ex * ex + ey * ey
        if length2 == 0.0:  # a cone's point: the side reduces to the apex
            t = 0.0
        else:
            t = np.clip(((rho - a0) * ex + (h - b0) * ey) / length2, 0.0, 1.0)
        d = np.minimum(d, np.hypot(rho - a0 - t * ex, h - b0 - t * ey))
    inside = (h >= z0) & (h <= z1) & (rho <= r0 + (r1 - r0) * (h - z0) / (z1 - z0))
    return np.where(inside, -d, d)


def frame_coordinates(points: np.ndarray, tips: np.ndarray, axes: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(rho, h) of each point in the frame of its pose (tip, unit axis): distance from the axis, height along it."""
    v = points - tips
    h = np.einsum("ij,ij->i", v, axes)
    rho = np.sqrt(np.maximum(np.einsum("ij,ij->i", v, v) - h * h, 0.0))
    return rho, h


class SurfacePoints:
    """A point sample of a mesh's surface in nested cells, for the distance from tool bodies at any pose."""

    def __init__(self, mesh: TriMesh, step: float = 0.25) -> None:
        """`step`: the sample's spacing (mm); distances overestimate the surface's by at most `error`,
        step / sqrt(3)."""
        from scipy.spatial import cKDTree  # the k-d tree the core's other point queries use

        if isinstance(step, bool) or not isinstance(step, (int, float)) or not 0 < step < math.inf:
            raise TmmError(f"surface sample step must be a finite length > 0 mm, got {step!r}")
        self.step = float(step)
        self.error = self.step / math.sqrt(3.0)
        pts = sample_surface(mesh, self.step)
        fine = 2 * self.step
        extent = float((pts.max(axis=0) - pts.min(axis=0)).max())
        levels = 1
        while levels < 6 and fine * _RATIO ** levels < extent / 2:
            levels += 1
        key = np.floor((pts - pts.min(axis=0)) / fine).astype(np.int64)
        keys = [key // _RATIO ** j for j in range(levels)]            # nested: finest first
        order = np.lexsort(tuple(k[:, a] for k in keys for a in (2, 1, 0)))  # coarsest x is the primary key
        self.points = pts[order]
        starts = []
        for k in keys:
            k = k[order]
            starts.append(np.flatnonzero(np.concatenate([[True], (k[1:] != k[:-1]).any(axis=1)])))
        # per level (finest first): cell centres, radii, first child and child count (points for the finest)
        self.centres, self.radii, self.first, self.count = [], [], [], []
        for j, st in enumerate(starts):
            lo, hi = np.minimum.reduceat(self.points, st), np.maximum.reduceat(self.points, st)
            self.centres.append((lo + hi) / 2)
            self.radii.append(np.linalg.norm(hi - lo, axis=1) / 2)
            below = np.arange(len(self.points)) if j == 0 else starts[j - 1]
            first = np.searchsorted(below, st)
            self.first.append(first)
            self.count.append(np.diff(np.append(first, len(below))))
        self.tree = cKDTree(self.centres[-1])

    def worst(self, tips: np.ndarray, axes: np.ndarray, bodies: Sequence[Body],
              slack: float = 0.0) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Per pose (tips, unit axes, (m, 3) each): (intrusion, body, contact): the largest clearance - distance
        over the bodies and the sample points within clearance + `slack` of a body (-inf, -1 and NaN where
        none is), which body, and that point."""
        m = len(tips)
        best = np.full(m, -np.inf)
        which = np.full(m, -1, dtype=np.int64)
        contact = np.full((m, 3), np.nan)
        for lo in range(0, m, _CHUNK_POSES):
            hi = min(m, lo + _CHUNK_POSES)
            for b, body in enumerate(bodies):
                pose, cell = self._coarse_pairs(tips[lo:hi], axes[lo:hi], body, slack)
                for level in range(len(self.centres) - 1, -1, -1):
                    pose, cell = self._bound(level, pose, cell, tips[lo:hi], axes[lo:hi], body, slack, best[lo:hi])
                    if level:
                        pose, cell = _children(pose, cell, self.first[level], self.count[level])
                    cancel.poll()
                self._refine(pose + lo, cell, tips, axes, body, b, body[4] + slack, best, which, contact)
        return best, which, contact

    def _coarse_pairs(self, tips: np.ndarray, axes: np.ndarray, body: Body,
                      slack: float) -> tuple[np.ndarray, np.ndarray]:
        """(pose, coarsest cell) pairs, sorted by pose, whose cell meets a sphere about the body grown by its
        clearance + slack: the body is covered by spheres along its axis (a long thin shank by several)."""
        from scipy.spatial import cKDTree

        z0, z1, r0, r1, c = body
        radius = float(self.radii[-1].max())
        pieces = max(1, math.ceil((z1 - z0) / max(2 * max(r0, r1), 2 * radius, 1e-9)))
        half = (z1 - z0) / pieces / 2
        sphere = math.hypot(half, max(r0, r1)) + c + slack + radius
        n = len(self.centres[-1])
        keys = []
        for k in range(pieces):
            pairs = cKDTree(tips + axes * (z0 + (2 * k + 1) * half)).sparse_distance_matrix(
                self.tree, sphere, output_type="ndarray")
            keys.append(pairs["i"].astype(np.int64) * n + pairs["j"].astype(np.int64))
        return np.divmod(np.unique(np.concatenate(keys)), n)

    def _bound(self, level: int, pose: np.ndarray, cell: np.ndarray, tips: np.ndarray, axes: np.ndarray,
               body: Body, slack: float, found: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The pairs (sorted by pose) whose cell may hold a point within clearance + slack of the body and may
        hold the pose's deepest: a cell's points are clearance - (centre distance +- radius) deep, so a cell
        whose deepest possible point is shallower than what another cell surely holds (or `found`, what other
        bodies reached) is dropped."""
        if len(pose) == 0:
            return pose, cell
        rho, h = frame_coordinates(self.centres[level][cell], tips[pose], axes[pose])
        sd, r, c = signed_distance(rho, h, body), self.radii[level][cell], body[4]
        near = sd - r < c + slack
        pose, cell, sd, r = pose[near], cell[near], sd[near], r[near]
        if len(pose) == 0:
            return pose, cell
        heads = np.flatnonzero(np.concatenate([[True], pose[1:] != pose[:-1]]))
        sure = np.maximum(np.maximum.reduceat(c - sd - r, heads), found[pose[heads]])
        keep = c - sd + r >= np.repeat(sure, np.diff(np.append(heads, len(pose)))) - 1e-12
        return pose[keep], cell[keep]

    def _refine(self, pose: np.ndarray, cell: np.ndarray, tips: np.ndarray, axes: np.ndarray, body: Body, b: int,
                reach: float, best: np.ndarray, which: np.ndarray, contact: np.ndarray) -> None:
        """The finest cells' points against the body at their poses, in chunks; keeps each pose's deepest."""
        if len(cell) == 0:
            return
        counts = self.count[0][cell]
        ends = np.cumsum(counts)
        cuts = np.searchsorted(ends, np.arange(_CHUNK_POINTS, ends[-1], _CHUNK_POINTS), side="right")
        edges = np.unique(np.concatenate([[0], cuts, [len(cell)]]))
        for lo, hi in zip(edges[:-1], edges[1:]):
            at, idx = _children(pose[lo:hi], cell[lo:hi], self.first[0], self.count[0])
            rho, h = frame_coordinates(self.points[idx], tips[at], axes[at])
            v = body[4] - signed_distance(rho, h, body)   # how much closer than the clearance
            close = v > body[4] - reach
            at, v, idx = at[close], v[close], idx[close]
            if len(at):  # sorted by pose: each pose's deepest point by segment
                heads = np.flatnonzero(np.concatenate([[True], at[1:] != at[:-1]]))
                top = np.maximum.reduceat(v, heads)
                pick = np.flatnonzero(v == np.repeat(top, np.diff(np.append(heads, len(v)))))
                pick = pick[np.searchsorted(pick, heads)]   # the first deepest of each segment
                at, v, idx = at[pick], v[pick], idx[pick]
                deeper = v > best[at]
                best[at[deeper]] = v[deeper]
                which[at[deeper]] = b
                contact[at[deeper]] = self.points[idx[deeper]]
            cancel.poll()


def _children(pose: np.ndarray, cell: np.ndarray, first: np.ndarray, count: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Every (pose, child) of the (pose, cell) pairs, in the same order."""
    n = count[cell]
    offsets = np.arange(int(n.sum())) - np.repeat(np.cumsum(n) - n, n)
    return np.repeat(pose, n), np.repeat(first[cell], n) + offsets
