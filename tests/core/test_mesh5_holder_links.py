"""The links of a 5-axis mesh finish with the whole tool (mesh5.holder.link_clear): under an overhang, the
linker's exit (along the tool axis, then straight up to the transit height) brings the shank up into the roof;
the pass is then left and entered along its axis all the way to the transit height, and the linked path keeps
the shank and holder their clearance all along (core.verify.holder_clearance, every move sampled)."""
from __future__ import annotations

import numpy as np
import pytest

from tests.conftest import grid_mesh
from tmm_workbench.core.geometry.mesh import TriMesh
from tmm_workbench.core.linking import link
from tmm_workbench.core.segments import CutSegment
from tmm_workbench.core.strategies.mesh5 import holder
from tmm_workbench.core.strategies.multipoint import link_policy
from tmm_workbench.core.toolpath import MoveKind
from tmm_workbench.core.tools.assembly import ToolAssembly
from tmm_workbench.core.tools.cutter import Cutter
from tmm_workbench.core.verify.holder_clearance import check_holder_clearance

ROOF = 20.0   # a roof at this height over x >= 0 above a floor z = 0
TILT = np.radians(30.0)


def floor_under_roof() -> TriMesh:
    floor = grid_mesh(lambda x, y: 0.0 * x, 12, 4, (-30.0, -10.0, 30.0, 10.0), "floor")
    n = len(floor.vertices)
    roof = np.array([[0, -10, ROOF], [30, -10, ROOF], [30, 10, ROOF], [0, 10, ROOF]], dtype=float)
    return TriMesh(np.vstack([floor.vertices, roof]),
                   np.vstack([floor.triangles, [[n, n + 1, n + 2], [n, n + 2, n + 3]]]), "roof")


def passes_under_the_roof() -> list[CutSegment]:
    """Two passes along y on the floor under the roof (x 6 and 2), the tool leaning out from under it (-x)."""
    a = np.array([-np.sin(TILT), 0.0, np.cos(TILT)])
    ys = np.linspace(-5.0, 5.0, 6)
    return [CutSegment(np.column_stack([np.full(6, x), y, np.zeros(6)]), axes=np.tile(a, (6, 1)), pass_index=k)
            for k, (x, y) in enumerate(((6.0, ys), (2.0, ys[::-1])))]


@pytest.fixture(scope="module")
def setup():
    cutter = Cutter.flat(6.0)
    assembly = ToolAssembly(cutter, 6.0, 60.0, flute_length=6.0, holder="ER16 nut")
    return floor_under_roof(), cutter, assembly, link_policy(cutter, ROOF + 40.0, ROOF + 50.0, 5.0)


def _check(mesh, assembly, path):
    return check_holder_clearance(mesh, assembly, path, sample_step=0.25, surface_step=0.2, tolerance=0.01)


def test_straight_up_after_the_axis_retract_brings_the_shank_into_the_roof(setup):
    mesh, _, assembly, policy = setup
    path = link(passes_under_the_roof(), policy)
    check = _check(mesh, assembly, path)
    assert not check.ok
    # the cut itself is clear: only the links come too close
    assert all(path.moves[i].kind != MoveKind.FEED for i in check.move)


def test_the_passes_are_left_along_the_axis_to_the_transit_height_and_the_links_are_clear(setup):
    mesh, cutter, assembly, policy = setup
    segments = passes_under_the_roof()
    path, note = holder.link_clear(mesh, segments, policy, assembly)
    assert _check(mesh, assembly, path).ok
    assert note.checked == 4 and len(note.raised) == 2 and len(note.blocked) == 0
    assert "along the tool axis up to the transit height" in note.summary()
    # the same cut moves; each exit goes along the axis until the tilted tool's lowest point is at the safe height
    feeds = [m for m in path.moves if m.kind == MoveKind.FEED]
    assert len(feeds) == sum(len(s) - 1 for s in segments)
    transit = policy.safe_height + cutter.lowest_below_tip(tuple(segments[0].axis(0)))
    for k, m in enumerate(path.moves[:-1]):
        if m.kind == MoveKind.FEED and path.moves[k + 1].kind == MoveKind.PLUNGE:
            out = path.moves[k + 1]
            step = np.subtract((out.x, out.y, out.z), (m.x, m.y, m.z))
            assert np.allclose(step / np.linalg.norm(step), m.axis, atol=1e-9)
            assert out.z >= transit - 1e-6
    # segments given to it are not changed
    assert all(s.axis_retract is None for s in segments)


def test_without_an_assembly_the_linker_path_is_kept(setup):
    mesh, _, _, policy = setup
    segments = passes_under_the_roof()
    path, note = holder.link_clear(mesh, segments, policy, None)
    assert note is None and path.moves == link(segments, policy).moves
