"""How pytest orders the tests, for runs with pytest-xdist (`-n 2`: scripts/test.sh, scripts/env_test.sh).

The longest tests start first, so that no worker is left with one of them at the end while the other idles: the
GUI tests (tests/gui, each a FreeCAD under its own Xvfb, half a minute to a minute), then the FreeCAD modules
(tests/freecad, one freecadcmd each), then the rest in their usual order. The GUI tests run on every worker: a
GUI FreeCAD waits on its event loop much of the time (one worker of GUI tests kept 1.5 of the 2 cores busy),
and each worker's Xvfb displays start from a number of its own (tests/gui/launch.py: `xvfb-run -a` picks the
first free one without a lock). Without xdist the order changes nothing else.

The tests of a module that share a module-scoped fixture (a plan, a C-space) run on one worker: spread over
workers, each computed it again (test_mesh5_holder's plan twice, 54 and 45 s).
"""
from __future__ import annotations

import pytest

_FIRST = ("tests/gui/", "tests/freecad/")


def _rank(nodeid: str) -> int:
    for k, prefix in enumerate(_FIRST):
        if nodeid.startswith(prefix):
            return k
    return len(_FIRST)


def _shares_a_module_fixture(item: pytest.Item) -> bool:
    info = getattr(item, "_fixtureinfo", None)
    if info is None:
        return False
    return any(defs and defs[-1].scope == "module" for defs in info.name2fixturedefs.values())


@pytest.hookimpl(tryfirst=True)  # before xdist's own hooks, which read the order and the groups
def pytest_collection_modifyitems(config: pytest.Config, items: list[pytest.Item]) -> None:
    items.sort(key=lambda item: _rank(item.nodeid))  # stable: each part keeps its order
    for item in items:
        if item.get_closest_marker("xdist_group") is None and _shares_a_module_fixture(item):
            item.add_marker(pytest.mark.xdist_group(item.nodeid.split("::")[0]))
