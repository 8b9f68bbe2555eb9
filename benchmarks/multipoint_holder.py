"""The whole tool on multipoint paths (core.strategies.multipoint_holder): the compute's time without a holder
and with one, what the guard did, on the wall face of tests/core/test_multipoint_holder.py (a floor beside an
80 mm wall, D10 R3 torus, ER32 nut on a 16 mm stick-out; passes into the wall and along it) and on seed 001's
convex patch (the seed's torus, an ER32 nut on a 40 mm stick-out: nothing comes close, the check's cost alone).
One run each (the machine is shared: the ratio is what to read).

    .venv/bin/python benchmarks/multipoint_holder.py
"""
from __future__ import annotations

import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from tmm_workbench.core.geometry import bezier  # noqa: E402
from tmm_workbench.core.geometry.face import BezierFace  # noqa: E402
from tmm_workbench.core.shared_data import benchmark_file  # noqa: E402
from tmm_workbench.core.strategies.multipoint import MultipointParams, compute  # noqa: E402
from tmm_workbench.core.tools.assembly import ToolAssembly  # noqa: E402
from tmm_workbench.core.tools.cutter import Cutter  # noqa: E402
from tests.core.test_multipoint_holder import CUTTER, assembly, params, wall_face  # noqa: E402


def timed(face, cutter, p):
    t0 = time.perf_counter()
    result = compute(face, cutter, p)
    return time.perf_counter() - t0, result


def row(label, face, cutter, asm, base) -> None:
    bare_s, bare = timed(face, cutter, MultipointParams(**base))
    held_s, held = timed(face, cutter, MultipointParams(**base, assembly=asm))
    rep = held.diagnostics["holder"]
    positions = sum(len(s) for s in bare.segments)
    print(f"| {label} | {positions} | {bare_s:.2f} s | {held_s:.2f} s | {held_s / bare_s:.1f} | "
          f"{sum(rep.pieces.values())} | {rep.tilted} | {rep.inserted} | {len(rep.unreachable)} | {rep.split_moves} |")


def main() -> None:
    print("| case | positions | without holder | with holder | ratio | too close | tilted | inserted | "
          "unreachable | moves left out |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    face = wall_face()
    for angle in (0.0, 90.0):
        base = {k: v for k, v in vars(params(feed_angle_deg=angle)).items()
                if k in ("side_step", "forward_step", "pass_spacing", "beta_max_deg", "feed_angle_deg")}
        row(f"wall, passes at {angle:g} deg", face, CUTTER, assembly(), base)
    seed = BezierFace.from_net(bezier.load_seed_patch(benchmark_file("seed_surfaces.json"), "convex"))
    torus = Cutter.torus(6.7, 6.0)
    far = ToolAssembly(torus, shank_diameter=20, stick_out=40, flute_length=15, holder="ER32 nut")
    row("seed convex, side step 18", seed, torus, far, dict(side_step=18.0, forward_step=2.0, pass_spacing="fixed"))


if __name__ == "__main__":
    main()
