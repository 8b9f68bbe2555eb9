"""Where a planned Job's time between cuts goes, per op, from its G-code (`tmm plan`'s <name>.ngc): the cutting,
the entries (fed straight down after a rapid: the plunges), the fed moves straight up, and the rapids (count,
length, time; the lifts to the op's top height, the hops below it). A rest, pencil or clean-up op is a scatter
of pieces: its linking is what this measures.

    .venv/bin/python benchmarks/rest_linking.py out/plan/sign [out/plan/wheel_in_box ...] [--rapid 5000]
    OPENBLAS_NUM_THREADS=1 .venv/bin/python benchmarks/rest_linking.py --ops /tmp/sign_ops [--feed 960 --plunge 320]
        [--set rest_joins.JOIN_MM=2 ...]

--ops: the rest, pencil and clean-up ops of a planned Job computed again in the core alone, from their inputs
pickled by benchmarks/rest_linking_dump.py (under freecadcmd), with the code as it is now: the same table from
their tool paths (feed and plunge rates as given: the tool's, from the report), the compute's wall seconds, and
their checks (--set: a constant of a core.strategies module changed for the run, to compare): the deepest cut into the model along every fed move (the kernel's drop, core.verify.linear_moves),
the rapids that meet the stock (the simulation from the earlier ops' stock) and the simulated deviation's low.

Times: each fed move its length at its F; each rapid its slowest axis at the rapid rate (mm/min, XY and Z alike,
the planner's default 5000), as core.sim.cycle_time times them. The operation comments the posts write split the
program ("(begin operation: <label>)" or "(operation: <label>)").
"""
from __future__ import annotations

import math
import re
import sys
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

WORD = re.compile(r"([A-Z])\s*([-+]?\d*\.?\d+)")
OP_COMMENT = re.compile(r"\((?:begin )?operation:\s*(.+?)\)", re.IGNORECASE)


@dataclass
class OpLinks:
    label: str
    cut_mm: float = 0.0
    cut_s: float = 0.0
    plunges: int = 0            # fed straight down right after a rapid: the entries
    plunge_mm: float = 0.0
    plunge_s: float = 0.0
    down_mm: float = 0.0        # fed straight down inside the cut (a pass down a wall), counted in cut
    up_mm: float = 0.0          # fed straight up, counted in cut
    rapids: int = 0
    rapid_mm: float = 0.0
    rapid_s: float = 0.0
    lifts: int = 0              # rapids straight up to the op's top height: full retracts
    hops: int = 0               # rapids straight up that stay below it
    top: float = -math.inf
    moves: list = field(default_factory=list, repr=False)

    @property
    def link_s(self) -> float:
        return self.plunge_s + self.rapid_s

    @property
    def total_s(self) -> float:
        return self.cut_s + self.link_s


def parse(text: str) -> list[OpLinks]:
    """The ops of a program with their moves: (kind 0 rapid / 1 feed, x0, y0, z0, x1, y1, z1, F mm/min)."""
    ops: list[OpLinks] = []
    pos = [0.0, 0.0, 0.0]
    mode, feed = 0, 0.0
    for raw in text.splitlines():
        line = raw.strip().upper()
        m = OP_COMMENT.search(raw)
        if m and not raw.strip().upper().startswith("(FINISH"):
            ops.append(OpLinks(m.group(1).strip()))
            continue
        line = re.sub(r"\(.*?\)", "", line)
        if not line or not ops:
            continue
        words = WORD.findall(line)
        new = list(pos)
        moved = False
        for letter, value in words:
            v = float(value)
            if letter == "G" and int(v) in (0, 1, 2, 3):
                mode = 0 if int(v) == 0 else 1
            elif letter in "XYZ":
                new["XYZ".index(letter)] = v
                moved = True
            elif letter == "F":
                feed = v
        if moved and new != pos:
            ops[-1].moves.append((mode, *pos, *new, feed))
            pos = new
    return ops


def measure(op: OpLinks, rapid: float) -> OpLinks:
    op.top = max((max(m[3], m[6]) for m in op.moves), default=-math.inf)
    before = 0
    for kind, x0, y0, z0, x1, y1, z1, f in op.moves:
        dxy, dz = math.hypot(x1 - x0, y1 - y0), z1 - z0
        length = math.hypot(dxy, dz)
        if kind == 0:
            op.rapids += 1
            op.rapid_mm += length
            op.rapid_s += max(dxy, abs(dz)) / rapid * 60
            if dxy < 1e-6 and dz > 0:
                if z1 >= op.top - 1e-6:
                    op.lifts += 1
                else:
                    op.hops += 1
        else:
            t = length / f * 60 if f > 0 else 0.0
            vertical = dxy < 1e-6
            if vertical and dz < 0 and before == 0:
                op.plunges += 1
                op.plunge_mm += -dz
                op.plunge_s += t
            else:
                op.cut_mm += length
                op.cut_s += t
                if vertical:
                    if dz < 0:
                        op.down_mm += -dz
                    else:
                        op.up_mm += dz
        before = kind
    return op


def table(folder: Path, rapid: float) -> None:
    programs = sorted(folder.glob("*.ngc"))
    if not programs:
        print(f"{folder}: no .ngc")
        return
    print(f"{programs[0]}  (rapids {rapid:g} mm/min)")
    print(HEAD)
    print("-" * len(HEAD))
    for op in parse(programs[0].read_text()):
        if op.moves:
            row(measure(op, rapid))


