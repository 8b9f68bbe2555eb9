"""The layering rule, checked on the sources (no FreeCAD needed): core never imports FreeCAD,
app never imports Gui code (FreeCADGui, PySide, Path's Gui modules, tmm_workbench.gui)."""
from __future__ import annotations

import ast
from pathlib import Path

import pytest

PKG = Path(__file__).resolve().parents[2] / "tmm_workbench"
FORBIDDEN = {
    "core": ("FreeCAD", "FreeCADGui", "Path", "PathScripts", "Part", "Mesh", "PySide", "tmm_workbench.app",
             "tmm_workbench.gui"),
    "app": ("FreeCADGui", "PySide", "PathGui", "tmm_workbench.gui"),
}


def imported_modules(path: Path) -> set[str]:
    names: set[str] = set()
    for node in ast.walk(ast.parse(path.read_text(), str(path))):
        if isinstance(node, ast.Import):
            names.update(a.name for a in node.names)
        elif isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            names.add(node.module)
    return names


@pytest.mark.parametrize("layer", sorted(FORBIDDEN))
def test_layer_imports(layer: str) -> None:
    bad = []
    for path in sorted((PKG / layer).rglob("*.py")):
        for name in imported_modules(path):
            if any(name == f or name.startswith(f + ".") for f in FORBIDDEN[layer]):
                bad.append(f"{path.relative_to(PKG.parent)} imports {name}")
            if "Gui" in name.split(".")[-1] and layer == "app":
                bad.append(f"{path.relative_to(PKG.parent)} imports {name}")
    assert not bad, "\n".join(bad)


def test_app_gui_names_are_only_named_in_compat() -> None:
    """Path's Gui module names may appear in app/compat.py's table, loaded by the gui package only."""
    for path in (PKG / "app").rglob("*.py"):
        if path.name != "compat.py":
            assert "import_gui" not in path.read_text(), path
