"""For benchmarks/rest_linking.py --ops: the inputs of a planned Job's rest, pencil and clean-up ops (the Surface
op's call of core.strategies.finish_passes.compute_finish_toolpath: mesh, cutter, params, finish, link policy with
the earlier ops' stock), each pickled as it is recomputed in FreeCAD, so the core can run them again alone.

    HOME=/tmp/home-<name> TMM_DUMP_DOC=out/plan/sign/sign.FCStd TMM_DUMP_OUT=/tmp/sign_ops freecadcmd \
        benchmarks/rest_linking_dump.py
"""
import copyreg
import os
import pickle
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

import FreeCAD  # noqa: E402

from tmm_workbench.app import op_surface  # noqa: E402
from tmm_workbench.core.linking import StockHeights  # noqa: E402
from tmm_workbench.core.tools.cutter import Cutter  # noqa: E402

PREFIXES = ("Rest", "Pencil", "Clean-up")


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
    for obj in doc.Objects:
        if obj.Label.startswith(PREFIXES) and hasattr(obj, "Region"):
            current.update(name=obj.Name, label=obj.Label)
            obj.Proxy.execute(obj)
            print(f"dumped {obj.Label} ({obj.Name}): {len(obj.Path.Commands)} commands", flush=True)


main()
