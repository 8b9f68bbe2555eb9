"""Fuzzes every entry point of the kernel binding (tmm_workbench._native) with random and extreme inputs: huge,
NaN and infinite coordinates, huge and negative indices, odd shapes and dtypes, options at and past their
limits. Every call must return finite values (where its documentation allows it: +-inf for "no contact" or
"unreached", NaN for a lean vertex that is no arc end) or raise ValueError, RuntimeError, TypeError,
IndexError or the binding's Cancelled; a crash or a sanitizer report ends the process. Calls that take a
progress callback get one that cancels after a second, so that no input can run for long.

    python native/fuzz/fuzz_binding.py [--calls N] [--seed S]

Fixed seed, bounded calls: the same inputs on every run. scripts/test.sh runs it under the sanitized module
(native/sanitize_bindings.sh sets the module up)."""
from __future__ import annotations

import argparse
import warnings
import math
import sys
import time
from typing import Any, Callable

import numpy as np

from tmm_workbench.core.kernel import native

EXTREME = [0.0, -0.0, 1.0, -1.0, 1e-300, 5e-324, 1e8, -9.99e8, 1e9, 1e150, -1e300, 1.7e308, math.inf, -math.inf,
           math.nan]
INDICES = [0, 1, 2, 3, -1, 2**31 - 1, 2**31, 2**32 + 2, -2**31, 2**63 - 1]
EXPECTED = (ValueError, RuntimeError, TypeError, IndexError, OverflowError, native.Cancelled)


class Fuzz:
    def __init__(self, seed: int) -> None:
        self.rng = np.random.default_rng(seed)
        self.calls = 0
        self.outcomes: dict[str, int] = {}

    # --- values

    def real(self, sane: float = 10.0) -> float:
        """Mostly sane values near the part, sometimes an extreme one."""
        if self.rng.random() < 0.3:
            return float(self.rng.choice(EXTREME))
        return float(self.rng.uniform(-sane, sane))

    def positive(self, sane: float = 5.0) -> float:
        return abs(self.real(sane)) if self.rng.random() < 0.3 else float(self.rng.uniform(sane / 50, sane))

    def points(self, n: int, cols: int, sane: float = 10.0, odd: bool = True) -> Any:
        a = self.rng.uniform(-sane, sane, (n, cols))
        if n and self.rng.random() < 0.4:  # a few extreme entries
            k = int(self.rng.integers(1, 4))
            a.flat[self.rng.integers(0, a.size, k)] = self.rng.choice(EXTREME, k)
        return self.odd(a) if odd else a

    def vec(self, sane: float = 10.0) -> Any:
        """A 3-vector, sometimes of the wrong length."""
        v = self.points(1, 3, sane, odd=False).reshape(-1)
        return v[:2] if self.rng.random() < 0.03 else v

    def odd(self, a: np.ndarray) -> Any:
        """Now and then a wrong shape, dtype or a non-array."""
        r = self.rng.random()
        if r < 0.04:
            return a.reshape(-1)
        if r < 0.06:
            return a.astype(np.float32)
        if r < 0.08:
            return a.T.copy() if a.ndim == 2 else a
        if r < 0.09:
            return a.tolist()
        if r < 0.095:
            return "not an array"
        return a

    def triangles(self, nv: int, m: int) -> Any:
        F = self.rng.integers(0, max(nv, 1), (m, 3))
        if self.rng.random() < 0.2:
            F.flat[self.rng.integers(0, F.size)] = self.rng.choice(INDICES)
        dtype = self.rng.choice([np.int32, np.int64, np.uint64, np.uint8, np.float64])
        if dtype is np.uint8 or dtype is np.uint64:
            F = np.abs(F)
        return self.odd(F.astype(dtype, casting="unsafe"))

    def mesh(self) -> tuple[Any, Any]:
        nv = int(self.rng.integers(3, 40))
        return self.points(nv, 3), self.triangles(nv, int(self.rng.integers(1, 40)))

    def progress(self) -> Callable[[float], bool]:
        start = time.monotonic()
        return lambda f: time.monotonic() - start < 1.0

    # --- checks

    def call(self, name: str, f: Callable[[], Any], allow_inf: bool = False, allow_nan: tuple = ()) -> Any:
        self.calls += 1
        try:
            out = f()
        except EXPECTED as exc:
            self.outcomes[name + ": " + type(exc).__name__] = self.outcomes.get(name + ": " + type(exc).__name__, 0) + 1
            return None
        self.outcomes[name + ": ok"] = self.outcomes.get(name + ": ok", 0) + 1
        self.check(name, out, allow_inf, allow_nan)
        return out

    def check(self, name: str, out: Any, allow_inf: bool, allow_nan: tuple, key: str = "") -> None:
        if isinstance(out, dict):
            for k, v in out.items():
                self.check(name, v, allow_inf, allow_nan, str(k))
        elif isinstance(out, (list, tuple)):
            for v in out:
                self.check(name, v, allow_inf, allow_nan, key)
        elif isinstance(out, (float, np.ndarray)) and np.asarray(out).dtype.kind == "f":
            a = np.asarray(out)
            bad = np.isnan(a) if key not in allow_nan else np.zeros(a.shape, bool)
            if not allow_inf:
                bad |= np.isinf(a)
            if bad.any():
                raise AssertionError(f"{name}: {key or 'result'} has non-finite values {a[bad][:5]} "
                                     f"(call {self.calls})")


