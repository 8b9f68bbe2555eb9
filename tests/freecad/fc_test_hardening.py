"""Hardening on the FreeCAD side (the op's invalid inputs are in fc_test_errors): the API refuses bad numbers
by name; a document saved on a machine without the kernel keeps every TMM object
and recomputes once the kernel is back."""
from __future__ import annotations

import json
import math
import shutil
import subprocess
import textwrap
import time
import unittest
from pathlib import Path

import FreeCAD
import numpy as np

from fc_helpers import OUT, FreeCADTestCase, bump_stl
from tmm_workbench.app.api import run_multipoint, run_surface
from tmm_workbench.core.errors import TmmError

ROOT = Path(__file__).resolve().parents[2]


class ApiBadNumbers(FreeCADTestCase):
    def test_surface_numbers_are_refused_by_name(self) -> None:
        for kwargs, fragment in (
                (dict(diameter=math.nan), "diameter must be a positive length, got nan"),
                (dict(diameter=0.0), "diameter must be a positive length, got 0"),
                (dict(sample_step=1e-6), "sample step 1e-06 mm"),
                (dict(stepover=math.inf), "stepover must be a positive length, got inf"),
                (dict(margin=math.nan), "margin must be a finite number of mm, got nan"),
                (dict(safe_height=math.nan), "safe_height must be a finite number of mm, got nan"),
                (dict(horiz_feed=0.0), "horiz_feed must be > 0 mm/min, got 0")):
            with self.subTest(**{k: str(v) for k, v in kwargs.items()}):
                t0 = time.perf_counter()
                with self.assertRaises(TmmError) as ctx:
                    run_surface(bump_stl(), progress=False,
                                **{**dict(boundary="model", stepover=2.0, sample_step=1.0), **kwargs})
                self.assertIn(fragment, str(ctx.exception))
                self.assertLess(time.perf_counter() - t0, 5.0)
        self.assertEqual([d for d in FreeCAD.listDocuments() if d.startswith("TMM")], [])

    def test_multipoint_numbers_are_refused_by_name(self) -> None:
        net = np.zeros((4, 4, 3))
        net[..., 0], net[..., 1] = np.meshgrid(np.linspace(0, 60, 4), np.linspace(0, 60, 4), indexing="ij")
        for kwargs, fragment in ((dict(Ri=math.nan), "Ri must be a length >= 0, got nan"),
                                 (dict(side_step=0.0), "side_step must be a positive length, got 0"),
                                 (dict(tilt_limit_deg=95.0), "tilt_limit_deg must be in (0, 90) deg, got 95"),
                                 (dict(side_step=0.01, forward_step=0.01), "tool positions")):
            with self.subTest(**{k: str(v) for k, v in kwargs.items()}):
                with self.assertRaises(TmmError) as ctx:
                    run_multipoint(net, progress=False, **{**dict(Ro=3.0, Ri=2.0), **kwargs})
                self.assertIn(fragment, str(ctx.exception))


# Runs in a second freecadcmd: the add-on copied without its kernel first on sys.path (FreeCAD's Mod link
# already imported the real package: it is forgotten), opens the document, recomputes, saves a copy.
CHILD = textwrap.dedent('''
    import json, sys
    for name in [m for m in sys.modules if m == "tmm_workbench" or m.startswith("tmm_workbench.")]:
        del sys.modules[name]
    sys.path.insert(0, {copy!r})
    import FreeCAD
    import tmm_workbench
    from tmm_workbench.core import kernel
    out = {{"package": tmm_workbench.__file__, "kernel": kernel.available()}}
    doc = FreeCAD.openDocument({doc!r})
    ops = [o for o in doc.Objects if type(getattr(o, "Proxy", None)).__name__.startswith("ObjectTmm")]
    out["ops"] = sorted(o.Name for o in ops)
    for o in ops:
        o.touch()
    doc.recompute()
    out["valid"] = [o.isValid() for o in ops]
    out["status"] = [o.getStatusString() for o in ops]
    out["commands"] = [len(o.Path.Commands) for o in ops]
    doc.saveAs({saved!r})
    with open({result!r}, "w") as f:
        json.dump(out, f)
    raise SystemExit(0)
''')


class WithoutKernel(FreeCADTestCase):
    def test_document_keeps_its_tmm_objects_without_the_kernel(self) -> None:
        original, saved, result = OUT / "nk_original.FCStd", OUT / "nk_saved.FCStd", OUT / "nk_result.json"
        r = run_surface(bump_stl(), stepover=2.0, sample_step=1.0, boundary="model", progress=False,
                        fcstd_path=original, doc_name="TMMnk")
        FreeCAD.closeDocument(r.doc.Name)

        copy = OUT / "nokernel"
        shutil.rmtree(copy, ignore_errors=True)
        shutil.copytree(ROOT / "tmm_workbench", copy / "tmm_workbench",
                        ignore=shutil.ignore_patterns("_native*", "__pycache__"))
        script = OUT / "nk_child.py"
        script.write_text(CHILD.format(copy=str(copy), doc=str(original), saved=str(saved), result=str(result)))
        freecadcmd = shutil.which("freecadcmd") or shutil.which("FreeCADCmd")
        proc = subprocess.run([freecadcmd, str(script)], cwd=OUT, capture_output=True, text=True, timeout=300)
        self.assertTrue(result.exists(), proc.stdout + proc.stderr)
        child = json.loads(result.read_text())
        self.assertTrue(child["package"].startswith(str(copy)), child)
        self.assertFalse(child["kernel"], "the copy must not find a kernel")
        self.assertEqual(child["ops"], ["TMM_Surface"], child)   # restored with its proxy
        self.assertEqual(child["valid"], [False])
        self.assertIn("native kernel", child["status"][0])
        self.assertIn("scripts/setup.sh", child["status"][0])
        self.assertEqual(child["commands"], [0])                  # no stale path

        doc = FreeCAD.openDocument(str(saved))                  # the kernel is back
        try:
            ops = [o for o in doc.Objects if type(getattr(o, "Proxy", None)).__name__ == "ObjectTmmSurface"]
            self.assertEqual(len(ops), 1)
            ops[0].Proxy.progress_enabled = False
            ops[0].touch()
            doc.recompute()
            self.assertTrue(ops[0].isValid(), ops[0].getStatusString())
            self.assertGreater(len(ops[0].Path.Commands), 10)
        finally:
            FreeCAD.closeDocument(doc.Name)


if __name__ == "__main__":
    unittest.main()
