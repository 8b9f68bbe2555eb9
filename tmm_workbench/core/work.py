"""The work of a strategy told from its parameters alone, before anything is allocated: what it counts against
the work limits (core.limits), the passes and the cutting length its spacing implies, and the compute it costs as
units of measured pace rows (the app times them: app.work_estimate.PACE). Every registered strategy tells it with
one signature: `estimate_work(params, cutter, bounds) -> Work`, `bounds` the box of what is machined (and optional
inputs a caller may have: the Surface's coarse height sample of the model)."""
from __future__ import annotations

import math
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

    def cutting_seconds(self, feed: float, vert_feed: Optional[float] = None, plunge_deg: float = 45.0) -> float:
        """The cutting time of cut_length at `feed` (mm/s), the half of the climbs steeper than `plunge_deg` (the
        moves going down them) at `vert_feed` as the ops write them (none without a vertical feed)."""
        steep = math.tan(math.radians(plunge_deg))
        down = 0.5 * sum(mm for t, mm in self.climbs if t > steep) if vert_feed and vert_feed > 0 else 0.0
        return (float(self.cut_length or 0.0) - down) / feed + (down / vert_feed if down else 0.0)
