"""Cancel latency of the kernel's mesh phases and the multipoint positioner's construction, through the binding.

    .venv/bin/python benchmarks/cancel_mesh_phases.py            # a 10M-triangle grid (STL files cached in /tmp)
    TMM_MESH_SIDE=1000 .venv/bin/python benchmarks/cancel_mesh_phases.py   # 2M triangles

Each phase runs once to the end with a progress callback that always goes on (its time, how many reports, the
longest gap between two), then again with a callback that answers False from half that time on: the latency is
the time from then to the exception (Cancelled). Before these phases reported, a cancel waited for the rest of
the phase: about half its time.
"""
from __future__ import annotations

import os
import re
import sys
import time
from typing import Callable

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, ROOT)

from tmm_workbench.core.kernel import native  # noqa: E402

SIDE = int(os.environ.get("TMM_MESH_SIDE", "2236"))  # 2 * side^2 triangles: 10M by default
BINARY, ASCII = f"/tmp/tmm_cancel_grid_{SIDE}.stl", f"/tmp/tmm_cancel_grid_{SIDE}_ascii.stl"


def grid(side: int) -> tuple[np.ndarray, np.ndarray]:
    """A wavy height field over 100 x 100 mm: vertices (n, 3) and triangles (m, 3)."""
    x = np.linspace(0.0, 100.0, side + 1)
    X, Y = np.meshgrid(x, x, indexing="ij")
    V = np.column_stack([X.ravel(), Y.ravel(), (np.sin(X / 7) * np.cos(Y / 5)).ravel()])
    idx = np.arange((side + 1) ** 2).reshape(side + 1, side + 1)
    a, b, c, d = idx[:-1, :-1].ravel(), idx[1:, :-1].ravel(), idx[1:, 1:].ravel(), idx[:-1, 1:].ravel()
    F = np.concatenate([np.column_stack([a, b, c]), np.column_stack([a, c, d])]).astype(np.int32)
    return V, F


def write_stls(soup: np.ndarray) -> None:
    """The soup as a binary and an ASCII STL (written once per size)."""
    if not os.path.exists(BINARY):
        rec = np.zeros(len(soup), dtype=[("n", "<f4", 3), ("v", "<f4", 9), ("a", "<u2")])
        rec["v"] = soup
        with open(BINARY, "wb") as fh:
            fh.write(bytes(80) + np.uint32(len(soup)).tobytes() + rec.tobytes())
    if not os.path.exists(ASCII):
        facet = ("facet normal 0 0 1\n outer loop\n  vertex %.7g %.7g %.7g\n  vertex %.7g %.7g %.7g\n"
                 "  vertex %.7g %.7g %.7g\n endloop\nendfacet\n")
        with open(ASCII, "w") as fh:
            fh.write("solid grid\n")
            for s in range(0, len(soup), 100000):
                fh.write("".join(facet % tuple(r) for r in soup[s:s + 100000].astype(np.float32)))
            fh.write("endsolid grid\n")


def measure(name: str, call: Callable[[Callable[[float], bool]], object]) -> None:
    """Prints the phase's time, reports, longest gap between reports and the latency of a cancel mid-way."""
    stamps: list[float] = []
    fractions: list[float] = []

    def go_on(f: float) -> bool:
        stamps.append(time.perf_counter())
        fractions.append(f)
        return True

    t0 = time.perf_counter()
    call(go_on)
    total = time.perf_counter() - t0
    gaps = np.diff([t0] + stamps)
    monotone = all(b >= a for a, b in zip(fractions, fractions[1:]))
    at = t0 = time.perf_counter()
    at += total / 2

    def stop_at_half(_: float) -> bool:
        return time.perf_counter() < at

    try:
        call(stop_at_half)
        latency = "finished"
    except native.Cancelled:
        latency = f"{time.perf_counter() - at:.3f}"
    back = "" if monotone else " (went back)"
    print(f"{name:<26} {total:8.2f} {len(stamps):8d} {gaps.max():8.3f} {latency:>10}{back}", flush=True)


def finest_positioner_options(surface) -> "native.MultipointOptions":
    """A 6.7 x 6.0 torus, extended face, at the finest sample spacing the face can take (two sample sets)."""
    o = native.MultipointOptions(Ro=6.7, Ri=6.0, extend=2.0, sample_spacing=1e-3)
    try:
        native.MultipointPositioner(surface, o)
    except ValueError as exc:
        o.sample_spacing = float(re.search(r">= ([0-9.e+-]+) mm", str(exc)).group(1))
    return o


def main() -> None:
    V, F = grid(SIDE)
    soup = V[F].reshape(-1, 9)
    write_stls(soup)
    print(f"{len(F)} triangles, {len(V)} vertices; {time.strftime('%Y-%m-%d')}")
    print(f"{'phase':<26} {'time s':>8} {'reports':>8} {'max gap':>8} {'latency s':>10}")
    measure("read_stl binary", lambda p: native.read_stl(BINARY, progress=p))
    measure("read_stl ASCII", lambda p: native.read_stl(ASCII, progress=p))
    measure("weld", lambda p: native.weld(soup, 1e-6, progress=p))
    measure("face_normals", lambda p: native.face_normals(V, F, progress=p))
    measure("vertex_normals angle", lambda p: native.vertex_normals(V, F, "angle", progress=p))
    measure("vertex_normals meyer", lambda p: native.vertex_normals(V, F, "meyer", progress=p))
    measure("triangle_adjacency", lambda p: native.triangle_adjacency(F, progress=p))
    measure("MeshIndex", lambda p: native.MeshIndex(V, F, progress=p))
    rng = np.random.default_rng(1)
    net = np.zeros((13, 13, 3))
    net[..., 0] = 50.0 * np.arange(13)[:, None]
    net[..., 1] = 50.0 * np.arange(13)[None, :]
    net[..., 2] = rng.uniform(70.0, 100.0, (13, 13))
    surface = native.PatchSurface.from_net(net)
    options = finest_positioner_options(surface)
    measure(f"positioner 13x13 {options.sample_spacing:.3g} mm",
            lambda p: native.MultipointPositioner(surface, options, progress=p))


if __name__ == "__main__":
    main()
