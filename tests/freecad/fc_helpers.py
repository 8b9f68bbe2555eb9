"""Shared helpers of the FreeCAD-side tests: scratch folder, small STL files, Jobs with a TMM op,
G-code parsing."""
from __future__ import annotations

import math
import os
import re
import tempfile
import unittest
from pathlib import Path
from typing import Any, Iterable, Optional

import FreeCAD
import Mesh

from tmm_workbench.app import job as jobs
from tmm_workbench.app import tools
from tmm_workbench.app import op_surface, posts
from tmm_workbench.core.shared_data import shared_dir

posts.install_post_dir()  # Init.py does it when the add-on is linked into FreeCAD's Mod folder

BENCH_STL = shared_dir() / "benchmarks" / "stl"
SPHERE_ON_PLATE = BENCH_STL / "sphere_on_plate.stl"
OUT = Path(os.environ.get("TMM_TEST_OUT") or tempfile.mkdtemp(prefix="tmm_fc_"))
OUT.mkdir(parents=True, exist_ok=True)

Triangle = tuple[tuple[float, float, float], tuple[float, float, float], tuple[float, float, float]]


def bump_triangles(n: int = 16, size: float = 20.0, height: float = 5.0) -> list[Triangle]:
    """A smooth bump z = h exp(-r^2/40) over [-size/2, size/2]^2, 2 n^2 triangles."""
    h = size / n
    z = lambda x, y: height * math.exp(-(x * x + y * y) / 40.0)  # noqa: E731
    tris: list[Triangle] = []
    for i in range(n):
        for j in range(n):
            x0, y0 = -size / 2 + i * h, -size / 2 + j * h
            a = (x0, y0, z(x0, y0))
            b = (x0 + h, y0, z(x0 + h, y0))
            c = (x0 + h, y0 + h, z(x0 + h, y0 + h))
            d = (x0, y0 + h, z(x0, y0 + h))
            tris += [(a, b, c), (a, c, d)]
    return tris


def write_ascii_stl(path: Path, tris: Iterable[Triangle], name: str = "tmm") -> Path:
    lines = [f"solid {name}"]
    for t in tris:
        lines += ["  facet normal 0 0 1", "    outer loop"]
        lines += [f"      vertex {p[0]} {p[1]} {p[2]}" for p in t]
        lines += ["    endloop", "  endfacet"]
    lines.append(f"endsolid {name}")
    path.write_text("\n".join(lines) + "\n")
    return path


def mesh_stl(mesh: Any, name: str) -> str:
    """A core TriMesh written as OUT/<name>.stl (ASCII); its path."""
    tris = [tuple(tuple(map(float, mesh.vertices[i])) for i in f) for f in mesh.triangles]
    return str(write_ascii_stl(OUT / f"{name}.stl", tris, name))


def bump_stl() -> Path:
    path = OUT / "bump.stl"
    if not path.exists():
        write_ascii_stl(path, bump_triangles())
    return path


def new_doc(name: str = "TmmTest") -> Any:
    doc = FreeCAD.newDocument(name)
    FreeCAD.setActiveDocument(doc.Name)
    return doc


def close_all() -> None:
    for name in list(FreeCAD.listDocuments()):
        FreeCAD.closeDocument(name)


def mesh_feature(doc: Any, tris: list[Triangle], name: str = "Bump") -> Any:
    obj = doc.addObject("Mesh::Feature", name)
    obj.Mesh = Mesh.Mesh([list(p) for t in tris for p in t])
    doc.recompute()
    return obj


def job_with_op(doc: Any, model: Any, shape: str = "ballend", diameter: float = 4.0,
                corner_radius: float = 0.0, horiz_mm_min: float = 1200.0, vert_mm_min: float = 240.0,
                values: Optional[dict[str, Any]] = None) -> tuple[Any, Any, Any]:
    """(job, tool controller, op) for `model` (STL path, mesh or Part object), recomputed."""
    jm = jobs.prepare_model(doc, model)
    doc.recompute()
    job = jobs.create_job(doc, jm.job_base)
    bit = tools.make_tool_bit(doc, shape, diameter, corner_radius)
    tc = jobs.set_tool(job, bit, horiz_mm_min / 60, vert_mm_min / 60, 12000)
    vals = {"StepOver": 2.0, "SampleStep": 1.0}
    vals.update({"StlFile": jm.stl_file} if jm.stl_file else {"Model": jm.link})
    vals.update(values or {})
    op = op_surface.Create(op_surface.OP_NAME, parentJob=job, values=vals)
    op.Proxy.progress_enabled = False
    doc.recompute()
    return job, tc, op


