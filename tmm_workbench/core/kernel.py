"""The compiled kernel, imported on first use, with a clear message when it is missing.

It is either built in place by scripts/setup.sh (`tmm_workbench._native`) or installed as a wheel
(`pip install ./native`: `tmm_kernel._native`); the first that imports is used.

Nothing imports the kernel at module load: FreeCAD restores (and saves) documents with TMM objects on a
machine where the kernel cannot be imported, because the op modules import without it; only a
computation needs it, and it then fails with `KernelMissing` saying what is missing and the fix.
"""
from __future__ import annotations

import importlib
from types import ModuleType
from typing import Any, Optional

from tmm_workbench.core.errors import TmmError

FIX = "bash scripts/setup.sh"  # builds the kernel for Debian's /usr/bin/python3, the one FreeCAD runs
PIP_FIX = "python3 -m pip install ./native"  # the same kernel as a wheel, for the Python FreeCAD runs
MODULES = ("tmm_workbench._native", "tmm_kernel._native")


class KernelMissing(TmmError):
    """The kernel module cannot be imported (not built, or built for another Python)."""


class _Kernel:
    """Stands for the module `tmm_workbench._native`; attribute access imports it."""

    _module: Optional[ModuleType] = None

    def load(self) -> ModuleType:
        if self._module is None:
            causes = []
            for name in MODULES:
                try:
                    self._module = importlib.import_module(name)
                    break
                except ImportError as exc:
                    causes.append(f"{name}: {exc}")
            else:
                import sys

                raise KernelMissing(
                    "TMM's native kernel is not installed, or was built for another Python (this is Python "
                    f"{sys.version_info.major}.{sys.version_info.minor}): run `{FIX}` in the TMM folder, or "
                    f"`{PIP_FIX}` with this Python. Tried {'; '.join(causes)}")
        return self._module

    def __getattr__(self, name: str) -> Any:
        return getattr(self.load(), name)


native: Any = _Kernel()


def available() -> bool:
    try:
        native.load()
    except KernelMissing:
        return False
    return True


def require() -> None:
    """Raises KernelMissing (a TmmError) when the kernel cannot be imported."""
    native.load()
