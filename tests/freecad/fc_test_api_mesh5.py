"""The 'TMM 5-axis Mesh' op headless: `api.run_mesh5` and `api_run.run("TMM_Mesh5", ...)` on a gently curved patch
(fc_test_mesh5's), computed and posted by the Tarus post (the default for a 5-axis op); the same G-code both ways;
bad tools, values, tilts, holder settings and posts refused by name before a document is made."""
from __future__ import annotations

import FreeCAD

from fc_helpers import OUT, FreeCADTestCase
from fc_test_mesh5 import D, TOL, patch_stl
from tmm_workbench.app.api import run_mesh5
from tmm_workbench.app.api_run import run
from tmm_workbench.core.errors import TmmError

ARGS = dict(diameter=D, tolerance=TOL, tilt_limit_deg=24.0, yaw_limit_deg=30.0, forward_step=3.0)
PROPS = dict(Tolerance=TOL, TiltLimit=24.0, YawLimit=30.0, ForwardStep=3.0)


def _motion(gcode: str) -> list[str]:
    """The motion lines of a G-code text (the post's date and comments left out)."""
    return [ln for ln in gcode.splitlines() if ln.startswith(("G0", "G1"))]


class RunMesh5(FreeCADTestCase):
    def test_run_mesh5_is_run_by_name_and_posts_for_the_tarus(self) -> None:
        named = run_mesh5(patch_stl(), **ARGS, progress=False, doc_name="TmmApiMesh5",
                          gcode_path=OUT / "api_mesh5.tarus.ngc")
        generic = run("TMM_Mesh5", patch_stl(), tool="endmill", diameter=D, **PROPS, progress=False,
                      doc_name="TmmRunMesh5")
        d = named.op.Proxy.diagnostics
        self.assertGreaterEqual(d["passes"], 2)
        self.assertIn(f"{d['passes']} passes", named.op.Mesh5Summary)
        self.assertEqual(named.job.PostProcessor, "tarus")   # the Job's post follows its first, 5-axis op
        self.assertTrue((OUT / "api_mesh5.tarus.ngc").is_file())
        self.assertIn(" A", named.gcode)                     # the Tarus's joints, not a 3-axis post's X Y Z
        self.assertGreater(len(_motion(generic.gcode)), 20)
        self.assertEqual(_motion(generic.gcode), _motion(named.gcode))
        self.assertAlmostEqual(generic.op.TiltLimit.Value, 24.0)

    def test_bad_tools_values_tilts_and_posts_are_refused_before_a_document_is_made(self) -> None:
        before = set(FreeCAD.listDocuments())
        stl = patch_stl()
        cases = [
            (lambda: run_mesh5(stl, tool="ballend"), "ball", "not taken by 5-axis mesh finishing"),
            (lambda: run("TMM_Mesh5", stl), "ball", "flat end mill or a bull-nose"),   # run's default tool
            (lambda: run_mesh5(stl, tolerance=0.0), "tolerance must be", "got 0"),
            (lambda: run_mesh5(stl, tilt_limit_deg=60.0), "tilt limit 60 deg is outside the machine's tilt range"),
            (lambda: run_mesh5(stl, least_tilt_deg=30.0, tilt_limit_deg=20.0),
             "least tilt 30 deg must not be above the tilt limit 20 deg"),
            (lambda: run_mesh5(stl, yaw_limit_deg=-5.0), "yaw_limit_deg must be"),
            (lambda: run_mesh5(stl, post="linuxcnc"), "post 'linuxcnc' cannot write the tool axes of TMM_Mesh5"),
            (lambda: run("TMM_Mesh5", stl, tool="endmill", post="grbl"), "post 'grbl' cannot write"),
            (lambda: run("TMM_Mesh5", stl, tool="endmill", TiltLimt=20.0), "did you mean TiltLimit?"),
            (lambda: run("TMM_Mesh5", stl, tool="endmill", GridStep=0.0), "posture grid step must be"),
            (lambda: run_mesh5(stl, stick_out=30.0), "stick_out is used with a holder only"),
            (lambda: run_mesh5(stl, holder="ER16 nut", stick_out=-1.0), "stick_out", "got -1"),
            (lambda: run_mesh5(stl, cleanup_diameter=0.0), "cleanup_diameter", "got 0"),
        ]
        for call, *said in cases:
            with self.subTest(said=said[0]), self.assertRaises(TmmError) as ctx:
                call()
            for fragment in said:
                self.assertIn(fragment, str(ctx.exception))
        self.assertEqual(set(FreeCAD.listDocuments()), before)