def moves(op: Any) -> list[tuple[str, dict[str, float]]]:
    """(G-word, parameters) of the op's motion commands."""
    return [(c.Name, dict(c.Parameters)) for c in op.Path.Commands if c.Name in ("G0", "G1")]


_WORD = re.compile(r"([A-Z])\s*(-?\d+(?:\.\d*)?)")


def parse_gcode(text: str) -> list[tuple[str, float, float, float, Optional[float]]]:
    """(G0|G1, x, y, z, f) for every motion line, with modal X/Y/Z/F carried over; comments,
    line numbers and other lines skipped."""
    pos = {"X": math.nan, "Y": math.nan, "Z": math.nan}
    feed: Optional[float] = None
    motion = None
    out = []
    for raw in text.splitlines():
        line = re.sub(r"\(.*?\)|;.*$", "", raw).strip().upper()
        if not line:
            continue
        words = _WORD.findall(line)
        gs = [int(float(v)) for k, v in words if k == "G"]
        if any(g in (0, 1) for g in gs):
            motion = "G0" if 0 in gs else "G1"
        elif gs or not any(k in pos for k, _ in words):
            continue
        for k, v in words:
            if k in pos:
                pos[k] = float(v)
            elif k == "F":
                feed = float(v)
        if motion is not None:
            out.append((motion, pos["X"], pos["Y"], pos["Z"], feed if motion == "G1" else None))
    return out



def reopened(doc: Any, obj: Any, filename: str) -> Any:
    """`obj`, from its document saved as OUT/`filename`, closed (with every other) and opened again; its new
    document is `.Document`."""
    path = OUT / filename
    doc.saveAs(str(path))
    name = obj.Name
    close_all()
    return FreeCAD.openDocument(str(path)).getObject(name)

# A test whose outcome depends on TMM's core, not on FreeCAD's version: what it does through FreeCAD (a Job, an op,
# save and reopen) other tests of its module do on every version, its weight is the core's computing. It runs on
# the host's FreeCAD; scripts/env_test.sh (FreeCAD 1.0 and 1.1) sets TMM_FC_VERSIONED=1, and fc_runner leaves it out.
CORE_WORK = "_tmm_core_work"


def core_work(test: Any) -> Any:
    """Marks `test` as core work done through FreeCAD (see CORE_WORK)."""
    setattr(test, CORE_WORK, True)
    return test


class FreeCADTestCase(unittest.TestCase):
    def tearDown(self) -> None:
        close_all()


class BadInputCase(FreeCADTestCase):
    """An op (`self.doc`, `self.op`, made valid by setUp) recomputed with a bad value must fail at once: invalid,
    its status naming what is wrong, no path left (partial or stale)."""

    doc: Any
    op: Any
    FAIL_SECONDS = 5.0   # the default time allowed for the refusal

    def assertFails(self, *fragments: str, seconds: Optional[float] = None) -> str:
        import time

        t0 = time.perf_counter()
        self.op.touch()
        self.doc.recompute()
        self.assertLess(time.perf_counter() - t0, self.FAIL_SECONDS if seconds is None else seconds)
        status = self.op.getStatusString()
        self.assertFalse(self.op.isValid(), "op should be invalid")
        for f in fragments:
            self.assertIn(f.lower(), status.lower())
        self.assertEqual(len(self.op.Path.Commands), 0, "no partial or stale path")
        self.assertIsNone(self.op.Proxy.toolpath)
        return status


def seed_net():
    """Seed 001's convex Bézier control net (the 5-axis tests' face)."""
    from tmm_workbench.core.geometry import bezier
    from tmm_workbench.core.shared_data import benchmark_file

    return bezier.load_seed_patch(benchmark_file("seed_surfaces.json"), "convex")
