"""The compiled kernel, imported on first use, with a clear message when it is missing.

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


class KernelMissing(TmmError):
    """The kernel module cannot be imported (not built, or built for another Python)."""


class _Kernel:
    """Stands for the module `tmm_workbench._native`; attribute access imports it."""

    _module: Optional[ModuleType] = None

    def load(self) -> ModuleType:
        if self._module is None:
            try:
                self._module = importlib.import_module("tmm_workbench._native")
            except ImportError as exc:
                import sys

                raise KernelMissing(
                    "TMM's native kernel (tmm_workbench/_native*.so) is not built or was built for another "
                    f"Python (this is Python {sys.version_info.major}.{sys.version_info.minor}); run `{FIX}` in "
                    f"the TMM folder. Cause: {exc}") from exc
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