# --- the entry points, one function each (the binding's order: mesh, drop, direction, surface, multipoint,
# waterline, simulation, adaptive raster, arrival field, lean)

def fuzz_mesh(z: Fuzz, tmp: str) -> None:
    V, F = z.mesh()
    z.call("face_normals", lambda: native.face_normals(V, F, z.progress()))
    z.call("vertex_normals", lambda: native.vertex_normals(V, F, str(z.rng.choice(["angle", "area", "meyer", "x"])),
                                                           z.progress()))
    z.call("triangle_adjacency", lambda: native.triangle_adjacency(F, z.progress()))
    soup = z.points(int(z.rng.integers(0, 20)), 9)
    z.call("weld", lambda: native.weld(soup, z.real(1e-3), z.progress()))
    data = z.rng.integers(0, 256, int(z.rng.integers(0, 300)), dtype=np.uint8).tobytes()
    if z.rng.random() < 0.5:
        data = b"solid f\nfacet normal 0 0 1\nouter loop\n" + b"".join(
            b"vertex %r %r %r\n" % (z.real(), z.real(), z.real()) for _ in range(3)) + b"endloop\nendfacet\nendsolid f\n"
    with open(tmp, "wb") as f:
        f.write(data)
    z.call("read_stl", lambda: native.read_stl(tmp, z.progress()))


def cutter(z: Fuzz) -> Any:
    r = z.rng.random()
    if r < 0.5:
        return z.call("Cutter", lambda: native.Cutter(z.positive(3.0), z.positive(1.0)))
    return z.call("Cutter.apt", lambda: native.Cutter.apt(z.positive(3.0), z.positive(0.5), z.positive(20.0),
                                                           z.real(0.5), z.real(0.5)))


def fuzz_drop(z: Fuzz) -> None:
    V, F = z.mesh()
    index = z.call("MeshIndex", lambda: native.MeshIndex(V, F, threads=int(z.rng.integers(-1, 3)),
                                                         progress=z.progress()))
    c = cutter(z)
    if c is not None:
        z.call("Cutter.height", lambda: c.height(np.abs(z.points(5, 1, c.max_radius, odd=False).reshape(-1))))
        z.call("drop_on_triangle", lambda: native.drop_on_triangle(c, z.real(), z.real(), z.points(3, 3)),
               allow_inf=True)
    if index is None or c is None:
        return
    xy = z.points(int(z.rng.integers(0, 200)), 2)
    z.call("drop_cutter", lambda: native.drop_cutter(index, c, xy, z.real(), 2, z.progress()))
    z.call("drop_cutter_stats", lambda: native.drop_cutter_stats(index, c, xy, z.real(), 1))


