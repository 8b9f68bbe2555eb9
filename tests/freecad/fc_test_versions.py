"""Which FreeCAD runs TMM: this one does (0.20, 1.0 or 1.1); an older one or one whose CAM modules moved is
named with what failed; the kernel that is missing is named with the command that installs it."""
from __future__ import annotations

import unittest

from fc_helpers import FreeCADTestCase
from tmm_workbench.app import compat
from tmm_workbench.core import kernel


class Versions(FreeCADTestCase):
    def test_this_freecad_is_supported(self) -> None:
        self.assertEqual(compat.support_problem(), "")
        self.assertIn(compat.freecad_version(), ((0, 20), (1, 0), (1, 1)))
        self.assertEqual(compat.command_prefix(), "Path_" if compat.freecad_version() < (1, 0) else "CAM_")

    def test_older_freecad_is_named(self) -> None:
        text = compat.support_problem(version=(0, 19))
        self.assertIn("FreeCAD 0.19 is not supported", text)
        self.assertIn("0.20 or later", text)

    def test_moved_cam_module_is_named(self) -> None:
        moved = dict(compat._APP_MODULES, op=("Path.Op.NoSuchBase",))
        text = compat.support_problem(version=(1, 2), modules=moved)
        self.assertIn("FreeCAD 1.2 is not supported", text)
        self.assertIn("'op' (Path.Op.NoSuchBase)", text)

    def test_kernel_message_names_both_fixes(self) -> None:
        self.assertTrue(kernel.available())
        missing = kernel._Kernel()
        saved = kernel.MODULES
        kernel.MODULES = ("tmm_workbench._no_such_native",)
        try:
            with self.assertRaises(kernel.KernelMissing) as ctx:
                missing.load()
        finally:
            kernel.MODULES = saved
        self.assertIn("bash scripts/setup.sh", str(ctx.exception))
        self.assertIn("pip install ./native", str(ctx.exception))


if __name__ == "__main__":
    unittest.main()
