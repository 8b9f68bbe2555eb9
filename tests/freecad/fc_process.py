"""Running FreeCAD in a subprocess from pytest: command lookup, environment, readable output."""
from __future__ import annotations

import os
import re
import shutil
import signal
import subprocess
from pathlib import Path
from typing import Optional, Sequence

ROOT = Path(__file__).resolve().parents[2]
_NOISE = re.compile(r"\(\s*\d+ %\)|^\s*(Recompute|Importing project files|Postprocessing|create mesh "
                    r"structure)\.+\s*$", re.M)


def find(*names: str) -> Optional[str]:
    for n in names:
        path = shutil.which(n)
        if path:
            return path
    return None


def environment(**extra: str) -> dict[str, str]:
    """FreeCAD embeds Debian's python3: no venv or PYTHONHOME leaking into it."""
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONHOME", "VIRTUAL_ENV", "PYTHONSTARTUP")}
    env.update(extra)
    return env


def readable(text: str) -> str:
    """FreeCAD's console progress ('(42 %)' with tabs, no newlines) stripped for assertion messages."""
    text = _NOISE.sub("", text.replace("\t", " "))
    return "\n".join(line.rstrip() for line in text.splitlines() if line.strip())


def _ahead_of_the_other_tests() -> None:
    """In the child before it starts: a nice value under the other pytest workers' (root only; else as is)."""
    try:
        os.nice(-5)
    except OSError:
        pass


def run(cmd: Sequence[str], cwd: Path, timeout: float, *, ahead: bool = False, **env: str) -> tuple[int, str]:
    """Runs `cmd` in its own process group; on timeout the whole group (xvfb-run, Xvfb, FreeCAD) is killed,
    so a hung GUI never outlives its test. `ahead`: the group runs ahead of the other test workers on the
    cores, for a test that measures the GUI's own latency (what the other workers' load would add is not the
    add-on's)."""
    proc = subprocess.Popen(list(cmd), cwd=cwd, env=environment(**env), stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, start_new_session=True,
                            preexec_fn=_ahead_of_the_other_tests if ahead else None)
    try:
        out, err = proc.communicate(timeout=timeout)
    except subprocess.TimeoutExpired:
        os.killpg(proc.pid, signal.SIGKILL)
        out, err = proc.communicate()
        return -1, f"timed out after {timeout} s\n" + readable((out or "") + "\n" + (err or ""))
    return proc.returncode, readable(out + "\n" + err)


def failure_text(out: str, tail: int = 6000) -> str:
    """What an assertion message shows of a FreeCAD run: the end of its output and, when it crashed, first the
    Python stack faulthandler printed (tests/gui/gui_runner.py), which the long C stack after it pushes out of
    any tail."""
    start = out.find("Fatal Python error")
    if start < 0:
        return out[-tail:]
    stack = out[start:start + 4000]
    end = stack.find("\n\n", stack.find("most recent call first"))
    return (stack if end < 0 else stack[:end]) + "\n[...]\n" + out[-tail:]
