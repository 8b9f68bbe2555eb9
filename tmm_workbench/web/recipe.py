"""What a web customer chooses, turned into the planner's job file: the model (an upload checked as STL, a sample
of the shared benchmarks, or a sign of seed 003), the recipe (material, finish, machine) and the shop's tool
library. Every field is read from a form's text and checked here, with a message naming it, its value and what is
allowed; the planner's own reading of the job file (core.plan.job_file) checks the rest before a job is accepted.
Nothing the customer types names a file: the server picks every path."""
from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Mapping

from tmm_workbench.core.errors import TmmError
from tmm_workbench.core.plan import materials, recipes
from tmm_workbench.core.plan.recipes import FINISHES, MACHINES

MAX_UPLOAD_BYTES = 50 * 1024 * 1024
MAX_TRIANGLES = 1_000_000          # a model's work: the planner's reach tests and simulation grow with it
ZIP_MAGIC = (b"PK\x03\x04", b"PK\x05\x06", b"PK\x07\x08")
MODEL_FILE = "model.stl"
JOB_FILE = "job.yaml"
PART_NAME = "part"                  # the planner's outputs: part.ngc, part.FCStd, part_sim.png, report.json

SIGN_FIELDS = {"text": str, "width": float, "height": float, "shape": str, "border": float, "relief": float,
               "background": str, "thickness": float}


class RequestError(TmmError):
    """A request the server refuses: the HTTP status and the reason."""

    def __init__(self, status: int, reason: str) -> None:
        super().__init__(reason)
        self.status = status
        self.reason = reason


@dataclass(frozen=True)
class Recipe:
    material: str
    finish: str
    machine: str


def choices() -> dict:
    """What the page offers."""
    return {"materials": materials.names(), "finishes": list(FINISHES), "machines": list(MACHINES),
            "samples": samples(), "sign": {"shapes": _sign_module().SHAPES, "backgrounds": _sign_module().BACKGROUNDS},
            "max_upload_mb": MAX_UPLOAD_BYTES / 2 ** 20, "max_triangles": MAX_TRIANGLES}


def _sign_module():
    from tmm_workbench.core.geometry import sign

    return sign


def samples_dir() -> Path:
    from tmm_workbench.core.shared_data import benchmark_file

    return benchmark_file("stl")


def samples() -> list[str]:
    """The shared benchmark STL files by name (the only sample names taken)."""
    try:
        return sorted(p.name for p in samples_dir().iterdir() if p.suffix.lower() == ".stl" and p.is_file())
    except TmmError:
        return []


def _one(form: Mapping[str, Any], name: str, allowed: list[str]) -> str:
    value = form.get(name)
    if not isinstance(value, str) or value not in allowed:
        raise RequestError(400, f"{name}: got {_show(value)}; one of {', '.join(allowed)}")
    return value


def _show(value: Any) -> str:
    if value is None:
        return "nothing"
    return repr(value)[:80] if isinstance(value, str) else f"a {type(value).__name__}"


def recipe_of(form: Mapping[str, Any]) -> Recipe:
    return Recipe(_one(form, "material", materials.names()), _one(form, "finish", list(FINISHES)),
                  _one(form, "machine", list(MACHINES)))


def sample_of(form: Mapping[str, Any]) -> Path:
    """The sample file the form names, by its listed name only."""
    return samples_dir() / _one(form, "sample", samples())


def sign_spec(form: Mapping[str, Any], recipe: Recipe):
    """The sign the form describes (its fields' text turned to numbers), its grid from the finish; checked by the
    sign maker, and its mesh's size estimated against the triangle limit before anything is made."""
    sign = _sign_module()
    values: dict[str, Any] = {}
    for name, kind in SIGN_FIELDS.items():
        text = form.get(name)
        if text is None or text == "":
            continue
        if not isinstance(text, str):
            raise RequestError(400, f"{name}: got {_show(text)}; a text field")
        if kind is float:
            try:
                number = float(text)
            except ValueError:
                raise RequestError(400, f"{name}: got {text[:40]!r}; a number in mm") from None
            if not math.isfinite(number):
                raise RequestError(400, f"{name}: got {text[:40]!r}; a finite number in mm")
            values[name] = number
        else:
            values[name] = text
    if "text" not in values:
        raise RequestError(400, "text: missing; a sign needs its text")
    spec = sign.SignSpec(**values, cell=FINISHES[recipe.finish]["sign_cell"])
    try:
        spec.validate()
    except TmmError as exc:
        raise RequestError(400, str(exc)) from None
    nodes = (math.floor(spec.width / spec.cell) + 1) * (math.floor(spec.height / spec.cell) + 1)
    if 2 * nodes > MAX_TRIANGLES:
        raise RequestError(400, f"a {spec.width:g} x {spec.height:g} mm sign at the {recipe.finish} finish's "
                                f"{spec.cell:g} mm grid makes about {2 * nodes:,} triangles, more than "
                                f"{MAX_TRIANGLES:,}: choose a smaller sign or a coarser finish")
    return spec


def check_stl_bytes(head: bytes, size: int) -> None:
    """Refuses what is plainly not an STL before the reader sees it: empty, an archive."""
    if size == 0:
        raise RequestError(400, "model: the file is empty; an STL file (ASCII or binary)")
    if head[:4] in ZIP_MAGIC:
        raise RequestError(400, "model: the file is a zip archive; upload the STL file itself")


def check_stl_file(path: Path) -> int:
    """The triangle count of the STL at `path` read by the core's reader (which names what is wrong); refused
    above the limit."""
    from tmm_workbench.core.geometry.mesh import load_stl

    try:
        mesh = load_stl(path)
    except TmmError as exc:
        raise RequestError(400, f"model: not a readable STL: {str(exc).replace(str(path), 'the upload')}") from None
    if len(mesh) == 0:
        raise RequestError(400, "model: the STL holds no triangles")
    if len(mesh) > MAX_TRIANGLES:
        raise RequestError(400, f"model: {len(mesh):,} triangles, more than the limit of {MAX_TRIANGLES:,}")
    return len(mesh)


def job_data(recipe: Recipe) -> dict:
    """The planner's job file for the model beside it (MODEL_FILE) and `recipe`."""
    return recipes.job_data(recipe.material, recipe.finish, recipe.machine, MODEL_FILE, "out", PART_NAME)
