"""Drop of the whole tool assembly along -Z: the cutter, then the flutes above it, the neck, the shank and the
holder (core.tools.assembly), each kept its clearance away from the mesh. The kernel's drop_assembly gives
the lowest tip height at each (x, y) and which piece set it.

Kernel convention kept here: every piece stops on a mesh point over its footprint even above its own top (an
overhang over the holder stops the tool as the spindle above it would), so each piece acts as a column
upward. A body's piece name ('cutter', 'neck', 'shank', 'holder') is read from where it sits against the
assembly's flute length, neck and stick-out, not from its position in the list (which depends on the tool).
"""
from __future__ import annotations

import math
from typing import Callable, Iterable, Optional

import numpy as np

from tmm_workbench.core import cancel
from tmm_workbench.core.errors import Cancelled, TmmError
from tmm_workbench.core.geometry.mesh import TriMesh
from tmm_workbench.core.kernel import native
from tmm_workbench.core.query.drop import DropSurface
from tmm_workbench.core.query.drop_direction import DirectionalDrop, check_starts
from tmm_workbench.core.tools.assembly import Body, ToolAssembly

Progress = Callable[[float], bool]
PIECES = ("cutter", "neck", "shank", "holder")
SET_BY_CUTTER, SET_BY_FLOOR = -1, -2  # the kernel's owner codes besides a body's position
NEEDLE_RADIUS = 1e-6  # mm: stands in for the cutter when only bodies are asked (rises <= r^2 / 2R over a ball)
_EPS = 1e-9


def body_pieces(assembly: ToolAssembly) -> tuple[str, ...]:
    """The piece each of `assembly.bodies()` belongs to: flutes above the APT profile are the 'cutter'; the
    neck is the cylinder of the neck diameter above the flutes; bodies from the holder face up the 'holder';
    the rest (the cone up to the shank, the shank) the 'shank'."""
    fl, so = assembly.flute_length, assembly.stick_out
    neck_top = fl + assembly.neck_length if assembly.neck_diameter is not None else fl
    out = []
    for z0, z1, r0, r1, _ in assembly.bodies():
        if z1 <= fl + _EPS:
            out.append("cutter")
        elif z0 >= so - _EPS and assembly.holder is not None:
            out.append("holder")
        elif z0 >= fl - _EPS and z1 <= neck_top + _EPS and r0 == r1:
            out.append("neck")
        else:
            out.append("shank")
    return tuple(out)


