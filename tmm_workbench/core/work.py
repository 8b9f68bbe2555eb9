"""The work of a strategy told from its parameters alone, before anything is allocated: what it counts against
the work limits (core.limits), the passes and the cutting length its spacing implies, and the compute it costs as
units of measured pace rows (the app times them: app.work_estimate.PACE). Every registered strategy tells it with
one signature: `estimate_work(params, cutter, bounds) -> Work`, `bounds` the box of what is machined (and optional
inputs a caller may have: the Surface's coarse height sample of the model)."""
from __future__ import annotations

from dataclasses import dataclass
from typing import Optional

Box = tuple[float, float, float, float, float, float]   # xmin, ymin, zmin, xmax, ymax, zmax (mm)


@dataclass(frozen=True)
class Work:
    count: float                         # what the limits count: CL points, tool positions, loop points...
    what: str                            # its name ("CL points")
    passes: Optional[int] = None
    cut_length: Optional[float] = None   # mm of cutting moves, from the boxes and the spacing (not a path)
    note: str = ""                       # what the count leaves out
    paces: tuple[tuple[str, float], ...] = ()   # (pace row, units at it): the compute is their sum
    # the cut length by the slope the passes climb there: (tan of the slope along them, mm), from a sample of the
    # model; the moves going down its steep parts are cut at the plunge feed (app.work_estimate)
    climbs: tuple[tuple[float, float], ...] = ()

    def plus(self, count: float, pace: str, note: str) -> "Work":
        """This work and `count` more of the same kind at `pace` (a verification's dense raster)."""
        return Work(self.count + count, self.what, self.passes, self.cut_length, note,
                    self.paces + ((pace, count),), self.climbs)
