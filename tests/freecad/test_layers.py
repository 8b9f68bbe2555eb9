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


def _module_graph() -> dict[str, set[str]]:
    """tmm_workbench's modules -> the modules of the package each imports (function-level imports included:
    an import inside a function is still a dependency, only a later one)."""
    files = {}
    for path in PKG.rglob("*.py"):
        parts = path.relative_to(PKG.parent).with_suffix("").parts
        files[".".join(parts[:-1] if parts[-1] == "__init__" else parts)] = path
    return {name: {n for n in imported_modules(path) if n in files and n != name and not
                   files[n].name == "__init__.py"} for name, path in files.items()}


def _circles(graph: dict[str, set[str]]) -> list[frozenset[str]]:
    """The strongly connected components of more than one module (Tarjan's algorithm, iterative)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    found: list[frozenset[str]] = []
    for root in sorted(graph):
        if root in index:
            continue
        work = [(root, iter(sorted(graph[root])))]
        index[root] = low[root] = len(index)
        stack.append(root)
        on_stack.add(root)
        while work:
            node, children = work[-1]
            child = next(children, None)
            if child is not None:
                if child not in index:
                    index[child] = low[child] = len(index)
                    stack.append(child)
                    on_stack.add(child)
                    work.append((child, iter(sorted(graph[child]))))
                elif child in on_stack:
                    low[node] = min(low[node], index[child])
                continue
            work.pop()
            if work:
                low[work[-1][0]] = min(low[work[-1][0]], low[node])
            if low[node] == index[node]:
                members = set()
                while True:
                    m = stack.pop()
                    on_stack.discard(m)
                    members.add(m)
                    if m == node:
                        break
                if len(members) > 1:
                    found.append(frozenset(members))
    return found


def _short(names: frozenset[str]) -> frozenset[str]:
    return frozenset(n.replace("tmm_workbench.", "") for n in names)


# Circles that stand today, to be taken apart. The list may only shrink: a new circle, or a listed one grown, fails.
KNOWN_CIRCLES: list[frozenset[str]] = []


def test_the_circle_finder_finds_circles() -> None:
    graph = {"a": {"b"}, "b": {"c"}, "c": {"a", "d"}, "d": set(), "e": {"e"}}
    assert _circles(graph) == [frozenset({"a", "b", "c"})]


def test_no_new_import_circle() -> None:
    circles = {_short(c) for c in _circles(_module_graph())}
    new = [sorted(c) for c in circles if c not in KNOWN_CIRCLES]
    gone = [sorted(c) for c in KNOWN_CIRCLES if c not in circles]
    assert not new, f"modules importing each other in a circle: {new}"
    assert not gone, f"a known circle is gone or changed: take it off KNOWN_CIRCLES: {gone}"


# The one-way flow inside core: a part imports only parts of a lower rank (the base modules directly under core/
# import each other freely; the circle test keeps them apart). Data runs geometry/tools -> query -> footprint ->
# strategies -> linking -> toolpath; the simulation and verification read tool paths and never call strategies;
# planning (plan) runs strategies for candidates, measures what each leaves and draws its report's pictures
# (preview), so it sits above the posts and pictures.
CORE_RANK = {"geometry": 1, "tools": 1, "query": 2, "machine": 2, "sim": 3, "verify": 3, "footprint": 4,
             "linking": 5, "strategies": 6, "post": 7, "preview": 7, "plan": 8}
KNOWN_UPWARD: set[tuple[str, str]] = set()  # core imports against the flow that stand today (may only shrink)


def _core_part(name: str) -> str:
    parts = name.split(".")
    return parts[2] if len(parts) > 3 or parts[2] == "linking" else ""


def test_core_flows_one_way() -> None:
    upward = set()
    for name, imports in _module_graph().items():
        if not name.startswith("tmm_workbench.core."):
            continue
        for other in imports:
            a, b = _core_part(name), _core_part(other)
            if other.startswith("tmm_workbench.core.") and a and b and a != b and CORE_RANK[b] >= CORE_RANK[a]:
                upward.add((name.replace("tmm_workbench.", ""), other.replace("tmm_workbench.", "")))
    assert not upward - KNOWN_UPWARD, f"core imports against the flow: {sorted(upward - KNOWN_UPWARD)}"
    assert not KNOWN_UPWARD - upward, f"gone: take them off KNOWN_UPWARD: {sorted(KNOWN_UPWARD - upward)}"
