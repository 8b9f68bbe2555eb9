"""What changed in each op's tool path from one TMM version to the next. A document computed by an older
version keeps its path until it is recomputed; when the recomputed path differs from the saved one, the op
says so (its PathNote and the report view): the version that made the saved path and what changed since.

Each op type's list grows by one row whenever a change makes the same properties give another path; an op
saved before any row carries version 0 (no PathVersion property).
"""
from __future__ import annotations

# op proxy class name -> [(version, what changed in that version)], oldest first
CHANGES: dict[str, list[tuple[int, str]]] = {
    "ObjectTmmSurface": [
        (1, "a cusp height below 0.0001 mm is refused; entries rapid to 1 mm above what the Job's earlier ops "
            "left (VerifyCusp's partial passes: above its simulated surface) and feed from there; the 3D offset "
            "adds loops where fronts meet head on across a slope"),
    ],
    "ObjectTmmRoughing": [
        (1, "entries rapid to 1 mm above the material where it is known and feed from there; ramp and helix "
            "angles are limited to 0.5-45 deg"),
    ],
    "ObjectTmmWaterline": [
        (1, "entries rapid to 1 mm above what the Job's earlier ops left and feed from there; a loop starting "
            "within a tool radius below the previous one is joined with the tool down; levels stay within the stock"),
    ],
    "ObjectTmmMultipoint": [
        (1, "the Tarus post plans through the vertical tool axis (C = 0); passes the scallop cannot hold at an "
            "edge are machined where the tool reaches and reported"),
    ],
}


def current(op_class: str) -> int:
    """The path version an op of this class computes today."""
    rows = CHANGES.get(op_class, [])
    return rows[-1][0] if rows else 0


def changes_since(op_class: str, version: int) -> list[str]:
    """What changed in the op's path after `version`, one line per version."""
    return [f"version {v}: {text}" for v, text in CHANGES.get(op_class, []) if v > version]


def note(op_class: str, saved_version: int) -> str:
    """The op's note when its recomputed path differs from the one `saved_version` made."""
    since = "; ".join(changes_since(op_class, saved_version)) or "no change recorded"
    return (f"recomputed to a different path than the saved one, which TMM path version {saved_version} made "
            f"(now {current(op_class)}). Changed since: {since}")
