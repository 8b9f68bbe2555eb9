"""The native module's hardening, through the binding only: options as one keyword class, options the kernel
cannot honour refused by name, triangle indices never wrapped, read_stl refusing what is not a regular file
at once, and kernel errors arriving as Python exceptions with the kernel's message (never as a crash)."""
from __future__ import annotations

import math
import os
import re
import subprocess
import sys
import threading
import time

import numpy as np
import pytest

from tmm_workbench.core.kernel import native

BIG = 2**32 + 2  # wraps to 2 in int32


def seed_convex() -> "native.PatchSurface":
    cz = [80, 90, 90, 80, 90, 105, 105, 90, 90, 105, 105, 90, 80, 90, 90, 80]
    net = np.array([[(50.0 * i, 50.0 * j, cz[4 * i + j]) for j in range(4)] for i in range(4)])
    return native.PatchSurface.from_net(net)


def options(**kw) -> "native.MultipointOptions":
    return native.MultipointOptions(**{"Ro": 6.7, "Ri": 6.0, **kw})


# --- MultipointOptions / MultipointPositioner(surface, options)

def test_options_default_keyword_and_fields():
    o = native.MultipointOptions()
    assert (o.Ro, o.Ri, o.shape, o.method, o.rotation, o.anchor) == (0.0, 0.0, "round_insert", "vcrf",
                                                                       "pseudo_insert", "axis")
    assert (o.beta_max, o.tol, o.sample_spacing, o.extend) == (math.pi / 4, 1e-3, 0.0, 0.0)
    assert (o.divisions, o.refinements, o.drd_divisions, o.drd_refinements, o.drd_bisections,
            o.anchor_iterations) == (6, 1, 10, 5, 16, 12)
    o = native.MultipointOptions(Ro=3, Ri=1.5, shape="bull_nose", method="drd", anchor="tip", drd_bisections=9)
    assert (o.Ro, o.Ri, o.shape, o.method, o.anchor, o.drd_bisections) == (3.0, 1.5, "bull_nose", "drd", "tip", 9)
    o.rotation = "global_x"
    o.tol = 2e-3
    o.divisions = 8
    assert (o.rotation, o.tol, o.divisions) == ("global_x", 2e-3, 8)
    assert "rotation='global_x'" in repr(o)
    with pytest.raises(ValueError, match=r"shape must be 'round_insert' or 'bull_nose', got 'ball'"):
        o.shape = "ball"
    with pytest.raises(ValueError, match=r"method must be 'vcrf' or 'drd', got 'x'"):
        native.MultipointOptions(method="x")
    with pytest.raises(TypeError):
        native.MultipointOptions(6.7, 6.0)  # keywords only
    with pytest.raises(TypeError):
        native.MultipointOptions(radius=3)


def test_positioner_takes_surface_and_options_only():
    s = seed_convex()
    mp = native.MultipointPositioner(s, options())
    r = mp.position_batch(np.array([[75.0, 75.0]]), 1)
    assert r["status"][0] in (0, 1)
    assert mp.options.Ro == 6.7 and mp.options.method == "vcrf"
    with pytest.raises(TypeError):
        native.MultipointPositioner(s, 6.7, 6.0)  # the old positional constructor is gone


