"""FreeCAD's linuxcnc and grbl posts against TMM's fast posts (tmm_linuxcnc, tmm_grbl) on one large surface job:
mount_rush, ball d6, step-over 0.08 mm, sample step 0.1 mm (about 192k G-code lines). Each post exports the Job's
tool controller and op, best of 3 (seconds); the fast post's G-code is checked equal to FreeCAD's but for the
header's post name and time. The fast posts read the op's record of its Path (app.path_build); "from the Path"
is the same post with the record dropped, as in a reopened document.

    freecadcmd -c "exec(open('benchmarks/fast_posts.py').read())"
    TMM_POSTS_STEPOVER=0.5 freecadcmd -c "exec(open('benchmarks/fast_posts.py').read())"   # a small job
"""
from __future__ import annotations

import os
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__))) if "__file__" in globals() else os.getcwd()
sys.path.insert(0, ROOT)
STEPOVER = float(os.environ.get("TMM_POSTS_STEPOVER", "0.08"))
PAIRS = (("linuxcnc", "tmm_linuxcnc"), ("grbl", "tmm_grbl"))
REPEATS = 3


def best_of(post: str, objects: list, repeats: int = REPEATS) -> tuple[float, str]:
    """The shortest of `repeats` exports through `post` (s) and the last G-code."""
    from tmm_workbench.app import posts

    best, text = float("inf"), ""
    for _ in range(repeats):
        t0 = time.perf_counter()
        text = posts.export(post, objects)
        best = min(best, time.perf_counter() - t0)
    return best, text


def read_floor(op: object, repeats: int = REPEATS) -> float:
    """The shortest time (s) to read the op's commands through FreeCAD's Python API (Path.Commands, each
    command's Name and Parameters): what any Python post pays before writing a word."""
    best = float("inf")
    for _ in range(repeats):
        t0 = time.perf_counter()
        [(c.Name, c.Parameters) for c in op.Path.Commands]
        best = min(best, time.perf_counter() - t0)
    return best


def body(text: str) -> list[str]:
    """The G-code without the header lines that name the post and the time."""
    return [ln for ln in text.splitlines() if "(Post Processor:" not in ln and "(Output Time:" not in ln]


def main() -> None:
    from tmm_workbench.app import api
    from tmm_workbench.core.shared_data import benchmark_file

    t0 = time.perf_counter()
    result = api.run_surface(str(benchmark_file("stl", "mount_rush.stl")), stepover=STEPOVER, sample_step=0.1,
                             post="tmm_linuxcnc", progress=False, doc_name="FastPosts")
    objects = [result.op.ToolController, result.op]
    print(f"mount_rush step-over {STEPOVER:g} mm, sample step 0.1: {len(result.gcode.splitlines())} lines, "
          f"TMM's computation and post {time.perf_counter() - t0:.1f} s")
    print("| post | lines | FreeCAD's post s | TMM's fast post s | speed-up | from the Path s | speed-up | "
          "same G-code |")
    print("|---|---|---|---|---|---|---|---|")
    for stock, fast in PAIRS:
        slow_s, slow_text = best_of(stock, objects)
        fast_s, fast_text = best_of(fast, objects)
        record, result.op.Proxy.path_record = result.op.Proxy.path_record, None
        read_s, read_text = best_of(fast, objects)
        result.op.Proxy.path_record = record
        same = "yes" if body(slow_text) == body(fast_text) == body(read_text) else "NO"
        print(f"| {stock} / {fast} | {len(slow_text.splitlines())} | {slow_s:.2f} | {fast_s:.3f} | "
              f"{slow_s / fast_s:.1f}x | {read_s:.2f} | {slow_s / read_s:.1f}x | {same} |", flush=True)
    print(f"reading the op's commands alone (Path.Commands, Name, Parameters): {read_floor(result.op):.2f} s")


main()
