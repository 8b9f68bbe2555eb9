"""Progress for long computations, with cancel. The core calls `progress(fraction) -> bool`
(False cancels).

Headless (and by default) a text line goes to the console every 10 %. The GUI injects its own
factory (InitGui.py -> tmm_workbench/gui/progress_dialog.py: a progress dialog with Cancel).
FreeCAD's own sequencer (`FreeCAD.Base.ProgressIndicator`, Esc -> `FreeCADAbort` from `next(True)`)
cannot serve here: ops compute inside a document recompute, which runs its own sequencer, and
0.20 ignores a sequencer started while another runs (checked: nothing is shown, Esc never seen).
"""
from __future__ import annotations

import time
from contextlib import contextmanager
from typing import Callable, Iterator, Optional

import FreeCAD

Progress = Callable[[float], bool]
ProgressFactory = Callable[[str], "ProgressReporter"]


class ProgressReporter:
    """A progress callback with start/finish: `with reporter as cb: core(..., progress=cb)`."""

    def __enter__(self) -> Progress:
        return self.__call__

    def __exit__(self, *exc) -> None:
        self.finish()

    def __call__(self, fraction: float) -> bool:
        return True

    def finish(self) -> None:
        pass


class TextProgress(ProgressReporter):
    """'<label>: 30 % (1.2 s)' lines on the console every `every` (fraction)."""

    def __init__(self, label: str, every: float = 0.1) -> None:
        self.label, self.every, self.next_mark = label, every, every
        self.t0 = time.monotonic()

    def __call__(self, fraction: float) -> bool:
        if fraction + 1e-9 >= self.next_mark:
            pct = int(round(min(fraction, 1.0) * 100))
            FreeCAD.Console.PrintMessage(f"{self.label}: {pct} % ({time.monotonic() - self.t0:.1f} s)\n")
            while self.next_mark <= fraction + 1e-9:
                self.next_mark += self.every
        return True


class QuietProgress(ProgressReporter):
    pass


def default_factory(label: str) -> ProgressReporter:
    return TextProgress(label)


progress_factory: ProgressFactory = default_factory


# the kernel's share of an op's progress; the rest is the Path's commands being made (app.path_build)
KERNEL_SHARE = 0.9


def phase(progress: Optional[Progress], lo: float, hi: float) -> Optional[Progress]:
    """`progress` for one phase of a computation: its 0..1 shown as lo..hi of the whole."""
    return (lambda f: progress(lo + (hi - lo) * min(max(f, 0.0), 1.0))) if progress else None


def reporter(label: str, enabled: bool = True) -> ProgressReporter:
    return progress_factory(label) if enabled else QuietProgress()


@contextmanager
def using(factory: Optional[ProgressFactory]) -> Iterator[None]:
    """Temporarily report through `factory` (None: keep the current one)."""
    global progress_factory
    old = progress_factory
    if factory is not None:
        progress_factory = factory
    try:
        yield
    finally:
        progress_factory = old
