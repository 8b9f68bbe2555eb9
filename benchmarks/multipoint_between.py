"""Between multipoint positions on seed 001's three patches (core.strategies.multipoint_refine): for the
seed footprint (side step 18 mm Fixed) at forward steps 2 and 8 mm, without the check (between_tol 0) and
with it (0.005 mm): positions, inserted, still out of tolerance, the whole compute's time, and the deepest
cut and widest chord gap along the moves measured independently (tests/core/swept.py: worst_between, face
samples 0.25 mm apart, instances 0.5 mm apart).

    .venv/bin/python benchmarks/multipoint_between.py
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
from tmm_workbench.core.strategies import multipoint  # noqa: E402
from tmm_workbench.core.strategies.multipoint import MultipointParams, make_positioner  # noqa: E402
from tmm_workbench.core.tools.cutter import Cutter  # noqa: E402
from tests.core import swept  # noqa: E402

RO, RI = 6.7, 6.0


def patch(name: str) -> BezierFace:
    net = bezier.load_seed_patch(benchmark_file("seed_surfaces.json"), name)
    return BezierFace.from_net(net)


def main() -> None:
    print("| patch | forward mm | tolerance mm | positions | inserted | out of tol | compute s | deepest cut mm "
          "| widest gap mm |")
    print("|---|---|---|---|---|---|---|---|---|")
    tool = Cutter.torus(RO, RI)
    for name in ("convex", "concave", "saddle"):
        face = patch(name)
        positioner = make_positioner(face, RO, RI)
        samples = swept.FaceSamples.of(face, 0.25)
        for forward in (2.0, 8.0):
            for tol in (0.0, 0.005):
                params = MultipointParams(side_step=18.0, pass_spacing="fixed", forward_step=forward, between_tol=tol)
                t0 = time.perf_counter()
                result = multipoint.compute(face, tool, params)
                seconds = time.perf_counter() - t0
                report = result.diagnostics.get("between") or {}
                cut, gap = swept.worst_between(positioner, samples, RO + 2 * RI + 1.0, result.segments)
                print(f"| {name} | {forward:g} | {tol:g} | {sum(len(s) for s in result.segments)} | "
                      f"{report.get('inserted', 0)} | {report.get('remaining', 0)} | {seconds:.2f} | {cut:.4f} | "
                      f"{gap:.4f} |")


if __name__ == "__main__":
    main()