def fuzz_direction(z: Fuzz) -> None:
    V, F = z.mesh()
    d = z.vec(1.0) if z.rng.random() < 0.3 else np.array([0.3, 0.1, -1.0]) / math.sqrt(1.1)
    index = z.call("DirectionalIndex", lambda: native.DirectionalIndex(V, F, d))
    c = cutter(z)
    if c is not None:
        axis = z.vec(1.0) if z.rng.random() < 0.3 else np.array([0.0, 0.0, 1.0])
        z.call("drop_along_triangle", lambda: native.drop_along_triangle(
            c, z.vec(), axis, -axis if z.rng.random() < 0.7 else z.vec(1.0), z.points(3, 3)), allow_inf=True)
    if index is None or c is None:
        return
    n = int(z.rng.integers(0, 100))
    axes = z.points(n, 3, 1.0) if z.rng.random() < 0.3 else -index.direction
    travel = z.real(50.0) if z.rng.random() < 0.5 else math.inf
    z.call("drop_along", lambda: native.drop_along(index, c, z.points(n, 3), axes, travel, 2, z.progress()),
           allow_inf=True)
    z.call("drop_along_stats", lambda: native.drop_along_stats(index, c, z.points(n, 3), axes, travel, 1),
           allow_inf=True)


def net(z: Fuzz) -> np.ndarray:
    p, q = int(z.rng.integers(1, 5)), int(z.rng.integers(1, 5))
    g = np.stack(np.meshgrid(np.linspace(0, 50, p + 1), np.linspace(0, 50, q + 1), indexing="ij"), -1)
    out = np.concatenate([g, z.rng.uniform(0, 10, (p + 1, q + 1, 1))], -1)
    if z.rng.random() < 0.4:
        out.flat[z.rng.integers(0, out.size)] = z.rng.choice(EXTREME)
    return out


def fuzz_surface(z: Fuzz) -> Any:
    nu, nv = int(z.rng.integers(1, 3)), int(z.rng.integers(1, 3))
    breaks = lambda k: sorted(z.real(5.0) for _ in range(k + 1)) if z.rng.random() < 0.3 else list(range(k + 1))
    z.call("PatchSurface", lambda: native.PatchSurface([net(z) for _ in range(nu * nv)], nu, nv, breaks(nu),
                                                       breaks(nv)))
    s = z.call("PatchSurface.from_net", lambda: native.PatchSurface.from_net(z.odd(net(z))))
    z.call("bezier_subpatch", lambda: native.bezier_subpatch(net(z), z.real(1), z.real(1), z.real(1), z.real(1)))
    if s is None:
        return None
    z.call("net", lambda: s.net(int(z.rng.choice(INDICES[:6])), 0))
    z.call("evaluate", lambda: s.evaluate(z.points(int(z.rng.integers(0, 20)), 2, 1.0)))
    z.call("ray_hit", lambda: s.ray_hit(z.vec(100), z.vec(1)))
    return s


def fuzz_multipoint(z: Fuzz) -> None:
    s = fuzz_surface(z)
    opts = z.call("MultipointOptions", lambda: native.MultipointOptions(
        Ro=z.positive(5.0), Ri=z.positive(4.0), method=str(z.rng.choice(["vcrf", "drd"])),
        beta_max=z.positive(1.0), tol=z.positive(0.01), sample_spacing=z.positive(2.0) if z.rng.random() < 0.5 else 0.0,
        divisions=int(z.rng.choice([1, 4, 6, 0, 100000])), refinements=int(z.rng.choice([0, 1, 2, -1])),
        extend=z.positive(1.0) if z.rng.random() < 0.3 else 0.0))
    if s is None or opts is None:
        return
    mp = z.call("MultipointPositioner", lambda: native.MultipointPositioner(s, opts, z.progress()))
    if mp is None:
        return
    xy = z.points(int(z.rng.integers(0, 6)), 2, 50.0)
    # a failed point's fields are NaN (documented): only its status is checked
    r = z.call("position_batch", lambda: mp.position_batch(xy, 2, z.progress()), allow_inf=True,
               allow_nan=("beta", "drop_z", "gap_P", "gap_Q", "penetration", "seed_axis_angle", "tip", "axis",
                          "centre", "P", "nP", "Q", "nQ", "seed_axis", "uvP", "uvQ", "axis_xy", "anchor_error",
                          "penetration_real"))
    if r is not None:
        assert np.all(np.isin(r["status"], [0, 1, 2])), r["status"]
    tip, axis = z.vec(50.0), z.vec(1.0)
    z.call("tool_distance", lambda: mp.tool_distance(tip, axis, z.points(4, 3, 50.0)))
    n = int(z.rng.integers(0, 4))
    z.call("clearance", lambda: mp.clearance(z.points(n, 3, 50.0), z.points(n, 3, 1.0), 2), allow_inf=True)


