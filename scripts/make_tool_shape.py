"""Writes TMM's ToolBit shape for the generalized APT cutter, resources/tools/Shape/tmm_apt.fcstd.
Run by `freecadcmd scripts/make_tool_shape.py` (made on FreeCAD 0.20; 1.0 and 1.1 read it too).

A ToolBit shape is a FreeCAD document with a PartDesign Body named `Body` (1.1 finds the shape by that
name) and a property bag labelled `Attributes` whose group-`Shape` properties become the bit's
parameters; the body's sketch takes its dimensions from them by expressions, as FreeCAD's own shapes do.
The profile is the one core.tools.Cutter and the kernel use (seed 000, section 3.5.2.2): from the tip on
the axis a bottom line at BottomAngle (beta1) above the horizontal, a corner arc of CornerRadius tangent to
it and to the side, the side at TaperAngle (beta2) from the axis through (Diameter/2, CuttingEdgeHeight),
then a line to the shank's top (ShankDiameter/2, Length) and back along the axis. The sketch only draws
the tool (the corner radius is drawn at least 1 um from its limits); TMM reads the parameters, not the solid."""
import os
import sys

import FreeCAD
import Sketcher

try:
    from Path.Base import PropertyBag  # FreeCAD 1.x
except ImportError:
    from PathScripts import PathPropertyBag as PropertyBag  # 0.20

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(globals().get("__file__") or sys.argv[-1])))
OUT = os.environ.get("TMM_SHAPE_OUT") or os.path.join(ROOT, "resources", "tools", "Shape", "tmm_apt.fcstd")

# name, type, group, default, description: the parameters app/tools.py maps to core.tools.Cutter
PARAMETERS = (
    ("Diameter", "App::PropertyLength", "Shape", "10 mm", "Diameter 2R at the cutting-edge height"),
    ("CornerRadius", "App::PropertyLength", "Shape", "2 mm", "Corner radius r (0: a sharp corner)"),
    ("BottomAngle", "App::PropertyAngle", "Shape", "5 deg", "Bottom angle beta1 above the horizontal, 0 to 90"),
    ("TaperAngle", "App::PropertyAngle", "Shape", "3 deg",
     "Taper angle beta2 of the side from the axis, -90 to 90, positive when the side widens upwards"),
    ("CuttingEdgeHeight", "App::PropertyLength", "Shape", "20 mm", "Cutting-edge height L_C above the tip"),
    ("Length", "App::PropertyLength", "Shape", "50 mm", "Overall length of the tool"),
    ("ShankDiameter", "App::PropertyLength", "Shape", "10 mm", "Shank diameter"),
    ("Flutes", "App::PropertyInteger", "Attributes", 2, "Number of flutes"),
    ("Chipload", "App::PropertyLength", "Attributes", "0 mm", "Chip load per tooth"),
)


def _drawn_corner_radius() -> str:
    """The corner radius the sketch draws: CornerRadius kept 1 um inside (0, r_max), since a zero radius or a
    bottom line of zero length (a ball corner, e = 0 and beta1 = 0) is no solid. r_max, the radius at which
    the arc centre reaches the axis, is d/2 cos(beta1 + beta2) / (cos beta1 - sin beta2), with d/2 the radius
    of the sharp corner (R - L_C tan beta2) / (1 - tan beta1 tan beta2) (seed 000, eq. 3.35)."""
    a = "<<Attributes>>."
    b1, b2 = a + "BottomAngle", a + "TaperAngle"
    half_d = f"({a}Diameter / 2 - {a}CuttingEdgeHeight * tan({b2})) / (1 - tan({b1}) * tan({b2}))"
    r_max = f"({half_d} * cos({b1} + {b2}) / (cos({b1}) - sin({b2})))"
    r = a + "CornerRadius"
    return f"{r} > {r_max} - 1 um ? {r_max} - 1 um : ({r} > 1 um ? {r} : 1 um)"