def test_clearance_is_signed_and_refuses_bad_rows_by_name():
    mp = native.MultipointPositioner(seed_convex(), options())
    r = mp.position_batch(np.array([[75.0, 75.0]]), 1)
    tip, axis = r["tip"][0], r["axis"][0]
    c = mp.clearance(np.array([tip, tip + 0.1 * axis, tip - 0.1 * axis]), np.array([axis] * 3), 1)
    assert abs(c[0]) < 1e-6 and c[1] == pytest.approx(0.1, abs=1e-3) and c[2] == pytest.approx(-0.1, abs=1e-3)
    assert np.isinf(mp.clearance(np.array([[900.0, 900.0, 0.0]]), np.array([[0.0, 0.0, 1.0]]))[0])
    with pytest.raises(ValueError, match=r"tips: row 1 is not finite"):
        mp.clearance(np.array([tip, [np.nan, 0, 0]]), np.array([axis, axis]))
    with pytest.raises(ValueError, match=r"axes: row 0 is not a direction"):
        mp.clearance(np.array([tip]), np.array([[0.0, 0.0, 0.0]]))
    with pytest.raises(ValueError, match=r"as many rows"):
        mp.clearance(np.array([tip, tip]), np.array([axis]))
    with pytest.raises(ValueError, match=r"tips must have shape \(n, 3\)"):
        mp.clearance(np.array([tip[:2]]), np.array([axis]))


def test_positions_do_not_depend_on_how_the_options_were_made():
    s = seed_convex()
    xy = np.array([[40.0, 60.0], [75.0, 75.0], [120.0, 30.0]])
    a = native.MultipointPositioner(s, options(method="drd")).position_batch(xy, 1)
    o = options()
    o.method = "drd"
    b = native.MultipointPositioner(s, o).position_batch(xy, 1)
    for k in a:
        np.testing.assert_array_equal(a[k], b[k])


@pytest.mark.parametrize("name", ["Ro", "Ri", "beta_max", "tol", "sample_spacing", "extend"])
@pytest.mark.parametrize("bad", [math.nan, math.inf, -math.inf])
def test_non_finite_options_are_refused_by_name(name, bad):
    with pytest.raises(ValueError, match=rf"{name} must be"):
        native.MultipointPositioner(seed_convex(), options(**{name: bad}))


def test_sample_spacing_too_fine_is_refused_with_the_range():
    for tiny in (1e-300, 1e-6):
        with pytest.raises(ValueError, match=r"sample_spacing .* is finer than this face can be sampled at .* "
                                             r"must be 0 \(auto: \(Ro \+ Ri\) / 8 = 1.5875 mm\) or >= [0-9.]+ mm"):
            native.MultipointPositioner(seed_convex(), options(sample_spacing=tiny))
    # A spacing the face can take is kept.
    assert native.MultipointPositioner(seed_convex(), options(sample_spacing=0.5)).sample_spacing == 0.5


def test_grid_sizes_are_bounded():
    with pytest.raises(ValueError, match=r"divisions must be a whole number in \[1, 1000\], got 100000"):
        native.MultipointPositioner(seed_convex(), options(divisions=100000))


# --- triangle indices

def mesh3():
    return np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0]], float)


@pytest.mark.parametrize("make", [
    lambda V, F: native.MeshIndex(V, F),
    lambda V, F: native.DirectionalIndex(V, F, np.array([0.0, 0.0, -1.0])),
    lambda V, F: native.face_normals(V, F),
    lambda V, F: native.vertex_normals(V, F),
    lambda V, F: native.triangle_adjacency(F),
])
def test_indices_beyond_int32_are_refused_not_wrapped(make):
    V = mesh3()
    for bad in (BIG, -BIG, 2**31):
        F = np.array([[0, 1, bad]], dtype=np.int64)
        with pytest.raises(ValueError, match=rf"triangle 0 refers to vertex {bad}, which does not fit a 32-bit "
                                             rf"index: vertex indices must be in \[0, 2147483647\]"):
            make(V, F)
    with pytest.raises(ValueError, match=r"refers to vertex 18446744073709551615"):
        make(V, np.array([[0, 1, 2**64 - 1]], dtype=np.uint64))
    with pytest.raises(TypeError, match="integer array"):
        make(V, np.array([[0, 1, 2]], dtype=float))
    make(V, np.array([[0, 1, 2]], dtype=np.int64))  # in range: fine from any integer dtype
    make(V, np.array([[0, 1, 2]], dtype=np.uint8))