def toolpath_moves(tp, feed: float, plunge: float) -> list:
    from tmm_workbench.core.toolpath import MoveKind

    pts = tp.points()
    return [(0 if m.kind is MoveKind.RAPID else 1, *pts[i - 1], *pts[i],
             plunge if m.kind is MoveKind.PLUNGE else feed) for i, m in enumerate(tp.moves) if i]


def checks(data: dict, tp) -> str:
    """The deepest cut into the model along the fed moves, the rapids into the stock, the simulated low."""
    from tmm_workbench.core.query.drop import DropSurface
    from tmm_workbench.core.sim.simulate import simulate
    from tmm_workbench.core.toolpath import MoveKind
    from tmm_workbench.core.verify.linear_moves import deepest_cut

    cutter, params, stock = data["cutter"], data["params"], data["policy"].material_top
    s = max(float(getattr(params, "stock_to_leave", 0.0)), 0.0)
    fed = np.array([m.kind is not MoveKind.RAPID for m in tp.moves])
    deep, _ = deepest_cut(DropSurface(data["mesh"]), cutter.offset(s) if s else cutter,
                          tp.points() - np.array([0.0, 0.0, s]), fed, 0.025)
    text = f"deepest cut {deep:.4f} mm"
    if stock is not None:
        sim = simulate(tp, cutter, stock.grid, stock.heights)
        design = getattr(params.rest, "design", None)
        low = float(np.nanmin(sim.heights - design)) if design is not None else math.nan
        text += f", {len(sim.collisions)} rapid(s) into the stock, simulated low {low:.4f} mm"
    return text


def ops(folder: Path, rapid: float, feed: float, plunge: float) -> None:
    import pickle
    import time

    from tmm_workbench.core.segments import SegmentKind
    from tmm_workbench.core.strategies import finish_passes, raster_drop
    from tmm_workbench.core.strategies.finish_passes import compute_finish_toolpath

    linked = []

    def keep(link):   # the segments the op links: its joins (LINK) and pieces (PASS)
        def linking(segments, policy):
            linked[:] = list(segments)
            return link(segments, policy)
        return linking

    finish_passes.link, raster_drop.link = keep(finish_passes.link), keep(raster_drop.link)

    def length(kind) -> float:
        return sum(float(np.linalg.norm(np.diff(seg.tips, axis=0), axis=1).sum()) for seg in linked
                   if seg.kind is kind)

    print(f"{folder}: computed again (feed {feed:g}, plunge {plunge:g}, rapids {rapid:g} mm/min)")
    print(HEAD)
    print("-" * len(HEAD))
    notes = []
    for pkl in sorted(folder.glob("*.pkl")):
        raw = pkl.read_bytes()
        data, fresh = pickle.loads(raw), pickle.loads(raw)   # the linker cuts the stock heights as it links
        t0 = time.perf_counter()
        tp = compute_finish_toolpath(fresh["mesh"], fresh["cutter"], fresh["params"], fresh["finish"],
                                     fresh["policy"])
        wall = time.perf_counter() - t0
        op = OpLinks(data["label"], moves=toolpath_moves(tp, feed, plunge))
        row(measure(op, rapid))
        pieces = sum(1 for seg in linked if seg.kind is SegmentKind.PASS and not seg.joined)
        notes.append(f"{data['label']}: compute {wall:.0f} s; {len(linked)} segments ({pieces} entered from above), "
                     f"pieces {length(SegmentKind.PASS):.0f} mm, joins {length(SegmentKind.LINK):.0f} mm in "
                     f"{sum(1 for seg in linked if seg.kind is SegmentKind.LINK)}; {checks(data, tp)}")
    for n in notes:
        print(n)


HEAD = (f"{'op':<30} {'total min':>9} {'cut min':>8} {'link min':>8} {'entries':>7} {'plunge mm':>9} "
        f"{'plunge min':>10} {'rapids':>6} {'rapid mm':>9} {'rapid min':>9} {'lifts':>5} {'hops':>5} "
        f"{'down mm':>7} {'up mm':>7}")


def row(op: OpLinks) -> None:
    print(f"{op.label[:30]:<30} {op.total_s / 60:>9.2f} {op.cut_s / 60:>8.2f} {op.link_s / 60:>8.2f} "
          f"{op.plunges:>7} {op.plunge_mm:>9.0f} {op.plunge_s / 60:>10.2f} {op.rapids:>6} {op.rapid_mm:>9.0f} "
          f"{op.rapid_s / 60:>9.2f} {op.lifts:>5} {op.hops:>5} {op.down_mm:>7.0f} {op.up_mm:>7.0f}", flush=True)


def option(args: list[str], name: str, default: float) -> float:
    if name not in args:
        return default
    k = args.index(name)
    value = float(args[k + 1])
    del args[k:k + 2]
    return value


def set_constants(args: list[str]) -> None:
    """--set module.NAME=value (a core.strategies module's constant), taken out of `args`."""
    import importlib

    while "--set" in args:
        k = args.index("--set")
        name, value = args[k + 1].split("=")
        module, const = name.rsplit(".", 1)
        mod = importlib.import_module(f"tmm_workbench.core.strategies.{module}")
        setattr(mod, const, type(getattr(mod, const))(value))
        print(f"{name} = {getattr(mod, const)!r}")
        del args[k:k + 2]


def main() -> None:
    args = sys.argv[1:]
    set_constants(args)
    rapid, feed, plunge = option(args, "--rapid", 5000.0), option(args, "--feed", 960.0), option(args, "--plunge", 320.0)
    if args[:1] == ["--ops"]:
        for folder in args[1:]:
            ops(Path(folder), rapid, feed, plunge)
        return
    for folder in args:
        table(Path(folder), rapid)


if __name__ == "__main__":
    main()
