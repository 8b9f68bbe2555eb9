"""How long Cancel takes to be honoured, per op and phase: each case runs through the headless API with a progress
callback that starts answering False `--at` seconds in; the time from then to the exception is the latency. A
sampler names where the main thread was while the cancel waited (the phase that does not poll).

    freecadcmd -c "exec(open('benchmarks/cancel_latency.py').read())"          # all cases, one process each
    TMM_CANCEL_CASES=cusp,sim3 freecadcmd -c "exec(open('benchmarks/cancel_latency.py').read())"

Prints a table: case, latency (s), result, where the latency was spent (the last sampled TMM frames).
"""
from __future__ import annotations

import os
import subprocess
import sys
import threading
import time
import traceback

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__))) if "__file__" in globals() else os.getcwd()
sys.path.insert(0, ROOT)
SCRIPT = os.path.join(ROOT, "benchmarks", "cancel_latency.py")
AT = float(os.environ.get("TMM_CANCEL_AT", "2.0"))
STL = "stl/sphere_on_plate.stl"

# case -> (API function, keyword arguments); STL cases machine sphere_on_plate
CASES = {
    "stepover": ("run_surface", dict(stepover=0.05, sample_step=0.05)),
    "cusp": ("run_surface", dict(stepover_mode="cusp", cusp=0.002)),
    "flat_cusp": ("run_surface", dict(tool="endmill", stepover_mode="cusp", cusp=0.01)),
    "adaptive": ("run_surface", dict(stepover_mode="adaptive", cusp=0.002)),
    "offset3d": ("run_surface", dict(stepover_mode="offset3d", cusp=0.002)),
    "verify": ("run_surface", dict(stepover_mode="adaptive", cusp=0.005, verify_cusp=True)),
    "roughing": ("run_roughing", dict(step_down=0.5, stepover_percent=10)),
    "waterline": ("run_waterline", dict(step_down=0.02)),
    "multipoint": ("run_multipoint", dict(scallop=0.02, forward_step=2.0)),
    "sim3": ("simulate", dict(cell=0.02)),
}


def _where(frame) -> str:
    stack = [f for f in traceback.extract_stack(frame) if "tmm_workbench" in f.filename]
    return " <- ".join(f"{os.path.basename(s.filename)}:{s.name}" for s in stack[-2:][::-1]) or "(FreeCAD)"


def run_case(name: str) -> None:
    from tmm_workbench.app import api
    from tmm_workbench.core.shared_data import benchmark_file

    function, kwargs = CASES[name]
    state = {"at": None, "done": False, "where": {}}
    main = threading.main_thread().ident

    def sampler() -> None:
        while not state["done"]:
            if state["at"] is not None:
                w = _where(sys._current_frames().get(main))
                state["where"][w] = state["where"].get(w, 0) + 1
            time.sleep(0.05)

    def progress(fraction: float) -> bool:
        return state["at"] is None

    def arm() -> None:
        time.sleep(AT)
        state["at"] = time.monotonic()

    stl = str(benchmark_file(STL))
    if function == "simulate":
        target = api.run_surface(stl, stepover=0.5, sample_step=0.5, progress=False, doc_name="Cancel")
        call = lambda: api.simulate(target, progress=progress, **kwargs)  # noqa: E731
    elif function == "run_multipoint":
        from tmm_workbench.core.geometry import bezier

        net = bezier.load_seed_patch(benchmark_file("seed_surfaces.json"), "convex")
        call = lambda: api.run_multipoint(net, progress=progress, posts=(), **kwargs)  # noqa: E731
    else:
        call = lambda: getattr(api, function)(stl, progress=progress, **kwargs)  # noqa: E731
    threading.Thread(target=sampler, daemon=True).start()
    threading.Thread(target=arm, daemon=True).start()  # armed once the case's own input is made
    t0 = time.monotonic()
    try:
        call()
        result = "finished"
    except Exception as exc:  # noqa: BLE001 - the outcome is what is measured
        result = f"{type(exc).__name__}: {str(exc)[:40]}"
    end = time.monotonic()
    state["done"] = True
    latency = f"{end - state['at']:.2f}" if state["at"] is not None else f"done in {end - t0:.1f} s"
    where = max(state["where"], key=state["where"].get) if state["where"] else ""
    print(f"CANCEL|{name}|{latency}|{result}|{where}", flush=True)


def main() -> None:
    case = os.environ.get("TMM_CANCEL_CASE")
    if case:
        run_case(case)
        return
    names = [c for c in os.environ.get("TMM_CANCEL_CASES", ",".join(CASES)).split(",") if c]
    print(f"cancel requested {AT:g} s in; latency = from then to the exception (s)")
    print(f"{'case':<12} {'latency':>14}  {'result':<44} where most of the wait was")
    for name in names:
        env = dict(os.environ, TMM_CANCEL_CASE=name)
        out = subprocess.run(["freecadcmd", "-c", f"exec(open({SCRIPT!r}).read())"], env=env, capture_output=True,
                             text=True, timeout=1800).stdout
        line = next((ln for ln in out.splitlines() if ln.startswith("CANCEL|")), f"CANCEL|{name}|?|no result|")
        _, n, latency, result, where = line.split("|", 4)
        print(f"{n:<12} {latency:>14}  {result:<44} {where}", flush=True)


main()
