"""For benchmarks/rest_linking.py --ops: the inputs of a planned Job's rest, pencil and clean-up ops (the Surface
op's call of core.strategies.finish_passes.compute_finish_toolpath: mesh, cutter, params, finish, link policy with
the earlier ops' stock), each pickled as it is recomputed in FreeCAD, so the core can run them again alone; and each op's time between cuts as the code now makes it (the table of
benchmarks/rest_linking.py, its tool controller's feeds, rapids 5000 mm/min).

    HOME=/tmp/home-<name> TMM_DUMP_DOC=out/plan/sign/sign.FCStd TMM_DUMP_OUT=/tmp/sign_ops freecadcmd \
        benchmarks/rest_linking_dump.py
"""
import copyreg
import os
import pickle
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

import FreeCAD  # noqa: E402

from benchmarks.rest_linking import HEAD, OpLinks, measure, row, toolpath_moves  # noqa: E402
from tmm_workbench.app import op_surface  # noqa: E402
from tmm_workbench.core.linking import StockHeights  # noqa: E402
from tmm_workbench.core.tools.cutter import Cutter  # noqa: E402

PREFIXES = ("Rest", "Pencil", "Clean-up")
RAPID = 5000.0   # mm/min, the planner's cycle estimate's


def _pickled_natively() -> None:
    """The cutter and the stock heights pickled by what makes them (their kernel objects and closures are not)."""
    copyreg.pickle(Cutter, lambda c: (Cutter, (c.diameter, c.corner_radius, c.bottom_angle_deg, c.taper_angle_deg,
                                               c.cutting_length)))
    copyreg.pickle(StockHeights, lambda s: (StockHeights, (s.grid, s.heights, s.cutter)))


def main() -> None:
    _pickled_natively()
    out = Path(os.environ["TMM_DUMP_OUT"])
    out.mkdir(parents=True, exist_ok=True)
    doc = FreeCAD.openDocument(str(Path(os.environ["TMM_DUMP_DOC"]).resolve()))
    original = op_surface.finish_passes.compute_finish_toolpath
    current = {}

    def dump(mesh, cutter, params, finish, policy, progress=None, surface=None):
        with open(out / f"{current['name']}.pkl", "wb") as f:
            pickle.dump({"label": current["label"], "mesh": mesh, "cutter": cutter, "params": params,
                         "finish": finish, "policy": policy}, f)
        return original(mesh, cutter, params, finish, policy, progress, surface)

    op_surface.finish_passes.compute_finish_toolpath = dump
    ops = [obj for obj in doc.Objects if obj.Label.startswith(PREFIXES) and hasattr(obj, "Region")]
    print(HEAD)
    for obj in sorted(ops, key=lambda o: -PREFIXES.index(o.Label.split()[0])):   # the clean-up first
        current.update(name=obj.Name, label=obj.Label)
        t0 = time.perf_counter()
        obj.Proxy.execute(obj)
        tc = obj.ToolController
        moves = toolpath_moves(obj.Proxy.toolpath, float(tc.HorizFeed.Value) * 60, float(tc.VertFeed.Value) * 60)
        row(measure(OpLinks(f"{obj.Label} (now)", moves=moves), RAPID))
        print(f"  computed in {time.perf_counter() - t0:.0f} s with the code as it is now", flush=True)


main()