def test_mesh_index_build_threads():
    V = mesh3()
    F = np.array([[0, 1, 2]], dtype=np.int32)
    assert native.MeshIndex(V, F, threads=1).build_threads == 1
    with pytest.raises(ValueError, match="threads must be >= 0"):
        native.MeshIndex(V, F, threads=-1)


# --- read_stl

def test_read_stl_refuses_a_fifo_at_once(tmp_path):
    fifo = tmp_path / "pipe.stl"
    os.mkfifo(fifo)
    result = {}

    def read():
        try:
            native.read_stl(str(fifo))
        except Exception as exc:  # noqa: BLE001 - the test inspects it
            result["error"] = exc

    t0 = time.monotonic()
    reader = threading.Thread(target=read, daemon=True)
    reader.start()
    reader.join(1.0)
    if reader.is_alive():  # blocked in open(): be the writer so the thread ends, then fail
        os.close(os.open(fifo, os.O_WRONLY))
        reader.join(5.0)
        pytest.fail("read_stl blocked on a FIFO")
    assert time.monotonic() - t0 < 0.5
    assert isinstance(result["error"], native.StlError)
    assert str(result["error"]) == f"{fifo}: not a regular file (a FIFO)"


def test_read_stl_refuses_devices_and_directories(tmp_path):
    with pytest.raises(native.StlError, match=r"^/dev/zero: not a regular file \(a character device\)$"):
        native.read_stl("/dev/zero")
    with pytest.raises(native.StlError, match="is a directory"):
        native.read_stl(str(tmp_path))


# --- kernel errors become Python exceptions

def test_kernel_errors_arrive_with_the_kernels_message():
    with pytest.raises(ValueError, match="minor radius Ri must be > 0: a flat end mill"):
        native.MultipointPositioner(seed_convex(), options(Ri=0.0))
    with pytest.raises(ValueError, match="no surface"):
        native.MultipointPositioner(None, options())
    with pytest.raises(ValueError, match="outside"):
        native.MeshIndex(mesh3(), np.array([[0, 1, 5]], dtype=np.int32))
    with pytest.raises(ValueError, match="footprint points must have shape"):
        native.MultipointPositioner(seed_convex(), options()).position_batch(np.zeros(3), 1)


def test_a_raising_progress_callback_propagates():
    class Stop(Exception):
        pass

    def progress(_fraction):
        raise Stop("from the callback")

    mp = native.MultipointPositioner(seed_convex(), options(method="drd"))
    xy = np.tile([[75.0, 75.0]], (40, 1))
    with pytest.raises(Stop, match="from the callback"):
        mp.position_batch(xy, 2, progress)
    with pytest.raises(native.Cancelled):
        mp.position_batch(xy, 2, lambda _f: False)


def test_patch_index_out_of_range_is_an_error_not_a_crash():
    # In a child process: before the check this read past the patch array (a crash would kill pytest).
    code = ("import sys, numpy as np\n"
            "from tmm_workbench.core.kernel import native\n"
            "s = native.PatchSurface.from_net(np.zeros((2, 2, 3)))\n"
            "for ij in ((1, 0), (0, -1), (100000, 3)):\n"
            "    try:\n"
            "        s.net(*ij)\n"
            "    except IndexError as e:\n"
            "        print(e)\n")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60,
                         env={**os.environ, "PYTHONPATH": os.pathsep.join(sys.path)})
    assert out.returncode == 0, out.stderr
    assert out.stdout.splitlines() == ["patch (1, 0) outside 0..0 x 0..0", "patch (0, -1) outside 0..0 x 0..0",
                                       "patch (100000, 3) outside 0..0 x 0..0"]


# --- the kernel's range: |coordinate| < 1e9 mm (tmm/util/constants.hpp kMaxCoordinate)

RANGE = r"is outside the kernel's range: (values must be finite with \|value\| < |lengths must be in \[0, )1e\+09"


