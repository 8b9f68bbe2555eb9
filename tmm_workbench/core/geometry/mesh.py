"""Indexed triangle meshes for the kernel: float64 vertices (n, 3), int32 triangles (m, 3)."""
from __future__ import annotations

from pathlib import Path
from typing import Callable, Optional

import numpy as np

from tmm_workbench.core.cancel import native_call
from tmm_workbench.core.errors import TmmError
from tmm_workbench.core.kernel import native

# Each kernel phase below takes seconds on a mesh of millions of triangles: it reports to `progress` and stops
# when it answers False (Cancelled), or without one asks the strategy's watched callback (core.cancel).
Progress = Callable[[float], bool]

WELD_TOLERANCE_MM = 1e-6
NORMAL_WEIGHTINGS = ("angle", "area", "meyer")


class TriMesh:
    """An indexed triangle mesh. Construction validates shapes, indices and finiteness.

    `degenerate_removed` counts the triangles dropped as degenerate when the mesh was welded from a
    triangle soup (0 for a mesh built from vertices and triangles)."""

    def __init__(self, vertices: np.ndarray, triangles: np.ndarray, name: str = "mesh") -> None:
        v = np.ascontiguousarray(vertices, dtype=np.float64)
        f = np.asarray(triangles)
        if f.size and f.max() > np.iinfo(np.int32).max:  # a cast would wrap it silently
            raise TmmError(f"{name}: triangle index {int(f.max())} does not fit the kernel's 32-bit indices "
                           f"(allowed 0..{np.iinfo(np.int32).max})")
        f = np.ascontiguousarray(f, dtype=np.int32)
        if v.ndim != 2 or v.shape[1] != 3:
            raise TmmError(f"{name}: vertices must have shape (n, 3), got {v.shape}")
        if f.ndim != 2 or f.shape[1] != 3:
            raise TmmError(f"{name}: triangles must have shape (m, 3), got {f.shape}")
        if len(f) == 0:
            raise TmmError(f"{name}: the mesh has no triangles")
        bad = ~np.isfinite(v).all(axis=1)
        if bad.any():
            raise TmmError(f"{name}: vertex {int(np.argmax(bad))} has a non-finite coordinate "
                           f"{v[int(np.argmax(bad))].tolist()}")
        if f.min() < 0 or f.max() >= len(v):
            raise TmmError(f"{name}: triangle indices out of range 0..{len(v) - 1}")
        self.vertices = v
        self.triangles = f
        self.name = name
        self.degenerate_removed = 0

    @classmethod
    def from_corners(cls, corners: np.ndarray, name: str = "mesh", weld_tolerance: float = WELD_TOLERANCE_MM,
                     progress: Optional[Progress] = None) -> "TriMesh":
        """From a triangle soup (m, 3, 3): corners welded within `weld_tolerance` mm; triangles that become
        degenerate (a repeated vertex or zero area) are dropped and counted in `degenerate_removed`."""
        c = np.ascontiguousarray(corners, dtype=np.float64)
        if c.ndim != 3 or c.shape[1:] != (3, 3):
            raise TmmError(f"{name}: triangle corners must have shape (m, 3, 3), got {c.shape}")
        if len(c) == 0:
            raise TmmError(f"{name}: the mesh has no triangles")
        try:  # the kernel also rejects non-finite corners, naming the triangle
            v, f, removed = native_call(native.weld, c.reshape(-1, 9), float(weld_tolerance), progress=progress)
        except ValueError as exc:
            raise TmmError(f"{name}: {exc}") from exc
        mesh = cls(v, f, name)
        mesh.degenerate_removed = int(removed)
        return mesh

    def face_normals(self, progress: Optional[Progress] = None) -> np.ndarray:
        """Unit normal (m, 3) of each triangle, from its winding; zero for a zero-area triangle."""
        return native_call(native.face_normals, self.vertices, self.triangles, progress=progress)

    def vertex_normals(self, weighting: str = "angle", progress: Optional[Progress] = None) -> np.ndarray:
        """Unit normal (n, 3) of each vertex; `weighting` is one of NORMAL_WEIGHTINGS (seed 000, 3.2)."""
        if weighting not in NORMAL_WEIGHTINGS:
            raise TmmError(f"{self.name}: unknown vertex normal weighting {weighting!r} "
                           f"(allowed: {', '.join(NORMAL_WEIGHTINGS)})")
        return native_call(native.vertex_normals, self.vertices, self.triangles, weighting, progress=progress)

    def adjacency(self, progress: Optional[Progress] = None) -> np.ndarray:
        """(m, 3) int32: the triangle across edge i = (t[i], t[(i + 1) % 3]) of each triangle t, or -1 for a
        boundary or non-manifold edge."""
        return native_call(native.triangle_adjacency, self.triangles, progress=progress)

    @property
    def bounds(self) -> tuple[np.ndarray, np.ndarray]:
        return self.vertices.min(axis=0), self.vertices.max(axis=0)

    def __len__(self) -> int:
        return len(self.triangles)

    def __repr__(self) -> str:
        return f"TriMesh({self.name!r}, {len(self.vertices)} vertices, {len(self.triangles)} triangles)"


def load_stl(path: str | Path, weld_tolerance: float = WELD_TOLERANCE_MM,
             progress: Optional[Progress] = None) -> TriMesh:
    """Read an ASCII or binary STL file (detected by content) into a welded mesh; `progress` sees the reading
    as its first half, the welding as the second.

    A missing, empty, truncated or garbled file raises TmmError naming the file and the line (ASCII) or
    triangle (binary) where it is wrong."""
    p = Path(path)
    reading = welding = None
    if progress is not None:
        reading, welding = (lambda f: progress(0.5 * f)), (lambda f: progress(0.5 + 0.5 * f))
    try:
        soup = native_call(native.read_stl, str(p), progress=reading)
    except (ValueError, RuntimeError) as exc:  # native.StlError is a ValueError
        raise TmmError(str(exc)) from exc
    return TriMesh.from_corners(soup.reshape(-1, 3, 3), name=p.name, weld_tolerance=weld_tolerance,
                                progress=welding)


def save_stl(mesh: TriMesh, path: str | Path) -> Path:
    """Write `mesh` as a binary STL (its facet normals from the corners' order); the file appears only when whole
    (written beside it, then renamed)."""
    p = Path(path)
    corners = mesh.vertices[mesh.triangles].astype(np.float32)
    normals = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
    normals /= np.maximum(np.linalg.norm(normals, axis=1, keepdims=True), 1e-30)
    rows = np.zeros(len(corners), dtype=[("n", "<f4", 3), ("v", "<f4", (3, 3)), ("attr", "<u2")])
    rows["n"], rows["v"] = normals, corners
    part = p.with_name(p.name + ".part")
    with open(part, "wb") as f:
        f.write(mesh.name.encode("ascii", "replace")[:80].ljust(80, b" "))
        f.write(np.uint32(len(rows)).tobytes())
        f.write(rows.tobytes())
    part.replace(p)
    return p
