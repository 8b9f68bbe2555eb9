"""What the ops that machine a model as a mesh share (Surface, Waterline, Roughing): the model's properties and
the mesh they give (`StlFile`, then `Model`, then the Job's model: Part solids tessellated within
`LinearDeflection`, TMM's stand-in boxes replaced by the meshes they stand for), the XY boundary from the stock
or the model, and the Path commands of a tool path (feeds from the tool controller).
"""
from __future__ import annotations

from typing import Any, Callable, Optional

from tmm_workbench.app import geometry, hooks, model_proxy, op_base, path_build, stages
from tmm_workbench.app.compat import PathOp, PathUtils
from tmm_workbench.app.op_base import Prop
from tmm_workbench.core.errors import TmmError
from tmm_workbench.core.geometry.mesh import TriMesh
from tmm_workbench.core.stage import Field, Stage
from tmm_workbench.core.toolpath import Toolpath

MODEL_STAGE = Stage("model", (
    Field("StlFile", "file", "Model", "STL file to machine (takes precedence over Model)"),
    Field("Model", "link", "Model", "Mesh or Part object to machine; empty: the Job's model"),
    Field("LinearDeflection", "length", "Model", "Tessellation tolerance for Part models",
          default=geometry.DEFAULT_DEFLECTION_MM, widget="linearDeflection"),
))
MODEL_PROPERTIES: list[Prop] = stages.properties((MODEL_STAGE,))
MODEL_DEFAULTS: dict[str, Any] = stages.defaults((MODEL_STAGE,))


class MeshOp(op_base.TmmOp):
    """An op computed on the model's mesh. `VIEW_KIND`: the view provider hooks attach on restore. Transient
    results of the last run (not saved): `toolpath`, `mesh`."""

    VIEW_KIND = "op"
    toolpath: Optional[Toolpath] = None
    mesh: Optional[TriMesh] = None

    def opFeatures(self, obj: Any) -> int:
        return PathOp.FeatureTool | PathOp.FeatureHeights | PathOp.FeatureCoolant

    def opOnDocumentRestored(self, obj: Any) -> None:
        self.ensure_properties(obj, restoring=True)
        hooks.attach_view(self.VIEW_KIND, obj)  # a document saved headless has no view providers
        job = PathUtils.findParentJob(obj)
        if job is not None:
            hooks.attach_view("job", job)

    def model_mesh(self, obj: Any) -> TriMesh:
        deflection = obj.LinearDeflection.Value
        if obj.StlFile:
            return geometry.mesh_from_stl(obj.StlFile)
        if obj.Model is not None:
            return model_proxy.mesh_of_model(obj.Model, deflection)
        models = list(self.model or [])
        if not models:
            raise TmmError("nothing to machine: set StlFile or Model, or give the Job a model")
        return geometry.combine([model_proxy.mesh_of_model(m, deflection) for m in models])

    def boundary(self, obj: Any, mesh: TriMesh, reach: float = 0.0) -> tuple[float, float, float, float]:
        """The Stock's or the model's XY box (the latter grown by `reach`: a waterline's tool goes round the
        model's outside walls), grown by BoundaryMargin."""
        if obj.BoundaryShape == "Stock":
            if self.stock is None or self.stock.Shape.isNull():
                raise TmmError("boundary 'Stock': the Job has no stock")
            bb = self.stock.Shape.BoundBox
            x0, y0, x1, y1 = bb.XMin, bb.YMin, bb.XMax, bb.YMax
        else:
            lo, hi = mesh.bounds
            x0, y0 = float(lo[0]) - reach, float(lo[1]) - reach
            x1, y1 = float(hi[0]) + reach, float(hi[1]) + reach
        m = obj.BoundaryMargin.Value
        return (x0 - m, y0 - m, x1 + m, y1 + m)

    def add_moves(self, toolpath: Toolpath, plunge_angle_deg: float = 45.0, clearance: Optional[float] = None,
                  progress: Optional[Callable[[float], bool]] = None) -> None:
        """The tool path's commands at the end of the op's command list (app.path_build.rows_of: G0 for rapids,
        no F; G1 at the vertical feed for plunges and for cutting moves going down more steeply than
        `plunge_angle_deg`, at the horizontal feed for the others; G2/G3 in their plane; with `clearance`, a
        Z-only rapid to it first: after a tool change the tool goes up before it moves in X and Y), made
        in chunks with `progress` between them; the rows are kept for the readers of the Path."""
        if not (0.0 <= plunge_angle_deg <= 90.0):
            raise TmmError(f"plunge angle must be in [0, 90] deg, got {plunge_angle_deg:g}")
        rows = path_build.rows_of(toolpath, self.horizFeed, self.vertFeed, plunge_angle_deg, clearance)
        self.add_rows(rows, progress)
