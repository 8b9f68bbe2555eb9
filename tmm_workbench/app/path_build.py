"""An op's moves as FreeCAD Path commands, and as arrays the post, the status line and the cycle time read.

A million-move path took FreeCAD 118 s after the kernel was done, the GUI frozen: every reader went through the
Path's per-command Python API (a Command object and a Parameters dict each, 2-3 us). Here the moves become rows
of arrays once (`MoveRows`: a command kind and its words per row, vectorised but for arcs), the Path's commands
are made from them in chunks with the progress callback between chunks (the dialog repaints, Cancel is heard),
and the op keeps the rows with the Path they built (`PathRecord`) for the readers that would otherwise read
the Path back. FreeCAD's own text route (`Path.Path().setFromGCode(text)`) is no faster on 0.20: 2.3 s to parse
a million lines in one call, against 1.7 s for the Command objects made here in 50 ms chunks.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Callable, Iterator, NamedTuple, Optional

import numpy as np

from tmm_workbench.core.arcs import PLANE_CODES
from tmm_workbench.core.cancel import poll
from tmm_workbench.core.errors import Cancelled
from tmm_workbench.core.toolpath import MoveKind, Toolpath, steep_mask

CHUNK = 20_000   # commands made between two progress calls (about 50 ms on the 2-core machine)
G0, G1 = 0, 1    # the first two kinds of every MoveRows
LINE_KINDS: list[tuple[str, tuple[str, ...]]] = [("G0", ("X", "Y", "Z")), ("G1", ("X", "Y", "Z", "F"))]
WIDTH = 7        # the most words of a row: an arc's X Y Z I J K F


class Cmd(NamedTuple):
    """A command as the posts read one (Name, Parameters), without FreeCAD."""
    Name: str
    Parameters: dict[str, float]


@dataclass
class MoveRows:
    """Commands as arrays: row r is `kinds[codes[r]]` = (name, word letters) with the words' values in
    `values[r, :len(letters)]` (the rest 0)."""
    kinds: list[tuple[str, tuple[str, ...]]] = field(default_factory=lambda: list(LINE_KINDS))
    codes: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=np.int32))
    values: np.ndarray = field(default_factory=lambda: np.zeros((0, WIDTH)))

    def __len__(self) -> int:
        return len(self.codes)

    def kind(self, name: str, words: tuple[str, ...]) -> int:
        key = (name, words)
        if key not in self.kinds:
            self.kinds.append(key)
        return self.kinds.index(key)

    def commands(self, start: int = 0, stop: Optional[int] = None) -> Iterator[Cmd]:
        """Rows start..stop as (Name, Parameters)."""
        kinds = self.kinds
        for code, row in zip(self.codes[start:stop].tolist(), self.values[start:stop].tolist()):
            name, words = kinds[code]
            yield Cmd(name, dict(zip(words, row)))

    def has_arcs(self) -> bool:
        return any(name not in ("G0", "G1") for name, _ in self.kinds[2:]) and bool((self.codes >= 2).any())


def rows_of(toolpath: Toolpath, horiz_feed: float, vert_feed: float, plunge_angle_deg: float,
            clearance: Optional[float]) -> MoveRows:
    """The rows of `toolpath`: a Z-only rapid to `clearance` first (when given), G0 for rapids, G1 at
    `vert_feed` for plunges and for feed moves down more steeply than `plunge_angle_deg`, else at
    `horiz_feed`; an arc as G2/G3 behind its plane's code when the plane changes."""
    moves = toolpath.moves
    n = len(moves)
    out = MoveRows()
    if not n:
        return out
    pts, rapid, feed, arcs = np.empty((n, 3)), np.empty(n, dtype=bool), np.empty(n, dtype=bool), []
    for a in range(0, n, CHUNK):   # the moves are Python objects: read a chunk at a time, Cancel heard between
        part = moves[a:a + CHUNK]
        pts[a:a + len(part)] = [(m.x, m.y, m.z) for m in part]
        rapid[a:a + len(part)] = [m.kind is MoveKind.RAPID for m in part]
        feed[a:a + len(part)] = [m.kind is MoveKind.FEED for m in part]
        arcs += [a + i for i, m in enumerate(part) if m.arc is not None and a + i > 0]
        poll()
    down = steep_mask(pts, feed, plunge_angle_deg)
    codes = np.where(rapid, G0, G1).astype(np.int32)
    values = np.zeros((n, WIDTH))
    values[:, :3] = pts
    values[:, 3] = np.where(rapid, 0.0, np.where(down | ~feed, vert_feed, horiz_feed))
    if arcs:
        codes, values = _with_arcs(out, moves, arcs, codes, values, horiz_feed)
    if clearance is not None:
        codes = np.concatenate([[out.kind("G0", ("Z",))], codes]).astype(np.int32)
        values = np.vstack([[max(clearance, float(pts[0, 2]))] + [0.0] * (WIDTH - 1), values])
    out.codes, out.values = codes, values
    return out


