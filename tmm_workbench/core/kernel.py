"""The compiled kernel, with a clear message when it has not been built."""
from __future__ import annotations

try:
    from tmm_workbench import _native  # noqa: F401  (re-exported)
except ImportError as exc:  # pragma: no cover - exercised only on a broken install
    raise ImportError(
        "TMM's native kernel (tmm_workbench/_native*.so) is not built or was built for another Python; "
        "run `bash scripts/setup.sh` (it builds for Debian's /usr/bin/python3, the one FreeCAD runs). Cause: %s" % exc
    ) from exc

native = _native
