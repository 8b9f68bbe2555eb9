"""Tarus G-code of seed 001's three patches seen by the machine (tests/core/machine_view.py): A range and travel,
the largest A step, the tip's deviation from the straight line under linear joint interpolation, lines the
joints cannot do in their programmed time, cycle time; joint mode and TCP mode.

    .venv/bin/python benchmarks/tarus_machine_view.py                       # this checkout's post
    .venv/bin/python benchmarks/tarus_machine_view.py --post-tree /tmp/old  # another checkout's post (before)

The tool paths come from this checkout (VCRF, seed footprint: side step 18 mm Fixed, forward step 2 mm,
torus Ro 6.7 Ri 6, linked along the tool axis: safe height 5 mm above the face, retract 5 mm; --no-refine:
without the positions inserted between (GougeTolerance 0)); only the post (tarus_writer and the machine
model) comes from --post-tree. The machine view is this checkout's.
"""
from __future__ import annotations

import argparse
import importlib
import math
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from tmm_workbench.core import path5  # noqa: E402
from tmm_workbench.core.geometry import bezier  # noqa: E402
from tmm_workbench.core.post import ToolInfo  # noqa: E402
from tmm_workbench.core.shared_data import benchmark_file  # noqa: E402
from tmm_workbench.core.strategies.multipoint import (BezierFace, MultipointParams,  # noqa: E402
                                                      compute_multipoint_toolpath, face_top, link_policy,
                                                      make_positioner)
from tmm_workbench.core.tools.cutter import Cutter  # noqa: E402
from tests.core import machine_view, swept  # noqa: E402

TOOL = ToolInfo(number=1, label="bull-nose D25.4 r6", shape="bullnose", diameter=25.4, corner_radius=6.0,
                cutting_height=30.0, spindle_rpm=10000, spindle_dir="CW")




def seed_net(which: str):
    """Seed 001's convex, concave and saddle (table 1) nets."""
    return bezier.load_seed_patch(benchmark_file("seed_surfaces.json"), which)


def post_modules(tree: Path | None):
    """tarus_writer and TarusMachine of `tree` (its own tmm_workbench package), else of this checkout."""
    if tree is None:
        from tmm_workbench.core import post
        from tmm_workbench.core.machine.tarus import TarusMachine
        from tmm_workbench.core.post import tarus_writer
        return tarus_writer, TarusMachine, post
    saved = {k: v for k, v in sys.modules.items() if k == "tmm_workbench" or k.startswith("tmm_workbench.")}
    for k in saved:
        del sys.modules[k]
    sys.path.insert(0, str(tree))
    try:
        writer = importlib.import_module("tmm_workbench.core.post.tarus_writer")
        machine = importlib.import_module("tmm_workbench.core.machine.tarus").TarusMachine
        post = importlib.import_module("tmm_workbench.core.post")
    finally:
        sys.path.remove(str(tree))
        for k in [k for k in sys.modules if k == "tmm_workbench" or k.startswith("tmm_workbench.")]:
            del sys.modules[k]
        sys.modules.update(saved)
    return writer, machine, post


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--post-tree", type=Path, help="a checkout whose post to use")
    ap.add_argument("--no-refine", action="store_true", help="no positions inserted between positions")
    args = ap.parse_args()
    paths, gouges = {}, {}
    tool = Cutter.torus(6.7, 6.0)
    for which in ("convex", "concave", "saddle"):
        face = BezierFace.from_net(seed_net(which))
        safe = face_top(face) + 5.0
        params = MultipointParams(side_step=18.0, pass_spacing="fixed", forward_step=2.0,
                                  between_tol=0.0 if args.no_refine else 0.005)
        tp, res = compute_multipoint_toolpath(face, tool, params,
                                              link_policy(tool, safe, safe + 5.0, 5.0))
        paths[which] = path5.encode_toolpath(tp, 1000 / 60, 300 / 60)
        gouges[which] = swept.FaceGouge(make_positioner(face, 6.7, 6.0, MultipointParams()), face, 6.7 + 13.0)
    writer, Machine, post = post_modules(args.post_tree)
    view_machine = post_modules(None)[1](a_limits=None)  # the view reads A as written
    print(f"post from {args.post_tree or ROOT}")
    print("| patch | mode | lines | A range deg | A travel deg | largest A step deg | tip deviation mm | "
          "too fast | deepest cut mm | cycle time s | post s |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    tool = post.ToolInfo(**{k: getattr(TOOL, k) for k in TOOL.__dataclass_fields__})
    for which, commands in paths.items():
        program = [tool, post.Operation(which, commands)]
        for tcp in (False, True):
            t0 = time.perf_counter()
            m = Machine()
            opts = writer.TarusOptions(tcp=tcp)
            try:
                text = writer.write_tarus(program, m, opts).text
            except Exception as exc:  # noqa: BLE001 - a refusal is a result here
                print(f"| {which} | {'TCP' if tcp else 'joints'} | refused: {exc} |")
                continue
            seconds = time.perf_counter() - t0
            v = machine_view.view(view_machine, text, tcp=tcp, depth=gouges[which])
            print(f"| {which} | {'TCP' if tcp else 'joints'} | {v.lines} | {math.degrees(v.a_min):.1f}.."
                  f"{math.degrees(v.a_max):.1f} | {math.degrees(v.a_travel):.0f} | "
                  f"{math.degrees(v.largest_a_step):.1f} | {v.largest_tip_deviation:.4f} | {len(v.too_fast)} | "
                  f"{v.deepest_cut:.4f} | "
                  f"{v.cycle_time:.0f} | {seconds:.2f} |")


if __name__ == "__main__":
    main()
