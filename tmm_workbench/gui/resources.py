"""Absolute paths of the add-on's icons and panels (resources/ beside the package, not Qt resources)."""
from __future__ import annotations

from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
ICONS = ROOT / "resources" / "icons"
PANELS = ROOT / "resources" / "panels"


def icon(name: str) -> str:
    return str(ICONS / f"{name}.svg")


def panel(name: str) -> str:
    return str(PANELS / f"{name}.ui")
