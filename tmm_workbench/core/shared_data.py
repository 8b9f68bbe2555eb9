"""Where the project's shared benchmark files are (seed surfaces, real STL files). They are not part of the
add-on: benchmarks, the demo, the seed experiment and the tests read them from $TMM_SHARED_DIR when set, else
from the folder `shared/` beside the checkout (the checkout found through this file, links resolved, so the
FreeCAD Mod link to it counts)."""
from __future__ import annotations

import os
from pathlib import Path

from tmm_workbench.core.errors import TmmError

REPO = Path(__file__).resolve().parents[2]
SIBLING = REPO.parent / "shared"


def shared_dir() -> Path:
    """The shared folder (the one holding benchmarks/); TmmError naming the places tried if none does."""
    env = os.environ.get("TMM_SHARED_DIR")
    tried = ([Path(env)] if env else []) + [SIBLING]
    for d in tried:
        if (d / "benchmarks").is_dir():
            return d
    raise TmmError("the shared benchmark files were not found; tried " + ", ".join(str(d) for d in tried))


def benchmark_file(*parts: str) -> Path:
    """A file under shared/benchmarks (e.g. benchmark_file("stl", "sphere_on_plate.stl")); TmmError if absent."""
    path = shared_dir().joinpath("benchmarks", *parts)
    if not path.exists():
        raise TmmError(f"shared benchmark file missing: {path}")
    return path
