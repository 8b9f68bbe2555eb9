"""Marks on an op's 3D view of where it left material on purpose or found it: the places its shank or holder kept
the tool off the model (HolderRegions, app.tool_assembly: orange), a rest op's rest cells (RestRegions,
app.rest_source: magenta) and what the 5-axis mesh op left for clean-up (CleanupRegions, app.op_mesh5: red).
Points under the op's node, each kind in a switch that follows its view property and hides with the op."""
from __future__ import annotations

from typing import Any, NamedTuple


class Mark(NamedTuple):
    prop: str          # the op's vector list
    show: str          # the view property that shows it
    colour: tuple
    tip: str


MARKS = (
    Mark("HolderRegions", "ShowHolderRegions", (1.0, 0.45, 0.0),
         "Draw where the shank or holder kept the tool off the model (material left there)"),
    Mark("RestRegions", "ShowRestRegions", (0.85, 0.0, 0.85),
         "Draw the rest cells this op machines (where earlier ops or a reference tool left material)"),
    Mark("CleanupRegions", "ShowCleanupRegions", (0.9, 0.0, 0.0),
         "Draw where no pass finishes within the tolerance (the 5-axis mesh op's empty C-space), left for clean-up"),
)
POINT_SIZE = 5.0


def attach(vobj: Any) -> dict:
    """{op property: switch} under the op's root node (and their view properties), drawn from the op."""
    from pivy import coin

    switches = {}
    for mark in MARKS:
        if not hasattr(vobj, mark.show):
            vobj.addProperty("App::PropertyBool", mark.show, "Marks", mark.tip)
            setattr(vobj, mark.show, True)
        switch = coin.SoSwitch()
        switch.setName(f"Tmm{mark.prop}")
        vobj.RootNode.addChild(switch)
        switches[mark.prop] = switch
        refresh(switches, vobj, mark.prop)
    return switches


def refresh(switches: dict, vobj: Any, prop: str) -> None:
    """Redraws the marks of `prop` (a property or its view property's name; Visibility: all of them); none when
    hidden, empty, or the op is hidden (the marks hang under the op's root node, beside its display modes)."""
    from pivy import coin

    if prop == "Visibility":
        for m in MARKS:
            refresh(switches, vobj, m.prop)
        return
    mark = next((m for m in MARKS if prop in (m.prop, m.show)), None)
    if mark is None or vobj is None or mark.prop not in (switches or {}):
        return
    switch = switches[mark.prop]
    switch.removeAllChildren()
    switch.whichChild = coin.SO_SWITCH_NONE
    points = list(getattr(vobj.Object, mark.prop, []) or [])
    if not points or not getattr(vobj, mark.show, True) or not getattr(vobj, "Visibility", True):
        return
    sep = coin.SoSeparator()
    material = coin.SoMaterial()
    material.diffuseColor = mark.colour
    material.emissiveColor = mark.colour
    style = coin.SoDrawStyle()
    style.pointSize = POINT_SIZE
    coords = coin.SoCoordinate3()
    coords.point.setValues(0, len(points), [(p.x, p.y, p.z) for p in points])
    for node in (style, material, coords, coin.SoPointSet()):
        sep.addChild(node)
    switch.addChild(sep)
    switch.whichChild = 0


def drawn(switches: dict, prop: str) -> int:
    """Points of `prop` drawn now (0 when hidden)."""
    switch = (switches or {}).get(prop)
    if switch is None or switch.whichChild.getValue() < 0 or switch.getNumChildren() == 0:
        return 0
    return int(switch.getChild(0).getChild(2).point.getNum())
