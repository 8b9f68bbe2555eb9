"""The tool assembly: the cutter (core.tools.Cutter, positioned exactly by the drop queries) and what rides
above it, the flutes' top, an optional neck, the shank and the holder, as the coaxial frusta the assembly
drop query lifts the tool over.

Tip coordinates: z up the tool axis from the tip. The cutter reaches from the tip to the flute length (the
cutting-edge height); `bodies()` covers everything above it, each (z0, z1, r0, r1, clearance): from z0 to
z1, radius r0 at z0 and r1 at z1, sorted by z, touching, never overlapping. In order:
  - the flutes above the cutter's APT profile when the flute length exceeds the cutter's L_C (a cone or
    taper cutter whose side flutes continue at its diameter), at the cutter clearance;
  - the neck (narrower than the cutter, as on long-reach ball mills), from the flutes' top;
  - the step or cone from the flutes (or the neck) to the shank: a step by default, which encloses the real
    tool's cone; `shank_cone_deg` (half angle from the axis) draws the cone when the catalogue gives it;
  - the shank up to the holder's face at z = stick-out (the gauge length from the holder face to the tip);
  - the holder's stack above the face.
Neck, cone and shank take the shank clearance; the holder takes the holder clearance.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Optional, Union

from tmm_workbench.core.errors import TmmError
from tmm_workbench.core.tools import holders
from tmm_workbench.core.tools.cutter import Cutter
from tmm_workbench.core.tools.holders import Holder, length

Body = tuple[float, float, float, float, float]  # (z0, z1, r0, r1, clearance)


@dataclass(frozen=True)
class ToolAssembly:
    cutter: Cutter
    shank_diameter: float
    stick_out: float                            # gauge length: holder face to tool tip
    flute_length: Optional[float] = None        # cutting-edge height; None: the cutter's finite L_C
    holder: Optional[Union[Holder, str]] = None  # a name looks in the shipped library
    neck_diameter: Optional[float] = None
    neck_length: float = 0.0
    shank_cone_deg: float = 90.0                # half angle of the cone up to the shank; 90: a step
    overall_length: Optional[float] = None      # the tool's length, when known: the stick-out cannot exceed it
    cutter_clearance: float = 0.0
    shank_clearance: float = 1.0
    holder_clearance: float = 1.0

    def __post_init__(self) -> None:
        if not isinstance(self.cutter, Cutter):
            raise TmmError(f"a tool assembly needs a Cutter, got {self.cutter!r}")
        object.__setattr__(self, "flute_length", self._checked_flute_length())
        object.__setattr__(self, "shank_diameter", length("shank diameter", self.shank_diameter))
        object.__setattr__(self, "stick_out", length("stick-out", self.stick_out))
        for what in ("cutter_clearance", "shank_clearance", "holder_clearance"):
            object.__setattr__(self, what, length(what.replace("_", " "), getattr(self, what), positive=False))
        self._check_neck()
        cone = self.shank_cone_deg
        if isinstance(cone, bool) or not isinstance(cone, (int, float)) or not 0 < cone <= 90:
            raise TmmError(f"shank cone half angle must be above 0 and at most 90 degrees (90: a step), got {cone!r}")
        if isinstance(self.holder, str):
            object.__setattr__(self, "holder", holders.holder(self.holder))
        self._check_lengths()
        self._check_holder()

    def _checked_flute_length(self) -> float:
        lc = self.cutter.cutting_length
        if self.flute_length is None:
            if not math.isfinite(lc):
                raise TmmError(f"the {self.cutter.describe()} cutter needs a flute length (cutting-edge height) "
                               "for its assembly: give flute_length in mm (> 0)")
            return float(lc)
        fl = length("flute length", self.flute_length)
        if math.isfinite(lc) and fl < lc - 1e-9:
            raise TmmError(f"flute length {fl:g} mm must be at least the {self.cutter.describe()} cutter's "
                           f"cutting-edge height {lc:g} mm")
        return fl

    def _check_neck(self) -> None:
        if self.neck_diameter is None:
            if self.neck_length != 0:
                raise TmmError(f"neck length {self.neck_length!r} mm is given without a neck diameter")
            return
        dn = length("neck diameter", self.neck_diameter)
        length("neck length", self.neck_length)
        top = min(self.cutter.diameter, self.shank_diameter)
        if dn > top + 1e-9:
            raise TmmError(f"neck diameter {dn:g} mm must be at most the cutter diameter "
                           f"{self.cutter.diameter:g} mm and the shank diameter {self.shank_diameter:g} mm")

    def _check_lengths(self) -> None:
        if self.stick_out < self.flute_length - 1e-9:
            raise TmmError(f"stick-out {self.stick_out:g} mm must be at least the flute length "
                           f"{self.flute_length:g} mm: the holder would cover the cutting edge")
        low = self.minimum_stick_out
        if self.stick_out < low - 1e-9:
            raise TmmError(f"stick-out {self.stick_out:g} mm must be at least {low:g} mm: the flutes "
                           f"({self.flute_length:g} mm), the neck ({self.neck_length:g} mm) and the cone up to "
                           f"the shank ({self._cone_height():g} mm) must stand out of the holder")
        if self.overall_length is not None:
            total = length("overall length", self.overall_length)
            if self.stick_out > total + 1e-9:
                raise TmmError(f"stick-out {self.stick_out:g} mm must be at most the tool's overall length "
                               f"{total:g} mm")

    def _check_holder(self) -> None:
        h = self.holder
        if h is None:
            return
        if not isinstance(h, Holder):
            raise TmmError(f"holder must be a Holder, a holder name or None, got {h!r}")
        if h.nose_diameter <= self.shank_diameter:
            raise TmmError(f"holder '{h.name}': its nose (diameter {h.nose_diameter:g} mm) is narrower than the "
                           f"shank ({self.shank_diameter:g} mm)")
        if not h.clamps(self.shank_diameter):
            raise TmmError(f"shank diameter {self.shank_diameter:g} mm is outside the clamping range "
                           f"{h.shank_min:g}-{h.shank_max:g} mm of holder '{h.name}'")

    def _below_shank_radius(self) -> float:
        """The radius the cone up to the shank starts from: the neck's, else the flutes' top."""
        return (self.neck_diameter if self.neck_diameter is not None else self.cutter.diameter) / 2

    def _cone_height(self) -> float:
        rise = self.shank_diameter / 2 - self._below_shank_radius()
        if rise <= 0 or self.shank_cone_deg >= 90:
            return 0.0
        return rise / math.tan(math.radians(self.shank_cone_deg))

    @property
    def minimum_stick_out(self) -> float:
        """The shortest stick-out that keeps the flutes, the neck and the cone to the shank out of the holder."""
        return self.flute_length + self.neck_length + self._cone_height()

    def bodies(self) -> list[Body]:
        """Everything above the cutter as (z0, z1, r0, r1, clearance) frusta, sorted by z (module doc)."""
        out: list[Body] = []
        R = self.cutter.radius
        lc = min(self.cutter.cutting_length, self.flute_length)
        z = self.flute_length
        if z > lc:
            out.append((lc, z, R, R, self.cutter_clearance))
        if self.neck_diameter is not None and self.neck_length > 0:
            rn = self.neck_diameter / 2
            out.append((z, z + self.neck_length, rn, rn, self.shank_clearance))
            z += self.neck_length
        rs = self.shank_diameter / 2
        cone = self._cone_height()
        if cone > 0:
            out.append((z, z + cone, self._below_shank_radius(), rs, self.shank_clearance))
            z += cone
        if self.stick_out > z:
            out.append((z, self.stick_out, rs, rs, self.shank_clearance))
        if self.holder is not None:
            out.extend(self.holder.bodies(self.stick_out, self.holder_clearance))
        return out

    @property
    def top(self) -> float:
        """The height above the tip of the assembly's top (the holder's top, else the holder face)."""
        return self.stick_out + (self.holder.length if self.holder is not None else 0.0)

    def describe(self) -> str:
        parts = [f"{self.cutter.describe()} flutes {self.flute_length:g}"]
        if self.neck_diameter is not None:
            parts.append(f"neck D{self.neck_diameter:g} x {self.neck_length:g}")
        parts.append(f"shank D{self.shank_diameter:g}, stick-out {self.stick_out:g} mm")
        holder = f"in {self.holder.name}" if self.holder is not None else "no holder"
        return (", ".join(parts) + f" {holder} (clearance cutter {self.cutter_clearance:g}, shank "
                f"{self.shank_clearance:g}, holder {self.holder_clearance:g} mm)")
