"""The pytest side of a GUI test: FreeCAD runs a tests/gui/gui_X.py session under Xvfb, its outcome (the JSON the
session wrote, tests/gui/gui_runner.py) is read back, its screenshots are checked and, when env TMM_GUI_REFRESH_DOCS
is 1, copied to docs/gui (a plain run leaves the tree as it was)."""
from __future__ import annotations

import json
import os
import shutil
from pathlib import Path

from tests.freecad import fc_process

HERE = Path(__file__).resolve().parent
FREECAD = fc_process.find("freecad", "FreeCAD")
XVFB_RUN = fc_process.find("xvfb-run")
SHOTS = fc_process.ROOT / "out" / "gui"
DOCS = fc_process.ROOT / "docs" / "gui"
REFRESH_ENV = "TMM_GUI_REFRESH_DOCS"


def run_session(script: str, tmp_path: Path, timeout: float, **env: str) -> dict:
    """`freecad tests/gui/<script>` under Xvfb (1280x1024) with `env`; the session's outcome, asserted to be a
    success (exit code 0 and "ok"; else the session's traceback and the end of FreeCAD's output)."""
    # scripts/setup.sh installs both: missing ones fail the test rather than skip it
    assert FREECAD is not None and XVFB_RUN is not None, "freecad and xvfb-run are needed (run scripts/setup.sh)"
    result = tmp_path / (Path(script).stem + ".json")
    code, out = fc_process.run(
        [XVFB_RUN, "-a", "-n", str(display_base()), "-s", "-screen 0 1280x1024x24", FREECAD, str(HERE / script)],
        cwd=tmp_path, timeout=timeout, TMM_GUI_RESULT=str(result),
        QTWEBENGINE_DISABLE_SANDBOX="1", **env)  # FreeCAD's start page uses QtWebEngine, which refuses root
    info = json.loads(result.read_text()) if result.is_file() else {}
    assert code == 0 and info.get("ok"), \
        f"FreeCAD exit code {code}\n{info.get('error', '')}\n{fc_process.failure_text(out)}"
    return info


def display_base() -> int:
    """The first X display number `xvfb-run -a` tries for this pytest-xdist worker (gw0: 100, gw1: 120, ...; 100
    without xdist): it takes the first free one from there without a lock, so two workers starting a session at
    the same moment must not start from the same number."""
    worker = os.environ.get("PYTEST_XDIST_WORKER", "gw0")
    index = int(worker[2:]) if worker[2:].isdigit() else 0
    return 100 + 20 * index


def blank(png: Path) -> bool:
    """A blank grab has (almost) one colour; a window with a panel and a 3D view has many."""
    try:
        from PIL import Image
    except ImportError:  # no Pillow: the size check has to do
        return False
    with Image.open(png) as im:
        colours = im.convert("RGB").resize((320, 256)).getcolors(maxcolors=1 << 16)
    return colours is not None and len(colours) < 16


def check_shots(pngs: list[Path], min_bytes: int = 5_000) -> None:
    """Each screenshot written, not blank; copied to docs/gui when env TMM_GUI_REFRESH_DOCS is 1."""
    for png in pngs:
        assert png.is_file() and png.stat().st_size > min_bytes, png
        assert not blank(png), f"{png} is blank"
    if os.environ.get(REFRESH_ENV) == "1":
        for png in pngs:
            shutil.copyfile(png, DOCS / png.name)