def _with_arcs(out: MoveRows, moves: list, arcs: list[int], codes: np.ndarray, values: np.ndarray,
               horiz_feed: float) -> tuple[np.ndarray, np.ndarray]:
    """The rows with each arc move's G2/G3 (and its plane's code where the plane changes; XY again at the end)."""
    rows_c, rows_v, plane, last = [], [], "XY", 0
    for i in arcs:
        rows_c.append(codes[last:i])
        rows_v.append(values[last:i])
        m = moves[i]
        if m.arc.plane != plane:
            plane = m.arc.plane
            rows_c.append(np.array([out.kind(PLANE_CODES[plane], ())]))
            rows_v.append(np.zeros((1, WIDTH)))
        prev = moves[i - 1]
        name, words = m.arc.command((prev.x, prev.y, prev.z), (m.x, m.y, m.z))
        words = {**words, "F": horiz_feed}
        row = np.zeros((1, WIDTH))
        row[0, :len(words)] = list(words.values())
        rows_c.append(np.array([out.kind(name, tuple(words))]))
        rows_v.append(row)
        last = i + 1
    rows_c.append(codes[last:])
    rows_v.append(values[last:])
    if plane != "XY":
        rows_c.append(np.array([out.kind(PLANE_CODES["XY"], ())]))
        rows_v.append(np.zeros((1, WIDTH)))
    return np.concatenate(rows_c).astype(np.int32), np.vstack(rows_v)


def path_commands(rows: MoveRows, progress: Optional[Callable[[float], bool]] = None) -> list[Any]:
    """FreeCAD Path commands of `rows`, CHUNK at a time, `progress(fraction)` after each (False: Cancelled)."""
    import Path

    out: list[Any] = []
    n = len(rows)
    for start in range(0, n, CHUNK):
        out.extend(Path.Command(c.Name, c.Parameters) for c in rows.commands(start, start + CHUNK))
        if progress is not None and not progress(min(start + CHUNK, n) / n):
            raise Cancelled("tool path computation cancelled")
    return out


def unusable_row(rows: MoveRows, limit: float) -> Optional[tuple[int, str, str, float]]:
    """The first row with a word beyond `limit` or not a number: (row, command, word, value); None when all are
    usable (the padding is 0)."""
    bad = ~(np.abs(rows.values) <= limit)
    if not bad.any():
        return None
    r, col = (int(v[0]) for v in np.nonzero(bad))
    name, words = rows.kinds[int(rows.codes[r])]
    return r, name, words[col], float(rows.values[r, col])


@dataclass
class PathRecord:
    """What an op's Path holds, for readers that must not read it back command by command: the commands
    before its moves (as Cmd), the moves' rows, the commands after them."""
    before: list[Cmd]
    rows: MoveRows
    after: list[Cmd]
    cycle_s: Optional[float] = None   # its cycle time once estimated (s)

    def __len__(self) -> int:
        return len(self.before) + len(self.rows) + len(self.after)

    def cuts(self) -> int:
        """Cutting passes: a G1/G2/G3 after a rapid or at the start (as the status line counts them)."""
        lut = np.array([_state(name) for name, _ in self.rows.kinds], dtype=np.int8)
        state = np.concatenate([np.array([_state(c.Name) for c in self.before], dtype=np.int8),
                                lut[self.rows.codes], np.array([_state(c.Name) for c in self.after], dtype=np.int8)])
        marks = state[state >= 0]
        return int(((marks == 1) & np.concatenate([[True], marks[:-1] == 0])).sum())

    def commands(self) -> Iterator[Cmd]:
        yield from self.before
        yield from self.rows.commands()
        yield from self.after


def line_moves(rec: PathRecord) -> Optional[tuple[np.ndarray, np.ndarray]]:
    """The tool tip's points and the feed of the move ending at each (inf for a rapid) as the cycle time reads
    them, when the Path is straight moves (G0/G1 rows, a Z-only rapid first, comments before, Z-only rapids after);
    None otherwise (read the Path)."""
    rows = rec.rows
    lines = rows.codes <= G1
    first_z = len(rows) and rows.kinds[int(rows.codes[0])] == ("G0", ("Z",))
    if not lines[int(first_z):].all() or any(not c.Name.startswith("(") for c in rec.before):
        return None
    if any(c.Name not in ("G0", "G00") or set(c.Parameters) != {"Z"} for c in rec.after):
        return None
    v = rows.values[int(first_z):]
    if not len(v):
        return None
    pts = [v[:, :3]] + [np.array([[v[-1, 0], v[-1, 1], c.Parameters["Z"]]]) for c in rec.after]
    feeds = np.where(rows.codes[int(first_z):] == G0, np.inf, v[:, 3])
    return np.vstack(pts), np.concatenate([feeds, np.full(len(rec.after), np.inf)])


def _state(name: str) -> int:
    """1 for a cutting move, 0 for a rapid, -1 for anything else."""
    return 1 if name in ("G1", "G01", "G2", "G02", "G3", "G03") else (0 if name in ("G0", "G00") else -1)


def record(commandlist: list[Any], start: int, rows: MoveRows) -> PathRecord:
    """The record of a Path built from `commandlist`, whose commands start..start+len(rows) came from `rows`."""
    def plain(cs: list[Any]) -> list[Cmd]:
        return [Cmd(c.Name, dict(c.Parameters)) for c in cs]
    return PathRecord(plain(commandlist[:start]), rows, plain(commandlist[start + len(rows):]))


def record_of(obj: Any) -> Optional[PathRecord]:
    """The record the op keeps of its current Path, or None (not a TMM op, reopened, changed since, undone)."""
    return getattr(getattr(obj, "Proxy", None), "path_record", None)
