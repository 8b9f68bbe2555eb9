"""The one run API (app.api_run.run): a mesh op by its registry name with its properties as the op declares them,
the same path as the named wrappers (run_surface, run_roughing), and every name, choice and number it is given
checked against the op's declarations before a document is made."""
from __future__ import annotations

import FreeCAD

from fc_helpers import OUT, SPHERE_ON_PLATE, FreeCADTestCase, core_work, seed_net
from tmm_workbench.app.api import run_roughing, run_surface
from tmm_workbench.app.api_run import run
from tmm_workbench.core.errors import TmmError


def _words(gcode: str) -> list[str]:
    """The motion lines of a G-code text (the post's date and comments left out)."""
    return [ln for ln in gcode.splitlines() if ln.startswith(("G0", "G1", "G2", "G3"))]


class RunByName(FreeCADTestCase):
    def test_the_surface_by_its_properties_is_run_surface(self) -> None:
        named = run_surface(str(SPHERE_ON_PLATE), stepover=2.0, sample_step=1.0, pattern="oneway", progress=False,
                            doc_name="TmmRunNamed")
        generic = run("TMM_Surface", str(SPHERE_ON_PLATE), StepOver=2.0, SampleStep=1.0, Pattern="OneWay",
                      BoundaryShape="Model",
                      progress=False, doc_name="TmmRunGeneric", gcode_path=OUT / "run_generic.ngc")
        self.assertGreater(len(_words(generic.gcode)), 100)
        self.assertEqual(_words(generic.gcode), _words(named.gcode))
        self.assertEqual(generic.op.Pattern, "OneWay")
        self.assertTrue((OUT / "run_generic.ngc").is_file())

    def test_roughing_by_its_properties_with_a_stock_margin(self) -> None:
        named = run_roughing(str(SPHERE_ON_PLATE), diameter=10.0, step_down=6.0, stock_margin=2.0, progress=False,
                             doc_name="TmmRunRoughNamed")
        generic = run("TMM_Roughing", str(SPHERE_ON_PLATE), tool="endmill", diameter=10.0, StepDown=6.0,
                      stock_margin=2.0, progress=False, doc_name="TmmRunRough")
        self.assertAlmostEqual(generic.job.Stock.Shape.BoundBox.XMin, named.job.Stock.Shape.BoundBox.XMin)
        self.assertEqual(_words(generic.gcode), _words(named.gcode))

    def test_every_name_choice_and_number_is_checked_before_a_document_is_made(self) -> None:
        before = set(FreeCAD.listDocuments())
        cases = [
            (dict(Stepover=1.0), "TMM_Surface has no property 'Stepover' (did you mean StepOver?)"),
            (dict(StepOverMode="Spiral"), "StepOverMode must be one of"),
            (dict(SampleStep=-0.5), "sample step must be"),
            (dict(StepOver=-1.0), "step-over must be a positive length, got -1"),
        ]
        for props, said in cases:
            with self.subTest(props=props), self.assertRaises(TmmError) as ctx:
                run("TMM_Surface", str(SPHERE_ON_PLATE), progress=False, **props)
            self.assertIn(said, str(ctx.exception))
        with self.assertRaises(TmmError) as ctx:
            run("TMM_Multipoint", str(SPHERE_ON_PLATE))
        self.assertIn("face_source must be a control net", str(ctx.exception))
        with self.assertRaises(TmmError) as ctx:
            run("TMM_Multipoint", seed_net(), stock_margin=2.0)
        self.assertIn("stock_margin is not used by TMM_Multipoint", str(ctx.exception))
        with self.assertRaises(TmmError) as ctx:
            run("TMM_Drill", str(SPHERE_ON_PLATE))
        self.assertIn("TMM_Surface, TMM_Roughing, TMM_Waterline, TMM_Mesh5, TMM_Multipoint", str(ctx.exception))
        self.assertEqual(set(FreeCAD.listDocuments()), before)


class SharedToolController(FreeCADTestCase):
    def test_ops_of_one_tool_share_its_controller_and_the_call_is_checked_against_it(self) -> None:
        """tool_controller: a second op cuts with the first one's controller (one tool in the Job, no tool change
        in its G-code); a call naming another tool, other feeds, no job or another Job's controller is refused by
        name, and nothing is added to the Job."""
        first = run_roughing(str(SPHERE_ON_PLATE), diameter=10.0, step_down=6.0, horiz_feed=1200.0, progress=False,
                             doc_name="TmmSharedTc")
        tc = first.op.ToolController
        second = run_surface(None, job=first, tool="endmill", diameter=10.0, horiz_feed=1200.0, tool_controller=tc,
                             stepover=4.0, sample_step=1.0, progress=False, label="Finish with the roughing's tool")
        self.assertIs(second.op.ToolController, tc)
        self.assertEqual(second.op.Label, "Finish with the roughing's tool")
        self.assertIn("(Finish with the roughing's tool)", second.gcode)   # named before it computed
        self.assertEqual(len(first.job.Tools.Group), 1)
        ops = len(first.job.Operations.Group)
        other = run_roughing(str(SPHERE_ON_PLATE), diameter=6.0, step_down=6.0, progress=False, doc_name="TmmOtherTc")
        cases = [(dict(job=first, diameter=8.0, horiz_feed=1200.0), "holds a flat D10"),
                 (dict(job=first, diameter=10.0), "horiz_feed 1000 is not tool_controller"),
                 (dict(diameter=10.0, horiz_feed=1200.0), "give job= as well"),
                 (dict(job=other, diameter=10.0, horiz_feed=1200.0), "is not a tool controller of Job")]
        for kwargs, said in cases:
            with self.subTest(said=said), self.assertRaises(TmmError) as ctx:
                run_surface(None, tool="endmill", tool_controller=tc, stepover=4.0, progress=False, **kwargs)
            self.assertIn(said, str(ctx.exception))
        self.assertEqual(len(first.job.Operations.Group), ops)


class FaceOpByName(FreeCADTestCase):
    # TMM's registry against its API (the 5-axis op in a Job, its post: fc_test_multipoint, fc_test_posts5)
    @core_work
    def test_multipoint_by_its_properties_is_run_multipoint(self) -> None:
        from tmm_workbench.app.api import run_multipoint
        from tmm_workbench.core.tools.cutter import Cutter

        named = run_multipoint(seed_net(), side_step=18.0, forward_step=4.0, pass_spacing="even", posts=("tarus",),
                               progress=False, doc_name="TmmRunMpNamed")
        generic = run("TMM_Multipoint", seed_net(), tool=Cutter.torus(6.7, 6.0), SideStep=18.0, ForwardStep=4.0,
                      PassSpacing="Even", ToolShape="RoundInsert", post="tarus", progress=False,
                      doc_name="TmmRunMpGeneric")
        self.assertGreater(len(_words(generic.gcode)), 20)
        self.assertEqual(_words(generic.gcode), _words(named.gcode["tarus"]))
        self.assertEqual(named.face[1], "Face1")
        self.assertAlmostEqual(generic.op.SafeHeight.Value, named.op.SafeHeight.Value)
