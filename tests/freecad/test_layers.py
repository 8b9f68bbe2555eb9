"""The layering rule, checked on the sources (no FreeCAD needed): core never imports FreeCAD,
app never imports Gui code (FreeCADGui, PySide, Path's Gui modules, tmm_workbench.gui); relative imports
are resolved to the modules they name. Only core/kernel.py imports the kernel module, and only when asked
(documents restore without it)."""
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
    """Absolute names of every module `path` imports (relative imports resolved, `from x import y` also
    counted as x.y since y may be a module)."""
    package = list(path.relative_to(PKG.parent).with_suffix("").parts[:-1])
    names: set[str] = set()
    for node in ast.walk(ast.parse(path.read_text(), str(path))):
        if isinstance(node, ast.Import):
            names.update(a.name for a in node.names)
        elif isinstance(node, ast.ImportFrom):
            base = package[:len(package) - node.level + 1] if node.level else []
            module = ".".join(base + ([node.module] if node.module else []))
            names.add(module)
            names.update(f"{module}.{a.name}" for a in node.names)
    return names


def test_relative_imports_are_resolved(tmp_path: Path) -> None:
    probe = PKG / "core" / "_layer_probe.py"
    probe.write_text("from ..app import api\nfrom . import errors\n")
    try:
        names = imported_modules(probe)
    finally:
        probe.unlink()
    assert {"tmm_workbench.app", "tmm_workbench.app.api", "tmm_workbench.core.errors"} <= names


def test_only_the_kernel_module_imports_the_kernel() -> None:
    for path in sorted(PKG.rglob("*.py")):
        if path == PKG / "core" / "kernel.py":
            continue
        assert not any(n.startswith("tmm_workbench._native") for n in imported_modules(path)), path


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
