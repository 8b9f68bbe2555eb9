"""The tool's bodies above the flutes (neck, shank, holder pieces) against the stock as the simulation cuts it
(the kernel's body check, native/include/tmm/sim/body_check.hpp): per move and piece the deepest cell that comes
closer to the body than its clearance. What hits the design hits the stock over it; the stock also holds what
no op has cut yet, which a check against the design cannot see (a roughing's stick-out too short for its depth)."""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Optional

import numpy as np

from tmm_workbench.core.errors import TmmError
from tmm_workbench.core.query.drop_assembly import body_pieces
from tmm_workbench.core.tools.assembly import ToolAssembly


@dataclass(frozen=True)
class CheckedBodies:
    """The bodies of an assembly the stock check tests, as the kernel takes them."""
    rows: np.ndarray          # (k, 5) (z0, z1, r0, r1, clearance) in tip coordinates
    names: tuple[str, ...]    # piece of each row: 'neck', 'shank' or 'holder'
    flute_top: float          # mm above the tip: the flutes cut up to here
    description: str
    clearances: dict

    @classmethod
    def of(cls, assembly: ToolAssembly) -> "CheckedBodies":
        if not isinstance(assembly, ToolAssembly):
            raise TmmError(f"assembly must be a ToolAssembly, got {assembly!r}")
        keep = [(b, p) for b, p in zip(assembly.bodies(), body_pieces(assembly)) if p != "cutter"]
        if not keep:
            raise TmmError(f"the tool assembly ({assembly.describe()}) has nothing above the flutes to check")
        rows = np.array([b for b, _ in keep], dtype=float).reshape(-1, 5)
        names = tuple(p for _, p in keep)
        clearances = {p: c for p, c in (("shank", assembly.shank_clearance), ("holder", assembly.holder_clearance))
                      if p in names}
        return cls(rows, names, float(assembly.flute_length), assembly.describe(), clearances)


@dataclass
class StockCollisions:
    """The deepest cell per colliding move and piece, one row each, in move order."""
    assembly: str                  # the assembly's description
    moves: np.ndarray              # (k,) move index: the move from path point m to m + 1
    pieces: np.ndarray             # (k,) 'neck', 'shank' or 'holder'
    positions: np.ndarray          # (k, 3) the cell's centre and its stock height
    depths: np.ndarray             # (k,) mm the stock reaches above the body grown by its clearance
    moves_checked: int = 0
    clearances: dict = field(default_factory=dict)

    @classmethod
    def from_kernel(cls, rows: np.ndarray, bodies: CheckedBodies, moves_checked: int) -> "StockCollisions":
        rows = np.asarray(rows, dtype=float).reshape(-1, 6)
        names = np.array(bodies.names, dtype=object)
        return cls(bodies.description, rows[:, 0].astype(np.int64), names[rows[:, 1].astype(np.int64)],
                   rows[:, 2:5].copy(), rows[:, 5].copy(), moves_checked, dict(bodies.clearances))

    @property
    def count(self) -> int:
        return len(self.moves)

    @property
    def ok(self) -> bool:
        return self.count == 0

    @property
    def per_piece(self) -> dict[str, int]:
        return {p: int(np.sum(self.pieces == p)) for p in ("neck", "shank", "holder") if np.any(self.pieces == p)}

    @property
    def deepest(self) -> float:
        return float(self.depths.max()) if self.count else 0.0

    def summary(self) -> str:
        if self.ok:
            return (f"Tool clear of the stock: neither the shank nor the holder comes closer to the stock than its "
                    f"clearance on {self.moves_checked:,} moves ({self.assembly}).")
        k = int(np.argmax(self.depths))
        x, y, z = self.positions[k]
        pieces = ", ".join(f"{p} {n:,}" for p, n in self.per_piece.items())
        return (f"Tool collision with the stock: on {len(np.unique(self.moves)):,} of {self.moves_checked:,} moves "
                f"a piece above the flutes comes closer to the stock than its clearance ({pieces}). Worst: the "
                f"{self.pieces[k]} {self.depths[k]:.3f} mm deep on move {int(self.moves[k])} at X{x:.3f} Y{y:.3f} "
                f"Z{z:.3f}. Lengthen the stick-out, rough deeper first, or choose a slimmer holder.")


def combined(parts: list[Optional[StockCollisions]]) -> Optional[StockCollisions]:
    """The collisions of several ops as one (moves as each op numbers them), None when none was checked."""
    parts = [p for p in parts if p is not None]
    if not parts:
        return None
    return StockCollisions("; ".join(dict.fromkeys(p.assembly for p in parts)),
                           np.concatenate([p.moves for p in parts]), np.concatenate([p.pieces for p in parts]),
                           np.vstack([p.positions for p in parts]), np.concatenate([p.depths for p in parts]),
                           sum(p.moves_checked for p in parts))
