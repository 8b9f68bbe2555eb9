"""FreeCAD-side tests (tests/freecad/fc_test_*.py) run under `freecadcmd`, one process per module."""
from __future__ import annotations

from pathlib import Path

import pytest

from tests.freecad import fc_process

HERE = Path(__file__).resolve().parent
# The longest modules first (each one freecadcmd): under pytest-xdist no worker is left with one of them at the
# end while the others idle (the root conftest.py orders the GUI and FreeCAD tests before the rest). Measured
# with fc_runner's TMM-FC-TIME sums on FreeCAD 0.20 (docs/results.md); a module not named keeps its place.
LONGEST = ("fc_test_plan", "fc_test_plan_tarus", "fc_test_multipoint", "fc_test_holder", "fc_test_rest",
           "fc_test_fast_posts", "fc_test_offset3d", "fc_test_multipoint_scallop", "fc_test_mesh5_holder",
           "fc_test_sim_holder", "fc_test_verify_cusp", "fc_test_simulate", "fc_test_op")
MODULES = sorted((p.stem for p in HERE.glob("fc_test_*.py")),
                 key=lambda m: (LONGEST.index(m) if m in LONGEST else len(LONGEST), m))
FREECADCMD = fc_process.find("freecadcmd", "FreeCADCmd")


@pytest.mark.parametrize("module", MODULES)
def test_freecad_module(module: str, tmp_path: Path) -> None:
    assert FREECADCMD is not None, "freecadcmd is needed (run scripts/setup.sh)"
    code, out = fc_process.run([FREECADCMD, str(HERE / "fc_runner.py")], cwd=tmp_path, timeout=300,
                               TMM_FC_MODULES=module, TMM_TEST_OUT=str(tmp_path))
    assert code == 0 and "TMM-FC-RESULT PASS" in out, f"freecadcmd exit code {code}\n{out}"