def fuzz_waterline(z: Fuzz) -> None:
    V, F = z.mesh()
    index = z.call("MeshIndex", lambda: native.MeshIndex(V, F))
    c = cutter(z)
    o = native.WaterlineOptions()
    o.xmin, o.ymin = z.real(), z.real()
    o.xmax, o.ymax = o.xmin + z.positive(20.0), o.ymin + z.positive(20.0)
    o.sample_step = z.positive(1.0)
    o.chord_tol = z.positive(0.05)
    o.bracket = o.chord_tol / 10
    o.min_segment = z.positive(0.05)
    o.max_depth = int(z.rng.choice([0, 4, 64, 65, -1]))
    o.min_step = 0.0 if z.rng.random() < 0.5 else o.sample_step / float(z.rng.choice([2, 256, 1000]))
    z.call("waterline_grid_size", lambda: native.waterline_grid_size(o))
    if index is not None and c is not None:
        zs = [z.real(5.0) for _ in range(int(z.rng.integers(0, 4)))]
        z.call("waterline", lambda: native.waterline(index, c, zs, o, threads=2, progress=z.progress()))


def fuzz_sim(z: Fuzz) -> None:
    nx, ny = (int(v) for v in z.rng.choice([1, 10, 60, 2**40, 0], 2))
    stock = z.call("ZMap", lambda: native.ZMap(z.real(), z.real(), z.positive(0.5), nx, ny, z.real(5.0)))
    z.call("ZMap.bytes_for", lambda: native.ZMap.bytes_for(int(z.rng.choice([1, 2**40, 2**62])), 2**10))
    if stock is None:
        return
    n = int(z.rng.integers(0, 6))
    kinds = z.odd(z.rng.choice([0, 1, 2, 3, -1, 256], max(n - 1, 0), p=[0.5, 0.2, 0.1, 0.1, 0.05, 0.05]))
    c = cutter(z)
    if c is not None:
        z.call("cut_3axis", lambda: native.cut_3axis(stock, c, z.points(n, 3), kinds, z.positive(0.01), 2,
                                                     z.progress()))
    axes = np.abs(z.points(n, 3, 1.0, odd=False)) + np.array([0.0, 0.0, 0.5]) if z.rng.random() < 0.7 else z.points(n, 3, 1.0)
    z.call("cut_5axis", lambda: native.cut_5axis(
        stock, z.positive(3.0), z.positive(2.0), str(z.rng.choice(["round_insert", "bull_nose", "x"])),
        z.points(n, 3), axes, kinds, max_step=z.positive(0.5), collision_tol=z.positive(0.01), threads=2,
        progress=z.progress()))
    z.call("ZMap.heights", lambda: stock.heights)
    z.call("lowest_on_vertical", lambda: native.lowest_on_vertical(
        z.positive(3.0), z.positive(2.0), "round_insert", z.vec(),
        np.array([z.real(1), z.real(1), 1.0]), z.real(), z.real()), allow_inf=True)


def fuzz_adaptive(z: Fuzz) -> None:
    V, F = z.mesh()
    index = z.call("MeshIndex", lambda: native.MeshIndex(V, F))
    tool, c = cutter(z), cutter(z)
    o = native.AdaptiveRasterOptions()
    o.xmin, o.ymin = z.real(), z.real()
    o.xmax, o.ymax = o.xmin + z.positive(20.0), o.ymin + z.positive(20.0)
    o.angle, o.cusp, o.sample_step = z.real(3.0), z.positive(0.05), z.positive(1.0)
    o.floor_z, o.stock_to_leave, o.max_slope = z.real(5.0), z.positive(0.5) if z.rng.random() < 0.3 else 0.0, 1.2
    o.step_min, o.step_max = z.positive(0.2), z.positive(2.0)
    if tool is not None:
        # a work estimate: inf (a step of 5e-324 mm) says "more than any limit", which the core refuses
        z.call("adaptive_raster_work", lambda: native.adaptive_raster_work(tool, o), allow_inf=True)
    if index is not None and tool is not None and c is not None:
        z.call("adaptive_raster", lambda: native.adaptive_raster(index, tool, c, o, threads=2, progress=z.progress()))


