"""The planner's recipes: the shop's machines, finish presets and tool library a person picks from (the web
front's form, the GUI's TMM Auto), turned into a job file's data (core.plan.job_file checks it)."""
from __future__ import annotations

from pathlib import Path
from typing import Optional, Union

# the shop's machines: the planner's machine section
MACHINES: dict[str, dict] = {
    "3-axis linuxcnc": {"type": "3-axis", "post": "linuxcnc", "travels": [300, 200, 100]},
    "3-axis grbl": {"type": "3-axis", "post": "grbl", "travels": [300, 300, 80]},
    "Tarus 5-axis": {"type": "tarus5"},   # 5-axis finishing where it pays (core.plan.five_axis), the tarus post
}
# finish presets: the cusp kept, the verification's tolerance and the planner's grids (coarser: faster);
# `draft` is tests/data/plan_beet.yaml's coarse values
FINISHES: dict[str, dict] = {
    "draft": {"finish": {"cusp": 0.1, "tolerance": 0.01}, "planner": {"analysis_cell": 0.5, "sim_cell": 0.4},
              "sign_cell": 0.5},
    "standard": {"finish": {"cusp": 0.05, "tolerance": 0.01}, "planner": {"analysis_cell": 0.5, "sim_cell": 0.2},
                 "sign_cell": 0.35},
    "fine": {"finish": {"cusp": 0.02, "tolerance": 0.01}, "planner": {"analysis_cell": 0.4, "sim_cell": 0.15},
             "sign_cell": 0.25},
}
# the shop's library (the planner's test job's)
TOOLS = [
    {"name": "T1 flat D8", "type": "flat", "diameter": 8, "flutes": 2, "flute_length": 20},
    {"name": "T2 ball D6", "type": "ball", "diameter": 6, "flutes": 2, "flute_length": 20, "holder": "ER16 nut",
     "stick_out": 30},
    {"name": "T3 bull D6 r1", "type": "bull", "diameter": 6, "corner_radius": 1, "flutes": 2, "flute_length": 20},
]
STOCK = {"type": "box", "margin": 2, "above": 1}


def job_data(material: str, finish: str, machine: str, model_file: str, out_dir: str, name: str,
             tools: Optional[Union[str, list]] = None, stock: Optional[dict] = None) -> dict:
    """The planner's job file for `model_file` (mm) with the recipe: a material of the table, a FINISHES and a
    MACHINES name; `tools` a tools file or a list (default: TOOLS), `stock` the stock section (default: STOCK)."""
    preset = FINISHES[finish]
    return {"format": "tmm-plan 1", "model": {"file": model_file, "units": "mm"},
            "stock": dict(stock or STOCK), "machine": dict(MACHINES[machine]),
            "tools": tools if isinstance(tools, str) else [dict(t) for t in (tools or TOOLS)],
            "material": material, "finish": dict(preset["finish"]), "outputs": {"dir": out_dir, "name": name},
            "planner": dict(preset["planner"])}


# `tmm plan part.stl` without a job file (core.plan.launch): the benchmark jobs' recipe (benchmarks/jobs/*.yaml)
SHOP_LIBRARY = Path(__file__).resolve().parents[3] / "benchmarks" / "jobs" / "shop_tools.yaml"
DEFAULT_MACHINE = {"type": "3-axis", "post": "linuxcnc", "travels": [400, 300, 120], "spindle_max": 24000,
                   "feed_max": 5000}
DEFAULT_FINISH = {"cusp": 0.01, "tolerance": 0.01}
DEFAULT_MATERIAL = "mdf"


def default_job(model_file: str, out_dir: str) -> dict:
    """The job file's data planning `model_file` (absolute; mm) with the default recipe into `out_dir`."""
    return {"format": "tmm-plan 1", "model": {"file": model_file, "units": "mm"}, "stock": dict(STOCK),
            "machine": dict(DEFAULT_MACHINE), "tools": str(SHOP_LIBRARY), "material": DEFAULT_MATERIAL,
            "finish": dict(DEFAULT_FINISH), "outputs": {"dir": out_dir}}
