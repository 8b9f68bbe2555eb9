"""Runs TMM's FreeCAD-side unittest modules inside `freecadcmd` and exits non-zero on failure.

freecadcmd returns 0 even when a script raises, but SystemExit(n) propagates, so every outcome ends
in an explicit SystemExit. Modules to run: env TMM_FC_MODULES (comma-separated names of fc_test_*.py
files in this folder). Scratch files go to env TMM_TEST_OUT (a temporary folder by default).
Usage: TMM_FC_MODULES=fc_test_op freecadcmd tests/freecad/fc_runner.py
(pytest does this per module: tests/freecad/test_freecad_app.py). FreeCAD's own runner works too,
with the add-on linked into its Mod folder: freecadcmd -t fc_test_op -M <repo>/tests/freecad
"""
import os
import sys
import time
import traceback
import unittest

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))


class TimedResult(unittest.TextTestResult):
    """Each test's wall time (the suite's time budget: which FreeCAD test costs what, on every version)."""

    def startTest(self, test: unittest.TestCase) -> None:
        self._started = time.monotonic()
        super().startTest(test)

    def stopTest(self, test: unittest.TestCase) -> None:
        super().stopTest(test)
        self.times = getattr(self, "times", []) + [(time.monotonic() - self._started, test.id())]


def main() -> int:
    # Did the add-on's Init.py run (FreeCAD's Mod link) and wrap the post search path? Recorded
    # before the tests' helpers install the wrapper themselves.
    prefs = sys.modules.get("PathScripts.PathPreferences") or sys.modules.get("Path.Preferences")
    wrapped = bool(prefs and getattr(prefs.searchPathsPost, "_tmm_wrapped", False))
    os.environ["TMM_FC_INIT_WRAPPED_POSTS"] = "1" if wrapped else "0"
    for p in (HERE, ROOT):
        if p not in sys.path:
            sys.path.insert(0, p)
    import tmm_workbench

    origin = os.path.realpath(os.path.dirname(os.path.dirname(tmm_workbench.__file__)))
    if origin != os.path.realpath(ROOT):
        sys.stderr.write(f"tmm_workbench comes from {origin}, not from this checkout {ROOT}: FreeCAD's Mod "
                         f"folder links another copy (scripts/setup.sh links this one)\n")
        return 1
    names = [n.strip() for n in os.environ.get("TMM_FC_MODULES", "").split(",") if n.strip()]
    if not names:
        names = sorted(f[:-3] for f in os.listdir(HERE) if f.startswith("fc_test_") and f.endswith(".py"))
    suite = unittest.defaultTestLoader.loadTestsFromNames(names)
    left_out = []
    if os.environ.get("TMM_FC_VERSIONED") == "1":
        suite, left_out = versioned(suite)
    result = unittest.TextTestRunner(stream=sys.stderr, verbosity=2, resultclass=TimedResult).run(suite)
    for seconds, name in sorted(getattr(result, "times", []), reverse=True):
        sys.stderr.write(f"TMM-FC-TIME {seconds:7.1f} s {name}\n")
    sys.stderr.write(f"TMM-FC-RESULT {'PASS' if result.wasSuccessful() else 'FAIL'} "
                     f"run={result.testsRun} failures={len(result.failures)} errors={len(result.errors)}\n")
    for name in left_out:
        sys.stderr.write(f"TMM-FC-LEFT-OUT {name} (core work, run on the host's FreeCAD)\n")
    return 0 if result.wasSuccessful() and result.testsRun + len(left_out) > 0 else 1


def versioned(suite: unittest.TestSuite) -> tuple[unittest.TestSuite, list[str]]:
    """The tests of `suite` whose outcome can depend on FreeCAD's version, and the ids of those left out: marked
    fc_helpers.core_work (TMM's core through FreeCAD, run on the host's FreeCAD; scripts/env_test.sh asks)."""
    from fc_helpers import CORE_WORK

    kept, left_out = unittest.TestSuite(), []
    for test in suite:  # in order: a class's tests stay together (its setUpClass runs once)
        if isinstance(test, unittest.TestSuite):
            inner, out = versioned(test)
            kept.addTest(inner)
            left_out += out
        elif getattr(getattr(test, test._testMethodName, None), CORE_WORK, False):
            left_out.append(test.id())
        else:
            kept.addTest(test)
    return kept, left_out


try:
    code = main()
except BaseException:  # noqa: B902 - anything, including import errors, is a failure
    traceback.print_exc()
    code = 1
sys.stderr.flush()
sys.stdout.flush()
raise SystemExit(code)
