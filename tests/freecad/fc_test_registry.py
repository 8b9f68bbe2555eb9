"""The strategy house: every op in the registry is a strategy module (params dataclass, compute,
supported tools), an op entry whose property table names params fields (defaults from the dataclass, one
place), and a Create that the headless API reaches through the registry."""
from __future__ import annotations

import inspect
import unittest
from dataclasses import MISSING, fields

from fc_helpers import FreeCADTestCase, bump_stl, job_with_op, new_doc
from tmm_workbench.app import registry
from tmm_workbench.core.params import StrategyParams


class Registry(FreeCADTestCase):
    def test_every_entry_is_a_complete_room(self) -> None:
        self.assertEqual([e.name for e in registry.OPS],
                         ["TMM_Surface", "TMM_Multipoint", "TMM_Roughing", "TMM_Waterline", "TMM_Mesh5"])
        self.assertEqual(len({e.view_kind for e in registry.OPS}), len(registry.OPS))  # one view hook each
        for entry in registry.OPS:
            with self.subTest(op=entry.name):
                app, core = entry.app(), entry.core()
                self.assertEqual(app.OP_NAME, entry.name)
                self.assertTrue(callable(app.Create) and callable(app.SetupProperties))
                proxy = next(c for _, c in inspect.getmembers(app, inspect.isclass)
                             if c.__module__ == app.__name__ and getattr(c, "PARAMS", None) is not None)
                params = proxy.PARAMS
                self.assertTrue(issubclass(params, StrategyParams))
                self.assertIs(proxy.STRATEGY, core)  # the estimate's strategy is the registry's
                self.assertTrue(callable(proxy.ESTIMATE))
                self.assertTrue(callable(core.compute))
                self.assertTrue(set(core.SUPPORTED_TOOLS) <= {"ball", "flat", "bull", "general"})
                by_name = {f.name: f for f in fields(params)}
                defaults = proxy.defaults()
                for row in proxy.PROPERTIES:
                    if not row.field:
                        continue
                    self.assertIn(row.field, by_name, f"{row.name} names no field of {params.__name__}")
                    f = by_name[row.field]
                    if f.default is MISSING or f.default is None:
                        continue
                    value = defaults[row.name]
                    if row.name in getattr(proxy, "NEW_OP_DEFAULTS", {}):  # a new op's declared own default
                        self.assertIn(value, proxy.CHOICES[row.name], row.name)
                        continue
                    if row.name in proxy.CHOICES:
                        value = proxy.CHOICES[row.name][value]
                    self.assertEqual(value, f.default, row.name)
        with self.assertRaises(KeyError):
            registry.entry("TMM_Nothing")

    def test_properties_map_to_params(self) -> None:
        doc = new_doc("TmmRegistry")
        _, _, op = job_with_op(doc, str(bump_stl()), values={"StepOver": 1.5, "Pattern": "OneWay",
                                                            "BoundaryShape": "Model"})
        params = op.Proxy.params_from(op, boundary=(0.0, 0.0, 1.0, 1.0))
        self.assertEqual((params.stepover, params.pattern, params.sample_step), (1.5, "oneway", 1.0))

    def test_roughing_and_waterline_properties_map_to_params(self) -> None:
        doc = new_doc("TmmRegistryZ")
        _, _, surface = job_with_op(doc, str(bump_stl()))
        job = surface.Proxy.job
        rough = registry.create("TMM_Roughing", job, {"StlFile": str(bump_stl()), "StepOver": 55.0,
                                                      "Entry": "Ramp", "LayerMode": "Tolerance",
                                                      "Direction": "Conventional", "StockToLeave": 0.25})
        rough.Proxy.progress_enabled = False
        doc.recompute()  # evaluates the axial stock's expression
        params = rough.Proxy.params_from(rough)
        self.assertEqual((params.stepover_percent, params.entry, params.layer_mode, params.direction),
                         (55.0, "ramp", "tolerance", "conventional"))
        self.assertEqual((params.stock_to_leave, params.stock_to_leave_axial), (0.25, 0.25))  # axial follows
        water = registry.create("TMM_Waterline", job, {"StlFile": str(bump_stl()), "StepDown": 0.75,
                                                       "Direction": "Conventional"})
        water.Proxy.progress_enabled = False
        params = water.Proxy.params_from(water, boundary=(0.0, 0.0, 1.0, 1.0))
        self.assertEqual((params.step_down, params.direction), (0.75, "conventional"))


if __name__ == "__main__":
    unittest.main()


class SurfaceStages(FreeCADTestCase):
    """The Surface op, its panel and run_surface are derived from its stages' declarations (app.stages)."""

    def test_every_declared_widget_is_in_the_panel(self) -> None:
        import xml.etree.ElementTree as ET
        from pathlib import Path

        from tmm_workbench.app import op_surface, stages

        ui = Path(__file__).resolve().parents[2] / "resources" / "panels" / "surface_op.ui"
        names = {w.get("name") for w in ET.parse(ui).iter("widget")}
        for table in stages.widgets(op_surface.STAGES):
            for widget, prop in table.items():
                self.assertIn(widget, names, f"{prop}: widget {widget} is not in {ui.name}")

    def test_every_run_surface_argument_is_declared(self) -> None:
        from tmm_workbench.app import api, api_run, op_surface
        from tmm_workbench.core.stage import api_names

        declared = api_names(op_surface.STAGES)
        own = set(inspect.signature(api_run.run).parameters) - {"op", "properties"}
        for name in inspect.signature(api.run_surface).parameters:
            self.assertTrue(name in declared or name in own, f"run_surface({name}=) is declared by no stage")
        self.assertFalse(declared - set(inspect.signature(api.run_surface).parameters),
                         "a stage declares an argument run_surface does not take")

    def test_a_property_declared_twice_is_refused(self) -> None:
        from tmm_workbench.app import op_surface, stages
        from tmm_workbench.core.strategies.surface import pattern

        with self.assertRaisesRegex(ValueError, "StepOver is declared by two stages"):
            stages.properties(op_surface.STAGES + (pattern.STAGE,))
