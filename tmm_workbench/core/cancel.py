"""Cancel from inside long Python loops without threading the progress callback through every helper.

A strategy's `compute` (and the simulation) runs its work `with watching(progress):`; a loop deep in a helper
(the section rule's step search, the 3D offset's arrival field, the verification's rounds) calls `poll()` now
and then. `poll` asks the innermost watched callback at most every POLL_S seconds, with the last fraction it
reported (a bar does not move, Cancel is seen), and raises Cancelled when it answers False. Without a watched
callback `poll` costs a list lookup. The kernel's batch calls keep their own progress and cancel.
"""
from __future__ import annotations

import time
from contextlib import contextmanager
from typing import Callable, Iterator, Optional

from tmm_workbench.core.errors import Cancelled

Progress = Callable[[float], bool]
POLL_S = 0.1   # seconds between two questions to the callback (it may repaint a dialog)


class _Watch:
    def __init__(self, progress: Progress) -> None:
        self.progress, self.fraction, self.next = progress, 0.0, 0.0

    def report(self, fraction: float) -> bool:
        self.fraction = max(self.fraction, float(fraction))
        return self.progress(fraction)


_stack: list[_Watch] = []


@contextmanager
def watching(progress: Optional[Progress]) -> Iterator[Optional[Progress]]:
    """Makes `progress` the callback `poll` asks; yields the callback the work reports through (it records
    the fraction). None: nothing watched, None yielded."""
    if progress is None:
        yield None
        return
    watch = _Watch(progress)
    _stack.append(watch)
    try:
        yield watch.report
    finally:
        _stack.remove(watch)


def poll() -> None:
    """Cancelled if the watched callback, asked at most every POLL_S seconds, says stop."""
    if not _stack:
        return
    watch = _stack[-1]
    now = time.monotonic()
    if now < watch.next:
        return
    watch.next = now + POLL_S
    if watch.progress(watch.fraction) is False:
        raise Cancelled("cancelled")


def _ask(_fraction: float) -> bool:
    try:
        poll()
    except Cancelled:
        return False
    return True


def asker() -> Optional[Progress]:
    """For a kernel batch call deep in a helper: a progress callback that asks the watched one whether to go on
    (None when nothing is watched)."""
    return _ask if _stack else None


def native_call(function: Callable, *args, progress: Optional[Progress] = None, **kwargs):
    """A kernel call taking a `progress` keyword (a batch, a mesh phase): given the caller's `progress`, else
    cancelled through the watched callback (`poll`); the kernel's Cancelled arrives as the core's."""
    from tmm_workbench.core.kernel import native

    try:
        return function(*args, progress=asker() if progress is None else progress, **kwargs)
    except native.Cancelled as exc:
        raise Cancelled("cancelled") from exc