def fuzz_arrival(z: Fuzz) -> None:
    nx, ny = int(z.rng.integers(1, 30)), int(z.rng.integers(1, 30))
    zz = z.points(ny, nx, 5.0)
    active = z.rng.integers(0, 2, (ny, nx)).astype(np.uint8)
    start = np.full((ny, nx), np.nan)
    start[0, :] = 0.0
    steps = np.abs(z.points(4, 1, 1.0, odd=False).reshape(-1))
    args = (z.positive(0.5), z.positive(2.0), z.positive(1.0), z.positive(0.1))  # dslope radius probe min_step
    z.call("arrival_field", lambda: native.arrival_field(zz, z.positive(1.0), active, start, steps, *args[:4],
                                                         progress=z.progress()), allow_inf=True)
    n = int(z.rng.integers(0, 10))
    z.call("arrival_steps", lambda: native.arrival_steps(zz, z.positive(1.0), z.points(n, 2, 20.0),
                                                         z.points(n, 2, 1.0), steps, *args[:4]))


def fuzz_lean(z: Fuzz) -> None:
    V, F = z.mesh()
    index = z.call("MeshIndex", lambda: native.MeshIndex(V, F))
    tool = cutter(z)
    if index is None or tool is None:
        return
    runs = int(z.rng.integers(1, 4))
    counts = z.rng.integers(2, 20, runs)
    offsets = np.concatenate([[0], np.cumsum(counts)])
    s = np.concatenate([np.sort(z.rng.uniform(0, 20, k)) for k in counts])
    if z.rng.random() < 0.3:
        s.flat[z.rng.integers(0, s.size)] = z.rng.choice(EXTREME)
    zz = native.drop_cutter(index, tool, np.zeros((len(s), 2)) + 1.0, -10.0) if z.rng.random() < 0.5 else \
        z.points(len(s), 1, 5.0, odd=False).reshape(-1)
    origin, dirs = z.points(runs, 2), np.tile([[1.0, 0.0]], (runs, 1))
    flags = z.rng.integers(0, 4, len(s)).astype(np.uint8)
    arcs = None if z.rng.random() < 0.5 else np.ones(runs, np.uint8)
    z.call("lean_profiles", lambda: native.lean_profiles(
        index, tool, origin, dirs, offsets, s, zz, flags, tol=z.positive(0.05), max_step=z.positive(0.5),
        min_step=z.positive(0.01), drop_floor=z.real(10.0), arcs=arcs, threads=2, progress=z.progress()),
        allow_nan=("arc_s", "arc_z"))


ENTRY_GROUPS = [fuzz_mesh, fuzz_drop, fuzz_direction, fuzz_surface, fuzz_multipoint, fuzz_waterline, fuzz_sim,
                fuzz_adaptive, fuzz_arrival, fuzz_lean]


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--calls", type=int, default=3000, help="stop after about this many calls")
    ap.add_argument("--seed", type=int, default=32)
    ap.add_argument("--tmp", default="/tmp/tmm_fuzz_binding.stl", help="scratch file for read_stl")
    ap.add_argument("-v", "--verbose", action="store_true", help="print the outcomes per entry point")
    a = ap.parse_args()
    warnings.simplefilter("ignore", RuntimeWarning)  # numpy's own overflow in the odd dtypes made here
    z = Fuzz(a.seed)
    z.call("multipoint_reasons", native.multipoint_reasons)
    rounds = 0
    start = time.monotonic()
    while z.calls < a.calls:
        group = ENTRY_GROUPS[rounds % len(ENTRY_GROUPS)]
        group(z, a.tmp) if group is fuzz_mesh else group(z)
        rounds += 1
    if a.verbose:
        for k in sorted(z.outcomes):
            print(f"{z.outcomes[k]:6d}  {k}")
    ok = sum(v for k, v in z.outcomes.items() if k.endswith(": ok"))
    print(f"fuzz_binding: {z.calls} calls ({ok} returned, {z.calls - ok} refused) over "
          f"{len({k.split(':')[0] for k in z.outcomes})} entry points in {time.monotonic() - start:.1f} s, seed {a.seed}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