def make(path: str) -> None:
    doc = FreeCAD.newDocument("tmm_apt")
    body = doc.addObject("PartDesign::Body", "Body")
    body.Label = "TmmApt"
    bag = PropertyBag.Create("PropertyBag")
    bag.Label = "Attributes"
    for name, typ, group, value, desc in PARAMETERS:
        bag.Proxy.addCustomProperty(typ, name, group, desc)
        setattr(bag, name, FreeCAD.Units.Quantity(value) if isinstance(value, str) else value)

    sketch = body.newObject("Sketcher::SketchObject", "Sketch")
    xz = [f for f in body.Origin.OriginFeatures if f.Role == "XZ_Plane"][0]
    support = "AttachmentSupport" if hasattr(sketch, "AttachmentSupport") else "Support"  # renamed in 1.0
    setattr(sketch, support, (xz, [""]))
    sketch.MapMode = "FlatFace"
    V = FreeCAD.Vector
    # rough positions (the solver moves them): tip, corner tangent points, cutting-edge top, shank top, axis top
    p = [V(0, 0, 0), V(2.8, 0.2, 0), V(5, 2, 0), V(5.5, 20, 0), V(5, 50, 0), V(0, 50, 0)]
    import Part

    bottom = sketch.addGeometry(Part.LineSegment(p[0], p[1]))
    corner = sketch.addGeometry(Part.ArcOfCircle(Part.Circle(V(3, 2, 0), V(0, 0, 1), 2), -1.6, -0.05))
    side = sketch.addGeometry(Part.LineSegment(p[2], p[3]))
    neck = sketch.addGeometry(Part.LineSegment(p[3], p[4]))
    top = sketch.addGeometry(Part.LineSegment(p[4], p[5]))
    axis = sketch.addGeometry(Part.LineSegment(p[5], p[0]))
    c = Sketcher.Constraint
    for con in (c("Coincident", bottom, 1, -1, 1),          # the tip on the sketch origin
                c("Tangent", bottom, 2, corner, 1), c("Tangent", corner, 2, side, 1),
                c("Coincident", side, 2, neck, 1), c("Coincident", neck, 2, top, 1),
                c("Coincident", top, 2, axis, 1), c("Coincident", axis, 2, bottom, 1),
                c("Horizontal", top), c("PointOnObject", top, 2, -2)):
        sketch.addConstraint(con)
    named = {
        "beta1": (c("Angle", bottom, 0.087), "<<Attributes>>.BottomAngle"),
        "r": (c("Radius", corner, 2.0), _drawn_corner_radius()),
        "beta2": (c("Angle", side, 1.52), "90 deg - <<Attributes>>.TaperAngle"),
        "R": (c("DistanceX", side, 2, 5.0), "<<Attributes>>.Diameter / 2"),
        "Lc": (c("DistanceY", side, 2, 20.0), "<<Attributes>>.CuttingEdgeHeight"),
        "Rs": (c("DistanceX", neck, 2, 5.0), "<<Attributes>>.ShankDiameter / 2"),
        "L": (c("DistanceY", neck, 2, 50.0), "<<Attributes>>.Length"),
    }
    for name, (con, expression) in named.items():
        index = sketch.addConstraint(con)
        sketch.renameConstraint(index, name)
        sketch.setExpression(f"Constraints.{name}", expression)
    revolution = body.newObject("PartDesign::Revolution", "Revolution")
    revolution.Profile = sketch
    revolution.ReferenceAxis = (sketch, ["V_Axis"])
    revolution.Angle = 360.0
    sketch.Visibility = False
    body.Group = body.Group + [bag]  # where FreeCAD's shapes keep it (Body.addObject takes features only)
    doc.recompute()
    if not revolution.Shape.isValid() or revolution.Shape.Volume <= 0:
        raise SystemExit("the tmm_apt shape did not build")
    os.makedirs(os.path.dirname(path), exist_ok=True)
    doc.saveAs(path)
    print(f"wrote {path}: volume {revolution.Shape.Volume:.1f} mm^3, sketch dof {sketch.solve()}")
    FreeCAD.closeDocument(doc.Name)


make(OUT)