def plate(scale=10.0):
    return np.array([[0, 0, 0], [scale, 0, 0], [0, scale, 0], [scale, scale, 1]], float), \
        np.array([[0, 1, 2], [1, 3, 2]], np.int32)


def far_net(pole):
    net = np.array([[(0.0, 0.0, 0.0), (0.0, 1.0, 0.0)], [(1.0, 0.0, 0.0), (1.0, 1.0, 0.0)]])
    net[1, 1] = pole
    return net


@pytest.mark.parametrize("scale", [1e150, 1e300, -2e9])
@pytest.mark.parametrize("make", [
    lambda V, F: native.MeshIndex(V, F),
    lambda V, F: native.DirectionalIndex(V, F, np.array([0.0, 0.0, -1.0])),
    lambda V, F: native.face_normals(V, F),
    lambda V, F: native.vertex_normals(V, F),
])
def test_meshes_outside_the_range_are_refused_naming_the_vertex(make, scale):
    V, F = plate(scale)
    with pytest.raises(ValueError, match=rf"vertex 1 coordinate x = {re.escape(f'{scale:g}')} {RANGE}"):
        make(V, F)


@pytest.mark.parametrize("call, message", [
    (lambda: native.weld(np.array([[0, 0, 0, 1e150, 0, 0, 0, 1, 0]], float), 1e-6),
     "triangle 0 corner 1 coordinate x = 1e\\+150 "),
    (lambda: native.PatchSurface.from_net(far_net((1e300, 1e300, 0.0))), "Bezier pole 3 coordinate x = 1e\\+300 "),
    (lambda: native.Cutter(1e10, 0.0), "cutter radius = 1e\\+10 "),
    (lambda: native.ZMap(1e300, 0.0, 1.0, 10, 10, 0.0), "z-map x0 = 1e\\+300 "),
    (lambda: native.drop_cutter(native.MeshIndex(*plate()), native.Cutter(1.0, 1.0), np.array([[5.0, 1e150]]), 0.0),
     r"points row 0 \(5, 1e\+150\) "),
    (lambda: native.drop_cutter(native.MeshIndex(*plate()), native.Cutter(1.0, 1.0), np.array([[5.0, 5.0]]), 1e300),
     "floor_z = 1e\\+300 "),
    (lambda: native.cut_5axis(native.ZMap(0.0, 0.0, 1.0, 10, 10, 5.0), 1.0, 1.0, "round_insert",
                              np.array([[0.0, 0.0, 0.0], [1e150, 0.0, 0.0]]), np.array([[0.0, 0.0, 1.0]] * 2),
                              np.array([0])), r"tips row 1 \(1e\+150, 0, 0\) "),
    (lambda: native.MultipointPositioner(seed_convex(), options(Ri=1e300)), "minor radius Ri = 1e\\+300 "),
])
def test_inputs_outside_the_range_are_refused_by_name(call, message):
    with pytest.raises(ValueError, match=message + RANGE):
        call()


def test_a_nan_floor_is_refused_by_name():
    from tmm_workbench.core.errors import TmmError
    from tmm_workbench.core.geometry.mesh import TriMesh
    from tmm_workbench.core.query.drop import DropSurface
    from tmm_workbench.core.tools.cutter import Cutter
    V, F = plate()
    with pytest.raises(ValueError, match="floor_z = nan "):
        native.drop_cutter(native.MeshIndex(V, F), native.Cutter(1.0, 1.0), np.array([[5.0, 5.0]]), math.nan)
    surface = DropSurface(TriMesh(V, F, "plate"))
    with pytest.raises(TmmError, match="drop floor_z is NaN"):
        surface.drop(Cutter.ball(2), np.array([[5.0, 5.0]]), math.nan)


