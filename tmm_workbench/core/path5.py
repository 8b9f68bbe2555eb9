"""TMM's 5-axis moves in FreeCAD Path command parameters (pure functions over dicts, no FreeCAD import).

Representation (docs/path5.md):
* A motion command (G0, G1; G2/G3 only at a constant axis) keeps FreeCAD's meaning of X, Y, Z: the tool TIP
  in work coordinates (mm), and of F: the feed of the tip (mm/s, FreeCAD's internal unit).
* The tool axis (unit vector from the tip towards the spindle, as `core.toolpath.Move.axis`) is stored as its
  three direction cosines in the words U, V, W (U = i, V = j, W = k), full double precision. The three
  come together or not at all.
* Axis words are modal within one Path (one op's `Path.Commands`), like X, Y, Z: a motion command without
  U, V, W keeps the previous axis, and every Path starts with the vertical axis (0, 0, 1). A 3-axis path
  needs no axis words at all; TMM writes U, V, W on every motion command of a 5-axis path.
* Nothing else changes: no A/B/C words (machine angles are the post's business), F stays mm/s.

Why U, V, W: `Path.Command` takes them and keeps them as doubles (exact recovery in memory), Path Inspect and
`toGCode()` print them, the stock 0.20 posts that know no U/V/W (linuxcnc, centroid, fanuc, mach3_mach4, ...)
drop them and print the tip path, and FreeCAD's geometry code (`Command.Placement`, arcs, bounding box,
Path length) ignores them. I, J, K would be arc words, and A, B, C are rotary axes in every post.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Iterable, Mapping, Optional, Sequence

from tmm_workbench.core.errors import TmmError
from tmm_workbench.core.toolpath import Move, MoveKind, Toolpath, Z_AXIS

AXIS_WORDS = ("U", "V", "W")
TIP_WORDS = ("X", "Y", "Z")
RAPID_NAMES = ("G0", "G00")
LINEAR_NAMES = ("G1", "G01")
ARC_NAMES = ("G2", "G02", "G3", "G03")
MOTION_NAMES = RAPID_NAMES + LINEAR_NAMES + ARC_NAMES
_CANONICAL = {"G00": "G0", "G01": "G1", "G02": "G2", "G03": "G3"}

Vec3 = tuple[float, float, float]


def encode(move: Move, feed: Optional[float] = None, with_axis: Optional[bool] = None) -> tuple[str, dict]:
    """(command name, parameters) for one toolpath move: G0 for rapids (no F), G1 otherwise with F = feed
    (mm/s) when given. Axis words are written when `with_axis` is True, or (None) when the axis is not Z."""
    name = "G0" if move.kind is MoveKind.RAPID else "G1"
    if not all(math.isfinite(float(c)) for c in (move.x, move.y, move.z, *move.axis)):
        # a NaN in a Path is read as 'keep the previous value' by some readers: never write one
        raise TmmError(f"a tool path move is not a finite number (tip {move.x}, {move.y}, {move.z}, axis "
                       f"{tuple(move.axis)}): nothing was written")
    params: dict[str, float] = {"X": float(move.x), "Y": float(move.y), "Z": float(move.z)}
    if with_axis or (with_axis is None and tuple(move.axis) != Z_AXIS):
        params.update(zip(AXIS_WORDS, (float(v) for v in move.axis)))
    if name == "G1" and feed is not None:
        params["F"] = float(feed)
    return name, params


def encode_toolpath(toolpath: Toolpath | Iterable[Move], horiz_feed: Optional[float] = None,
                    vert_feed: Optional[float] = None, with_axis: Optional[bool] = None) -> list[tuple[str, dict]]:
    """Every move encoded: FEED moves with `horiz_feed`, PLUNGE moves with `vert_feed` (mm/s). Axis words on
    every move when the path has any non-vertical axis (with_axis=None), always (True) or only where the
    axis is not Z (False)."""
    moves = list(toolpath)
    if with_axis is None:
        with_axis = any(tuple(m.axis) != Z_AXIS for m in moves)
    feeds = {MoveKind.FEED: horiz_feed, MoveKind.PLUNGE: vert_feed, MoveKind.RAPID: None}
    return [encode(m, feeds[m.kind], True if with_axis else None) for m in moves]


def axis_of(params: Mapping[str, Any]) -> Optional[Vec3]:
    """The unit tool axis in `params` (U, V, W), None when they are absent; TmmError when only some are
    there or they have no direction. A vector that is already unit comes back bit for bit."""
    present = [w in params for w in AXIS_WORDS]
    if not any(present):
        return None
    if not all(present):
        missing = [w for w, p in zip(AXIS_WORDS, present) if not p]
        raise TmmError(f"tool axis words U, V, W must come together; {', '.join(missing)} missing")
    v = [float(params[w]) for w in AXIS_WORDS]
    if not all(math.isfinite(c) for c in v):
        raise TmmError(f"tool axis U, V, W = {v} is not finite")
    n = math.sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2])
    if n < 1e-9:
        raise TmmError(f"tool axis U, V, W = {v} has no direction")
    if abs(n - 1.0) < 4e-16:
        return (v[0], v[1], v[2])
    return (v[0] / n, v[1] / n, v[2] / n)


@dataclass(frozen=True)
class PathMove:
    """One decoded motion command: canonical name (G0..G3), tip (mm; NaN for a coordinate never given),
    unit axis, feed (mm/s, modal; None before any F), the command's index in the Path, and the raw
    parameters (for arc words)."""
    name: str
    tip: Vec3
    axis: Vec3
    feed: Optional[float]
    index: int
    params: Mapping[str, float]

    @property
    def is_rapid(self) -> bool:
        return self.name == "G0"


@dataclass
class Pose:
    """Modal state of a decoder: the current tip, axis and feed."""
    tip: Vec3 = (math.nan, math.nan, math.nan)
    axis: Vec3 = Z_AXIS
    feed: Optional[float] = None


def decode(name: str, params: Mapping[str, Any], previous: Optional[Pose] = None) -> Pose:
    """The pose after one motion command (`name`, `params`) that follows `previous` (a Path's start when
    None): missing X/Y/Z/U,V,W/F words keep the previous values."""
    prev = previous or Pose()
    tip = tuple(float(params[w]) if w in params else prev.tip[k] for k, w in enumerate(TIP_WORDS))
    axis = axis_of(params) or prev.axis
    feed = float(params["F"]) if "F" in params else prev.feed
    return Pose(tip, axis, feed)  # type: ignore[arg-type]


def is_motion(name: str) -> bool:
    return name.upper() in MOTION_NAMES


def decode_commands(commands: Iterable[tuple[str, Mapping[str, Any]]]) -> list[PathMove]:
    """Every motion command of one Path decoded, with the modal rules above. Non-motion commands are
    skipped (their index still counts)."""
    out: list[PathMove] = []
    pose = Pose()
    for i, (name, params) in enumerate(commands):
        up = name.upper()
        if up not in MOTION_NAMES:
            continue
        try:
            pose = decode(up, params, pose)
        except TmmError as exc:
            raise TmmError(f"command {i} ({name}): {exc}") from None
        out.append(PathMove(_CANONICAL.get(up, up), pose.tip, pose.axis, pose.feed, i, dict(params)))
    return out


def moves_from_commands(commands: Iterable[tuple[str, Mapping[str, Any]]]) -> Toolpath:
    """A Toolpath back from commands (G0 -> RAPID, G1 -> FEED; arcs are not toolpath moves and raise).
    A coordinate never given raises too."""
    tp = Toolpath()
    for m in decode_commands(commands):
        if m.name not in ("G0", "G1"):
            raise TmmError(f"command {m.index} ({m.name}): arcs are not toolpath moves")
        if any(math.isnan(c) for c in m.tip):
            raise TmmError(f"command {m.index} ({m.name}): X, Y or Z was never given")
        tp.add(MoveKind.RAPID if m.is_rapid else MoveKind.FEED, *m.tip, axis=m.axis)
    return tp


def split_words(params: Mapping[str, Any], skip: Sequence[str] = TIP_WORDS + AXIS_WORDS) -> dict[str, float]:
    """The parameters of a command other than tip and axis words (I, J, K, F, S, ...)."""
    return {k: float(v) for k, v in params.items() if k not in skip}
