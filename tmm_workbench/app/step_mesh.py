"""The automatic planner's STEP reader: FreeCAD reads the STEP file (in mm, whatever its own units) and tessellates
its shape within a chordal deflection the core chose from the finish's tolerance, and writes the mesh as an STL
for the core's analysis and the Job (core.plan.launch starts it before planning):

    TMM_STEP_FILE=part.step TMM_STEP_STL=<folder>/part_model.stl TMM_STEP_DEFLECTION=0.005 \\
        freecadcmd tmm_workbench/app/step_mesh.py

Exit codes (freecadcmd returns 0 even when a script raises): 0 written, 2 the file is not a STEP FreeCAD reads or
has no faces (the reason on stderr), 3 another failure.
"""
from __future__ import annotations

import os
import sys
from pathlib import Path

REPO = Path(globals().get("__file__") or sys.argv[0]).resolve().parents[2]
UNREADABLE = 2   # app.plan_run.exit_with: 3 for any other failure


def step_mesh(step: Path, stl: Path, deflection: float, solid: bool = False) -> int:
    """`step`'s shape tessellated within `deflection` mm (app.geometry.mesh_from_shape), written to `stl`; its
    triangle count. ValueError: not readable as a STEP, nothing to tessellate, or (`solid`: a stock) no solid."""
    import Part

    from tmm_workbench.app.geometry import mesh_from_shape
    from tmm_workbench.core.geometry.mesh import save_stl

    try:
        shape = Part.read(str(step))
        mesh = mesh_from_shape(shape, deflection, step.stem)
    except Exception as exc:  # noqa: BLE001 - OCC's reader raises its own kinds, TMM a TmmError without faces
        raise ValueError(f"FreeCAD could not read {step.name} as a STEP model: {exc}") from None
    if solid and not shape.Solids:
        raise ValueError(f"{step.name} holds no solid (a stock is a closed solid)")
    save_stl(mesh, stl)
    return len(mesh.triangles)


def main() -> int:
    try:
        step_mesh(Path(os.environ["TMM_STEP_FILE"]), Path(os.environ["TMM_STEP_STL"]),
                  float(os.environ["TMM_STEP_DEFLECTION"]), os.environ.get("TMM_STEP_SOLID") == "1")
    except ValueError as exc:
        print(exc, file=sys.stderr)
        return UNREADABLE
    return 0


if __name__ in ("__main__", "step_mesh"):
    sys.path.insert(0, str(REPO))
    from tmm_workbench.app.plan_run import exit_with

    exit_with(main)