def run_child(code: str, limit_bytes: int = 0) -> "subprocess.CompletedProcess[str]":
    """code in a child Python (a crash or a huge allocation must not take pytest down), allocations limited:
    by the address space, or under AddressSanitizer (which reserves terabytes of it) by its allocator."""
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(sys.path)}
    prefix = "import resource\n"
    if limit_bytes and "asan" in env.get("LD_PRELOAD", ""):
        env["ASAN_OPTIONS"] = (env.get("ASAN_OPTIONS", "") + f":max_allocation_size_mb={limit_bytes >> 20}"
                               ":allocator_may_return_null=1")
    elif limit_bytes:
        prefix += f"resource.setrlimit(resource.RLIMIT_AS, ({limit_bytes}, {limit_bytes}))\n"
    return subprocess.run([sys.executable, "-c", prefix + code], capture_output=True, text=True, timeout=120,
                          env=env)


def test_adjacency_of_a_huge_index_allocates_by_the_triangles():
    # 2^31 - 1 used to size an 8.4 GB table before anything failed; 1.5 GB of address space is plenty now.
    out = run_child("import numpy as np\n"
                    "from tmm_workbench.core.kernel import native\n"
                    "F = np.array([[0, 1, 2**31 - 1], [1, 0, 7]], np.int64)\n"
                    "print(native.triangle_adjacency(F).tolist())\n", limit_bytes=1_500_000_000)
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip() == "[[1, -1, -1], [0, -1, -1]]"


def test_lean_samples_near_1e307_are_refused_not_a_crash():
    # Two triangles meeting between adjacent doubles near 1e307 made the refinement recurse until the stack
    # overflowed (SIGSEGV).
    out = run_child("import numpy as np\n"
                    "from tmm_workbench.core.kernel import native\n"
                    "X, D = 1e307, 1e300\n"
                    "V = np.array([[X-D,0,0],[X,0,0],[X,10,0],[X-D,10,0],[X+D,0,5],[X+D,10,5]])\n"
                    "F = np.array([[0,1,2],[0,2,3],[1,4,5],[1,5,2]], np.int32)\n"
                    "idx = native.MeshIndex(np.array([[0,0,0],[10,0,0],[0,10,0]], float), F[:1])\n"
                    "u = np.spacing(X)\n"
                    "try:\n"
                    "    idx = native.MeshIndex(V, F)\n"
                    "except ValueError as e:\n"
                    "    print(e)\n"
                    "s = np.array([X - 4 * u, X + 4 * u])\n"
                    "try:\n"
                    "    native.lean_profiles(idx, native.Cutter(1.0, 1.0), np.array([[0.0, 5.0]]),\n"
                    "        np.array([[1.0, 0.0]]), np.array([0, 2]), s, np.array([-1e6, -1e6]),\n"
                    "        np.zeros(2, np.uint8), tol=0.01, max_step=1e300)\n"
                    "except ValueError as e:\n"
                    "    print(e)\n")
    assert out.returncode == 0, out.stderr
    lines = out.stdout.splitlines()
    assert len(lines) == 2 and all("is outside the kernel's range" in line for line in lines), out.stdout
    assert lines[1].startswith("lean runs: s of run 0, sample row 0 (1e+307)")


@pytest.mark.parametrize("bad", [math.nan, 1e300])
def test_a_stock_cell_outside_the_range_is_refused_by_both_simulations(bad):
    stock = native.ZMap(0.0, 0.0, 1.0, 10, 10, 5.0)
    stock.heights[3, 2] = bad
    tips, kinds = np.array([[1.0, 1.0, 0.0], [8.0, 8.0, 0.0]]), np.array([0])
    with pytest.raises(ValueError, match=rf"stock cell \(2, 3\) height {re.escape(f'{bad:g}')} {RANGE}"):
        native.cut_3axis(stock, native.Cutter(1.0, 1.0), tips, kinds)
    with pytest.raises(ValueError, match=rf"stock cell \(2, 3\) height {re.escape(f'{bad:g}')} {RANGE}"):
        native.cut_5axis(stock, 1.0, 1.0, "round_insert", tips, np.array([[0.0, 0.0, 1.0]] * 2), kinds)
