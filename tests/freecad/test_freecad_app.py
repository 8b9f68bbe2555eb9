"""FreeCAD-side tests (tests/freecad/fc_test_*.py) run under `freecadcmd`, one process per module."""
from __future__ import annotations

from pathlib import Path

import pytest

from tests.freecad import fc_process

HERE = Path(__file__).resolve().parent
MODULES = sorted(p.stem for p in HERE.glob("fc_test_*.py"))
FREECADCMD = fc_process.find("freecadcmd", "FreeCADCmd")


@pytest.mark.parametrize("module", MODULES)
def test_freecad_module(module: str, tmp_path: Path) -> None:
    assert FREECADCMD is not None, "freecadcmd is needed (run scripts/setup.sh)"
    code, out = fc_process.run([FREECADCMD, str(HERE / "fc_runner.py")], cwd=tmp_path, timeout=300,
                               TMM_FC_MODULES=module, TMM_TEST_OUT=str(tmp_path))
    assert code == 0 and "TMM-FC-RESULT PASS" in out, f"freecadcmd exit code {code}\n{out}"