def _points(xy: np.ndarray) -> np.ndarray:
    try:
        pts = np.ascontiguousarray(xy, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise TmmError(f"drop points must be an (n, 2) array of numbers (mm), got {type(xy).__name__}") from exc
    if pts.ndim == 1 and pts.size % 2 == 0:  # x0, y0, x1, y1, ... as the kernel reads them
        pts = pts.reshape(-1, 2)
    if pts.ndim != 2 or pts.shape[1] != 2:
        raise TmmError(f"drop points must have shape (n, 2), got {pts.shape}")
    bad = np.flatnonzero(~np.isfinite(pts).all(axis=1))
    if len(bad):
        raise TmmError(f"drop point {int(bad[0])} is not finite: {pts[bad[0]].tolist()}")
    return pts


class AssemblyDrop:
    """A mesh indexed for drops of a tool assembly along -Z. Build once (or reuse a DropSurface's index),
    drop many points."""

    def __init__(self, mesh: TriMesh, assembly: ToolAssembly, surface: Optional[DropSurface] = None,
                 progress: Optional[Progress] = None) -> None:
        """Indexes `mesh` unless `surface` (a DropSurface of this mesh) is given, whose index is shared.
        `progress` as DropSurface: it, else the watched callback (core.cancel) may cancel the indexing."""
        if not isinstance(assembly, ToolAssembly):
            raise TmmError(f"assembly must be a ToolAssembly, got {assembly!r}")
        if surface is not None:
            if not isinstance(surface, DropSurface):
                raise TmmError(f"surface must be a DropSurface of the mesh or None, got {surface!r}")
            if mesh is not None and surface.mesh is not mesh:
                raise TmmError(f"surface indexes mesh '{surface.mesh.name}', not the mesh given "
                               f"('{getattr(mesh, 'name', mesh)}')")
        elif not isinstance(mesh, TriMesh):
            raise TmmError(f"mesh must be a TriMesh, got {mesh!r}")
        self.surface = surface if surface is not None else DropSurface(mesh, progress)
        self.mesh = self.surface.mesh
        self.assembly = assembly
        self.bodies: list[Body] = assembly.bodies()
        self.pieces: tuple[str, ...] = body_pieces(assembly)
        self._directional: Optional[DirectionalDrop] = None  # the last direction's index, kept for the next call

    @property
    def floor(self) -> float:
        """The default floor: the mesh's lowest point."""
        return float(self.surface.index.zmin)

    def piece(self, owner: int) -> str:
        """The name of what set a height: 'cutter' (-1 or the flutes), 'floor' (-2), or the body's piece."""
        if owner == SET_BY_CUTTER:
            return "cutter"
        if owner == SET_BY_FLOOR:
            return "floor"
        if not 0 <= owner < len(self.pieces):
            raise TmmError(f"owner {owner!r} is not -1, -2 or one of the {len(self.pieces)} bodies")
        return self.pieces[owner]

    def piece_names(self, owner: np.ndarray) -> np.ndarray:
        """piece() of every owner code, as an array of names."""
        names = np.array(["floor", "cutter", *self.pieces], dtype=object)
        return names[np.asarray(owner, dtype=np.int64) + 2]

    def heights(self, xy: np.ndarray, floor_z: Optional[float] = None, progress: Optional[Progress] = None,
                threads: int = 0) -> tuple[np.ndarray, np.ndarray]:
        """(z, owner) at the (n, 2) points: the lowest tip heights (never below `floor_z`, by default the mesh's
        lowest point) at which no piece comes closer to the mesh than its clearance, and what set each: -1 the
        cutter, -2 nothing above the floor, i body i of `assembly.bodies()` (its name: piece(i))."""
        return self._drop(self.assembly.cutter.native, self.bodies, xy, floor_z, progress, threads,
                          self.assembly.cutter_clearance)

    def heights_of(self, pieces: Iterable[str], xy: np.ndarray, floor_z: Optional[float] = None,
                   progress: Optional[Progress] = None, threads: int = 0) -> tuple[np.ndarray, np.ndarray]:
        """(z, owner) as heights() for the named pieces only ('neck', 'shank', 'holder'; 'cutter' takes the
        flutes above the profile): the cutter's profile is left out (a needle at the tip stands in, owner -1:
        none of the pieces reaches lower than the mesh under the tip). Owners are positions in
        `assembly.bodies()`."""
        wanted = set(pieces) if not isinstance(pieces, str) else {pieces}
        unknown = sorted(wanted - set(PIECES))
        if unknown:
            raise TmmError(f"unknown piece(s) {', '.join(map(repr, unknown))}: the pieces are {', '.join(PIECES)}")
        keep = [i for i, p in enumerate(self.pieces) if p in wanted]
        z, owner = self._drop(native.Cutter(NEEDLE_RADIUS, 0.0), [self.bodies[i] for i in keep], xy, floor_z,
                              progress, threads, 0.0)
        back = np.array([SET_BY_FLOOR, SET_BY_CUTTER, *keep], dtype=np.int32)
        return z, back[owner + 2]

    def face_heights(self, xy: np.ndarray, floor_z: Optional[float] = None, progress: Optional[Progress] = None,
                     threads: int = 0) -> tuple[np.ndarray, np.ndarray]:
        """(z, set_by): the lowest heights of the holder's face (the tip of a tool of stick-out 0) at which the
        holder alone keeps its clearance; set_by -2 where nothing is under the holder above `floor_z`. The
        holder's constraint on the tip of a tool of stick-out s is z - s. TmmError without a holder."""
        holder = self.assembly.holder
        if holder is None:
            raise TmmError(f"the assembly {self.assembly.describe()} has no holder")
        # The needle stands at the face's centre, under the holder's nose: it never sets a higher height.
        return self._drop(native.Cutter(NEEDLE_RADIUS, 0.0), holder.bodies(0.0, self.assembly.holder_clearance),
                          xy, floor_z, progress, threads, 0.0)

    def along(self, starts: np.ndarray, axis, direction, max_travel: float = math.inf,
              progress: Optional[Progress] = None, threads: int = 0) -> tuple[np.ndarray, np.ndarray]:
        """(travel, owner): the assembly translated along the unit `direction` from each (n, 3) start (tip at
        start + t * direction, t from -inf), its axis `axis` ((3,) or (n, 3) unit vectors), until a piece first
        comes as close to the mesh as its clearance: the travel t of that contact (max_travel where nothing is
        touched before it, owner -2) and what touched, as heights(). With the axis opposite to the direction this
        is heights() along that axis (travel = start height - tip height). Along a tilted axis the cutter is
        modelled up to where the first body starts and nothing above the holder. The mesh is indexed once per
        direction (the last one is kept)."""
        d = self._directional
        if d is None or not np.array_equal(d.direction, np.asarray(direction, dtype=np.float64).reshape(-1)):
            d = self._directional = DirectionalDrop(self.mesh, direction)
        pts, axes, _ = check_starts(starts, axis, d.direction, max_travel)
        rows = np.array(self.bodies, dtype=np.float64).reshape(-1, 5)
        if progress is None:
            progress = cancel.asker()
        try:
            travel, owner = native.drop_assembly_along(d.index, self.assembly.cutter.native, rows, pts, axes,
                                                       float(max_travel), float(self.assembly.cutter_clearance),
                                                       int(threads), progress)
        except native.Cancelled as exc:
            raise Cancelled("tool assembly drop cancelled") from exc
        except ValueError as exc:
            raise TmmError(f"{self.mesh.name}, {self.assembly.describe()}: {exc}") from exc
        return np.asarray(travel), np.asarray(owner, dtype=np.int32)

    def _drop(self, cutter: "native.Cutter", bodies: list[Body], xy: np.ndarray, floor_z: Optional[float],
              progress: Optional[Progress], threads: int, cutter_clearance: float) -> tuple[np.ndarray, np.ndarray]:
        pts = _points(xy)
        floor = self.floor if floor_z is None else floor_z
        if isinstance(floor, bool) or not isinstance(floor, (int, float, np.floating)) or math.isnan(floor):
            raise TmmError(f"drop floor_z must be a finite height (mm), got {floor_z!r}")
        rows = np.array(bodies, dtype=np.float64).reshape(-1, 5)
        if progress is None:  # deep in a helper the strategy's cancel still holds (core.cancel)
            progress = cancel.asker()
        try:
            z, owner = native.drop_assembly(self.surface.index, cutter, rows, pts, float(floor),
                                            float(cutter_clearance), int(threads), progress)
        except native.Cancelled as exc:
            raise Cancelled("tool assembly drop cancelled") from exc
        except ValueError as exc:  # the kernel's checks of the bodies, points and floor, with its message
            raise TmmError(f"{self.mesh.name}, {self.assembly.describe()}: {exc}") from exc
        return np.asarray(z), np.asarray(owner, dtype=np.int32)
