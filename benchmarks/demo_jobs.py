"""The README's demo jobs (scripts/demo.py's cases) for the benchmarks that measure them."""
from __future__ import annotations

import importlib.util
import sys
from pathlib import Path
from types import ModuleType

ROOT = Path(__file__).resolve().parents[1]


def load_demo() -> ModuleType:
    """scripts/demo.py loaded under another name: imported as "demo" it runs the whole demo first."""
    spec = importlib.util.spec_from_file_location("tmm_demo_cases", ROOT / "scripts" / "demo.py")
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module  # its dataclasses look their module up
    spec.loader.exec_module(module)
    return module
