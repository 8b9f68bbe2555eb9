"""The scallop rule's placement (core.strategies.multipoint_scallop) on seed 001's patches, random nets (4 x 4
poles 50 mm apart, z 70-100, the seed's torus Ro 6.7 Ri 6) and 12 mm nets (random nets scaled by 12/150, torus
Ro 2 Ri 1, forward step 0.5 mm): passes, areas reported (not reached / over scallop), the largest scallop
measured on the rows held, trial passes, compute seconds (CPU of the process, and wall). One JSON line a case.

    OPENBLAS_NUM_THREADS=1 .venv/bin/python benchmarks/scallop_placement.py [case ...]

MS_MODULE=<path to another multipoint_scallop.py> measures that version of the placement instead (a former
one, for before/after figures).
"""
from __future__ import annotations

import importlib.util
import json
import os
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

if os.environ.get("MS_MODULE"):
    import tmm_workbench.core.strategies as _strategies  # noqa: E402

    _spec = importlib.util.spec_from_file_location("tmm_workbench.core.strategies.multipoint_scallop",
                                                   os.environ["MS_MODULE"])
    _module = importlib.util.module_from_spec(_spec)
    sys.modules[_spec.name] = _module
    _spec.loader.exec_module(_module)
    _strategies.multipoint_scallop = _module

from tests.conftest import SEED_JSON, random_net  # noqa: E402
from tmm_workbench.core.geometry import bezier  # noqa: E402
from tmm_workbench.core.geometry.face import BezierFace  # noqa: E402
from tmm_workbench.core.strategies import multipoint  # noqa: E402
from tmm_workbench.core.strategies.multipoint import MultipointParams  # noqa: E402
from tmm_workbench.core.tools.cutter import Cutter  # noqa: E402

BIG, SMALL = Cutter.torus(6.7, 6.0), Cutter.torus(2.0, 1.0)
BOX = (30.0, 40.0, 85.0, 70.0)


def seed(which: str):
    return lambda: bezier.load_seed_patch(SEED_JSON, which)


def small(n: int):
    return lambda: random_net(n) * (12.0 / 150.0)


# name: (net, tool, scallop mm, boundary (None: the face), forward step mm, shape)
CASES = {
    "convex 0.3 box": (seed("convex"), BIG, 0.3, BOX, 2.0, "round_insert"),
    "convex bull 0.05 box": (seed("convex"), BIG, 0.05, (30.0, 40.0, 50.0, 70.0), 2.0, "bull_nose"),
    "concave 0.05 box": (seed("concave"), BIG, 0.05, BOX, 2.0, "round_insert"),
    "saddle 0.01 edge": (seed("saddle"), BIG, 0.01, (0.0, 100.0, 6.0, 150.0), 2.0, "round_insert"),
    "saddle 0.05 box": (seed("saddle"), BIG, 0.05, BOX, 2.0, "round_insert"),
    "random1 0.01 edge": (lambda: random_net(1), BIG, 0.01, (0.0, 0.0, 6.0, 60.0), 2.0, "round_insert"),
    "random2 0.05 box": (lambda: random_net(2), BIG, 0.05, BOX, 2.0, "round_insert"),
    "random3 0.05 box": (lambda: random_net(3), BIG, 0.05, BOX, 2.0, "round_insert"),
    "small1 0.01": (small(1), SMALL, 0.01, None, 0.5, "round_insert"),
    "small2 0.01": (small(2), SMALL, 0.01, None, 0.5, "round_insert"),
    "small3 0.02": (small(3), SMALL, 0.02, None, 0.5, "round_insert"),
    "saddle 0.01": (seed("saddle"), BIG, 0.01, None, 2.0, "round_insert"),
    "convex 0.05": (seed("convex"), BIG, 0.05, None, 2.0, "round_insert"),
    "random1 0.05": (lambda: random_net(1), BIG, 0.05, None, 2.0, "round_insert"),
    "random2 0.02": (lambda: random_net(2), BIG, 0.02, None, 2.0, "round_insert"),
}


def run(name: str) -> dict:
    make, tool, h, box, forward, shape = CASES[name]
    params = MultipointParams(pass_spacing="scallop", scallop=h, side_step=18.0 if tool is BIG else 1.0,
                              forward_step=forward, boundary=box, between_tol=0.0, shape=shape)
    cpu, wall = time.process_time(), time.time()
    rep = multipoint.compute(BezierFace.from_net(make()), tool, params).diagnostics["scallop"]
    held = [v for v in rep.scallops[1:] if v <= h]
    return {"case": name, "passes": len(rep.offsets),
            "not_reached": sum(a.reason == "not reached" for a in rep.unreached),
            "over_scallop": sum(a.reason == "over scallop" for a in rep.unreached),
            "rows_reported": sum(a.rows for a in rep.unreached), "max_held": round(max(held, default=0.0), 5),
            "max": round(rep.max_scallop, 4), "trials": rep.trials,
            "cpu_s": round(time.process_time() - cpu, 1), "wall_s": round(time.time() - wall, 1)}


if __name__ == "__main__":
    for case in sys.argv[1:] or list(CASES):
        print(json.dumps(run(case)), flush=True)
