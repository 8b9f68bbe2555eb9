"""The places an op's shank or holder kept its tool off the model (the op's HolderRegions, app.tool_assembly),
drawn on the 3D view as orange points under the op's node: a switch that follows the view property
ShowHolderRegions and hides with the op."""
from __future__ import annotations

from typing import Any

COLOUR = (1.0, 0.45, 0.0)
POINT_SIZE = 5.0
NAME = "TmmHolderRegions"
SHOW = "ShowHolderRegions"


def attach(vobj: Any) -> Any:
    """The switch under the op's root node (and the view property), drawn from the op's regions."""
    from pivy import coin

    if not hasattr(vobj, SHOW):
        vobj.addProperty("App::PropertyBool", SHOW, "Tool holder",
                         "Draw where the shank or holder kept the tool off the model (material left there)")
        setattr(vobj, SHOW, True)
    switch = coin.SoSwitch()
    switch.setName(NAME)
    vobj.RootNode.addChild(switch)
    refresh(switch, vobj)
    return switch


def refresh(switch: Any, vobj: Any) -> None:
    """Redraws the op's regions (none drawn when hidden, empty, or not computed with a holder)."""
    from pivy import coin

    if switch is None or vobj is None:
        return
    switch.removeAllChildren()
    switch.whichChild = coin.SO_SWITCH_NONE
    points = list(getattr(vobj.Object, "HolderRegions", []) or [])
    if not points or not getattr(vobj, SHOW, True):
        return
    sep = coin.SoSeparator()
    material = coin.SoMaterial()
    material.diffuseColor = COLOUR
    material.emissiveColor = COLOUR
    style = coin.SoDrawStyle()
    style.pointSize = POINT_SIZE
    coords = coin.SoCoordinate3()
    coords.point.setValues(0, len(points), [(p.x, p.y, p.z) for p in points])
    for node in (style, material, coords, coin.SoPointSet()):
        sep.addChild(node)
    switch.addChild(sep)
    switch.whichChild = 0


def drawn(switch: Any) -> int:
    """Points drawn now (0 when hidden)."""
    if switch is None or switch.whichChild.getValue() < 0 or switch.getNumChildren() == 0:
        return 0
    return int(switch.getChild(0).getChild(2).point.getNum())
