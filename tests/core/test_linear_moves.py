"""The 3-axis paths of the main job, as a post writes them at 4 decimals, checked against the model: no
straight move between CL points passes more than 0.01 mm below the exact drop height (checked every
0.02 mm), open edges included (the tool goes across at the upper height and straight down or up there);
without the check between points the same paths cut 0.08 mm (sphere) and 8 mm (mount_rush's edges)
into the model (issue 11 items 3 and 7, the 3-axis side). At linuxcnc's default 3 decimals the rounding
alone costs up to 0.024 mm on mount_rush, where the bull-nose rolls over the relief's near-vertical edges
(a 0.0005 mm shift in X on a CL profile of slope ~50): surface finishing wants `--precision 4`."""
from __future__ import annotations

import numpy as np
import pytest

from tests.conftest import SHARED_STL
from tmm_workbench.core.geometry.mesh import load_stl
from tmm_workbench.core.linking import LinkPolicy
from tmm_workbench.core.query.drop import DropSurface
from tmm_workbench.core.strategies.raster_drop import SurfaceParams, compute_surface_toolpath
from tmm_workbench.core.toolpath import MoveKind
from tmm_workbench.core.tools.cutter import Cutter
from tmm_workbench.core.verify.linear_moves import deepest_cut

# the main job's cases (scripts/demo.py)
CASES = [("sphere_on_plate.stl", Cutter.ball(6.0), 0.5, 0.25, "floor"),
         ("mount_rush.stl", Cutter.bull(4.0, 1.0), 0.3, 0.2, "skip")]


@pytest.mark.parametrize("name,cutter,stepover,step,off_model", CASES)
def test_moves_as_written_do_not_cut_into_the_model(name, cutter, stepover, step, off_model):
    mesh = load_stl(SHARED_STL / name)
    lo, hi = mesh.bounds
    surface = DropSurface(mesh)
    policy = LinkPolicy(float(hi[2]) + 5, float(hi[2]) + 10)
    depths = []
    for tol in (0.005, 0.0):
        p = SurfaceParams(boundary=(lo[0], lo[1], hi[0], hi[1]), stepover=stepover, sample_step=step,
                          off_model=off_model, gouge_tol=tol)
        tp = compute_surface_toolpath(mesh, cutter, p, policy, surface=surface)
        cutting = np.array([m.kind is not MoveKind.RAPID for m in tp])
        written = np.round(tp.points(), 4)  # a post at 4 decimals (linuxcnc --precision 4; see below)
        depths.append(deepest_cut(surface, cutter, written, cutting, step=0.02)[0])
    refined, plain = depths
    assert refined <= 0.01, (name, refined)
    assert plain > 5 * refined  # the check matters on these models
