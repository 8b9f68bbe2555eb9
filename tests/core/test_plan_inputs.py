"""The planner's job description beyond a box and a list (core.plan.job_file, core.plan.stock,
core.plan.tool_library, core.plan.launch): cylinder and solid stocks (their bounds, the model inside them, each bad
value named), FreeCAD's tool libraries (.fctl with their .fctb bits, as FreeCAD 0.20 and 1.1 ship them), the
machine's rapid rates, and `tmm plan part.stl` with the default recipe and its command-line overrides."""
from __future__ import annotations

import json
import shutil
from pathlib import Path

import numpy as np
import pytest

from tests.core.test_plan import BEET_JOB, good, refused, run_job, stand_in
from tmm_workbench.core.geometry.mesh import TriMesh, load_stl, save_stl
from tmm_workbench.core.plan import launch, recipes
from tmm_workbench.core.plan.job_file import PlanInputError, job_from_dict, read_job
from tmm_workbench.core.plan.stock import INSIDE_MM, planned_stock, stock_of_plan

FC_TOOLS = Path(__file__).resolve().parents[1] / "data" / "freecad_tools"


def beet() -> TriMesh:
    return load_stl(read_job(BEET_JOB).model.file)


def job_of(tmp_path: Path, data: dict):
    return job_from_dict(data, tmp_path / "job.yaml")


def box_mesh(lo, hi, top=None) -> TriMesh:
    """A closed box from `lo` to `hi`; `top` (x, y -> z) bends its top corners."""
    (x0, y0, z0), (x1, y1, z1) = lo, hi
    corners = [(x0, y0), (x1, y0), (x1, y1), (x0, y1)]
    v = [(x, y, z0) for x, y in corners] + [(x, y, z1 if top is None else top(x, y)) for x, y in corners]
    f = [[0, 2, 1], [0, 3, 2], [4, 5, 6], [4, 6, 7], [0, 1, 5], [0, 5, 4], [1, 2, 6], [1, 6, 5], [2, 3, 7],
         [2, 7, 6], [3, 0, 4], [3, 4, 7]]
    return TriMesh(np.array(v, float), np.array(f), "stock")


# --- the cylinder --------------------------------------------------------------------------------------------

def test_cylinder_around_the_model(tmp_path: Path) -> None:
    data = good(tmp_path)
    data["stock"] = {"type": "cylinder", "margin": 3, "above": 2, "below": 1}
    job = job_of(tmp_path, data)
    mesh = beet()
    stock = planned_stock(job, mesh)
    lo, hi = mesh.bounds
    centre = ((lo[0] + hi[0]) / 2, (lo[1] + hi[1]) / 2)
    reach = np.hypot(mesh.vertices[:, 0] - centre[0], mesh.vertices[:, 1] - centre[1]).max()
    assert stock.type == "cylinder" and stock.centre == pytest.approx(centre, abs=1e-4)
    assert stock.radius == pytest.approx(reach + 3, abs=2e-4)
    assert stock.radius < np.hypot(*(hi[:2] - lo[:2])) / 2 + 3   # the model's farthest point, not its box corner
    assert stock.box[2] == pytest.approx(lo[2] - 1, abs=1e-4) and stock.box[5] == pytest.approx(hi[2] + 2, abs=1e-4)
    assert stock.box[3] - stock.box[0] == pytest.approx(2 * stock.radius, abs=2e-4)
    # what the FreeCAD side gets from the plan's bounds alone
    again = stock_of_plan(job, stock.box)
    assert again.centre == pytest.approx(stock.centre, abs=1e-4) and again.radius == pytest.approx(stock.radius,
                                                                                                     abs=1e-4)
    assert again.as_dict()["describe"].startswith("cylinder D")


def test_cylinder_given_sizes_and_the_plan(tmp_path: Path) -> None:
    data = good(tmp_path)
    data["planner"]["compare_cutters"] = False
    data["stock"] = {"type": "cylinder", "diameter": 60, "height": 12, "below": 0.5}
    job = job_of(tmp_path, data)
    mesh, _, _, plan = launch.make_plan(job)
    lo = mesh.bounds[0]
    box = plan.stock_box
    assert box[3] - box[0] == pytest.approx(60, abs=2e-4) and box[5] - box[2] == pytest.approx(12, abs=2e-4)
    assert box[2] == pytest.approx(lo[2] - 0.5, abs=1e-4)
    doc = launch.plan_document(job, plan, job.model.file)
    assert doc["stock"]["type"] == "cylinder" and doc["stock"]["radius_mm"] == pytest.approx(30, abs=1e-4)
    assert doc["rapid_mm_min"] is None


@pytest.mark.parametrize("stock, words", [
    ({"type": "cylinder", "diameter": 20}, ["stock.diameter", "got 20", "at least", "not inside the stock"]),
    ({"type": "cylinder", "height": 5}, ["stock.height", "got 5", "at least", "not inside the stock"]),
], ids=["diameter", "height"])
def test_model_not_inside_the_cylinder_exit_2(tmp_path: Path, capsys, stock, words) -> None:
    data = good(tmp_path)
    data["stock"] = stock
    assert run_job(tmp_path, data) == launch.BAD_INPUT
    err = capsys.readouterr().err
    for w in words:
        assert w in err, (w, err)
    assert list(tmp_path.iterdir()) == [tmp_path / "job.yaml"]


BAD_STOCK = [
    ({"type": "cylinder", "diameter": 0}, ["stock.diameter", "0", "(0, 10000]"]),
    ({"type": "cylinder", "height": "tall"}, ["stock.height", "'tall'", "(0, 10000]"]),
    ({"type": "cylinder", "diameter": 80, "margin": 2}, ["stock.diameter", "80", "either stock.diameter or "
                                                          "stock.margin"]),
    ({"type": "cylinder", "height": 20, "above": 2}, ["stock.height", "either stock.height or stock.above"]),
    ({"type": "box", "diameter": 80}, ["stock (type box)", "unknown field(s) diameter", "margin, above, below"]),
    ({"type": "cylinder", "file": "s.stl"}, ["stock (type cylinder)", "unknown field(s) file"]),
    ({"type": "solid"}, ["stock.file", "missing", "STEP", "STL"]),
    ({"type": "solid", "margin": 2, "file": "s.stl"}, ["stock (type solid)", "unknown field(s) margin", "file"]),
    ({"type": "solid", "file": "nowhere.stl"}, ["stock.file", "nowhere.stl", "an existing STEP"]),
    ({"type": "solid", "file": "stock.iges"}, ["stock.file", "stock.iges", "(.step, .stp)"]),
    ("cylinder", ["stock", "'cylinder'", "a mapping"]),
]


@pytest.mark.parametrize("stock, words", BAD_STOCK, ids=[str(i) for i in range(len(BAD_STOCK))])
def test_bad_stock_named(tmp_path: Path, stock, words) -> None:
    data = good(tmp_path)
    data["stock"] = stock
    (tmp_path / "stock.iges").write_text("not read")
    text = refused(tmp_path, data)
    for w in words:
        assert w in text, (w, text)


def test_cylinder_larger_than_the_travels(tmp_path: Path) -> None:
    data = good(tmp_path)
    data["stock"] = {"type": "cylinder", "diameter": 250}
    text = str(pytest.raises(Exception, planned_stock, job_of(tmp_path, data), beet()).value)
    assert "machine.travels" in text and "(cylinder) is 250.0 mm in y" in text and "200 mm travel" in text


# --- the solid -----------------------------------------------------------------------------------------------

def solid_job(tmp_path: Path, mesh: TriMesh, name: str = "stock.stl") -> dict:
    save_stl(mesh, tmp_path / name)
    data = good(tmp_path)
    data["planner"]["compare_cutters"] = False
    data["stock"] = {"type": "solid", "file": name}
    return data


def test_solid_stock_bounds_and_plan(tmp_path: Path) -> None:
    lo, hi = beet().bounds
    # a block with a sloping top: 1 mm over the model's top at its low side
    top = lambda x, y: hi[2] + 1 + 0.1 * (x - lo[0] + 3)   # noqa: E731
    data = solid_job(tmp_path, box_mesh(lo - [3, 3, 1], hi + [3, 3, 0], top))
    job = job_of(tmp_path, data)
    mesh, _, _, plan = launch.make_plan(job)
    box = plan.stock_box
    assert box[0] == pytest.approx(lo[0] - 3, abs=1e-4) and box[2] == pytest.approx(lo[2] - 1, abs=1e-4)
    assert box[5] == pytest.approx(top(hi[0] + 3, 0), abs=1e-4)   # the top's highest corner
    doc = launch.plan_document(job, plan, job.model.file)
    assert doc["stock"]["type"] == "solid" and doc["stock"]["file"] == str(tmp_path / "stock.stl")
    assert doc["stock"]["scale"] == 1.0 and doc["stock"]["translate_mm"] == [0, 0, 0]
    assert "stock" not in plan.ops[0].kwargs or plan.ops[0].kwargs["stock"] == list(box)


def test_solid_stock_in_the_model_units_and_place(tmp_path: Path) -> None:
    lo, hi = beet().bounds
    data = solid_job(tmp_path, box_mesh(lo - 1, hi + 1))
    data["model"].update(units="inch", translate=[10, 0, 0])
    data["machine"]["travels"] = [1000, 1000, 400]
    stock = planned_stock(job_of(tmp_path, data), launch.placed_mesh(job_of(tmp_path, data))[0])
    assert stock.box[:3] == pytest.approx(list((lo - 1) * 25.4 + [10, 0, 0]), abs=1e-4)
    assert stock.scale == 25.4 and stock.translate == (10, 0, 0)


@pytest.mark.parametrize("grow", [(-1, 0, 0), (0, 0, -1)], ids=["side", "top"])
def test_model_not_inside_the_solid_exit_2(tmp_path: Path, capsys, grow) -> None:
    lo, hi = beet().bounds
    data = solid_job(tmp_path, box_mesh(lo - 2, hi + 2 + np.array(grow) * 2.6))   # cut 0.6 mm into the model
    assert run_job(tmp_path, data) == launch.BAD_INPUT
    err = capsys.readouterr().err
    for w in ("stock.file", "the model is not inside the stock stock.stl", "points lie outside it",
              "must hold the whole model"):
        assert w in err, (w, err)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["job.yaml", "stock.stl"]


def test_model_touching_the_solid_is_inside(tmp_path: Path) -> None:
    lo, hi = beet().bounds
    data = solid_job(tmp_path, box_mesh(lo - [0, 0, 1], hi + [0, 0, INSIDE_MM / 2]))   # the model's sides on its
    assert planned_stock(job_of(tmp_path, data), beet()).type == "solid"               # walls, its top under its top


def field_block(top, n: int, size: float, z0: float) -> TriMesh:
    """A closed block over [0, size]^2 from z0 up to the heights top(x, y) at n x n grid points."""
    g = np.linspace(0.0, size, n)
    x, y = (a.ravel() for a in np.meshgrid(g, g, indexing="ij"))
    v = np.concatenate([np.stack([x, y, top(x, y)], 1), np.stack([x, y, np.full_like(x, z0)], 1)])
    i, j = (a.ravel() for a in np.meshgrid(np.arange(n - 1), np.arange(n - 1), indexing="ij"))
    q = i * n + j
    faces = [np.stack([q, q + n, q + n + 1], 1), np.stack([q, q + n + 1, q + 1], 1)]   # the top, facing up
    faces += [f[:, ::-1] + n * n for f in faces]                                          # the bottom, down
    ring = [k * n for k in range(n)] + [(n - 1) * n + k for k in range(1, n)] + \
        [(n - 1) * n + n - 1 - k for k in range(1, n)] + [(n - 1 - k) * n for k in range(1, n - 1)]
    for a, b in zip(ring, ring[1:] + ring[:1]):                                           # the walls
        faces.append(np.array([[a, a + n * n, b], [b, a + n * n, b + n * n]]))
    mesh = TriMesh(v, np.concatenate(faces), "block")
    outward = mesh.face_normals()[:, 2]
    assert (outward[: 2 * (n - 1) ** 2] > 0).all() and (outward[2 * (n - 1) ** 2: 4 * (n - 1) ** 2] < 0).all()
    return mesh


def plate(z: float, corners) -> TriMesh:
    """A flat model of triangles at height z (the corners in XY, a fan from the first)."""
    v = np.array([(x, y, z) for x, y in corners], float)
    return TriMesh(v, np.array([[0, k, k + 1] for k in range(1, len(v) - 1)]), "plate")


@pytest.mark.parametrize("dip, model, words", [
    # a valley across the stock's top, deeper than the model between its points: the model's edges cross it
    (lambda x, y: np.where(np.isclose(x, 5.0), 3.0, 10.0), [(1, 1), (9, 1), (9, 9), (1, 9)],
     ["edges pass through the stock's surface", "X1 Y1 Z6"]),
    # a pit inside one of the model's faces: no model edge crosses, the pit's edges cross the face
    (lambda x, y: np.where(np.isclose(x, 5.0) & np.isclose(y, 5.0), 3.0, 10.0), [(0.5, 0.5), (9.5, 0.5), (5, 9.5)],
     ["the stock's edge from", "X5 Y5 Z3", "passes through its faces"]),
])
def test_model_crossing_the_solid_refused(tmp_path: Path, dip, model, words: list) -> None:
    """Every model point lies under the stock's top, but its surface crosses the stock's: refused (the points'
    check alone passed it)."""
    data = solid_job(tmp_path, field_block(dip, 5, 10.0, 0.0))
    with pytest.raises(PlanInputError) as ctx:
        planned_stock(job_of(tmp_path, data), plate(6.0, model))
    text = str(ctx.value)
    assert all(w in text for w in ["stock.file", "not inside the stock stock.stl", "(its points lie inside it)"]
               + words), text
    flat = solid_job(tmp_path, field_block(lambda x, y: np.full_like(x, 10.0), 5, 10.0, 0.0))
    assert planned_stock(job_of(tmp_path, flat), plate(6.0, model)).type == "solid"   # the same model held
    on_top = plate(10.0, model)   # the model's face on the stock's top (and its underside on the stock's bottom)
    assert planned_stock(job_of(tmp_path, flat), on_top).type == "solid"


def test_empty_solid_stock_exit_2(tmp_path: Path, capsys) -> None:
    data = solid_job(tmp_path, box_mesh((0, 0, 0), (1, 1, 1)))
    (tmp_path / "stock.stl").write_bytes(b"")
    assert run_job(tmp_path, data) == launch.BAD_INPUT
    assert "stock.file" in capsys.readouterr().err


# --- FreeCAD's tool libraries --------------------------------------------------------------------------------

@pytest.mark.parametrize("version, numbers", [("v0_20", ["T1", "T3", "T4"]), ("v1_1", ["T1", "T2", "T4", "T5"])])
def test_freecad_shipped_library(tmp_path: Path, version: str, numbers: list) -> None:
    data = good(tmp_path)
    data["tools"] = str(FC_TOOLS / version / "Library" / "Default.fctl")
    job = job_of(tmp_path, data)
    assert [t.name.split()[0] for t in job.tools] == numbers
    ball = next(t for t in job.tools if t.type == "ball")
    assert (ball.name.endswith("6mm Ball End") and ball.diameter == 6.0 and ball.corner_radius == 3.0
            and ball.flute_length == 40.0 and ball.shank_diameter == 3.0 and ball.length == 50.0)
    bull = next(t for t in job.tools if t.type == "bull")   # 0.20: FlatRadius 1.5 of D6; 1.1: CornerRadius 1.5
    assert bull.corner_radius == 1.5 and bull.flutes == 2
    flat = next(t for t in job.tools if t.name.split(" ", 1)[1] == "5mm Endmill")
    assert flat.type == "flat" and flat.corner_radius == 0.0 and flat.flute_length == 30.0
    assert any("5mm_Drill.fctb: shape 'drill'" in n for n in job.notes)
    assert all(n.startswith("tool library Default.fctl: left out T") for n in job.notes)
    assert len(job.notes) == {"v0_20": 6, "v1_1": 9}[version]


def library(tmp_path: Path, bits: dict, entries=None) -> Path:
    """A library in FreeCAD's layout: Tools/Library/shop.fctl naming Tools/Bit/<name>.fctb."""
    (tmp_path / "Tools" / "Bit").mkdir(parents=True, exist_ok=True)
    (tmp_path / "Tools" / "Library").mkdir(exist_ok=True)
    for name, bit in bits.items():
        (tmp_path / "Tools" / "Bit" / f"{name}.fctb").write_text(json.dumps(bit))
    lib = tmp_path / "Tools" / "Library" / "shop.fctl"
    lib.write_text(json.dumps({"version": 1, "tools": entries if entries is not None else
                               [{"nr": 10 - i, "path": f"{n}.fctb"} for i, n in enumerate(bits)]}))
    return lib


def bit(shape: str, **parameter) -> dict:
    return {"version": 2, "name": f"my {shape}", "shape": f"{shape}.fcstd", "parameter": parameter, "attribute": {}}


def test_library_quantities_and_order(tmp_path: Path) -> None:
    lib = library(tmp_path, {"ball": bit("ballend", Diameter="0.25 in", CuttingEdgeHeight=12.5, Flutes=3),
                             "bull": bit("bullnose", Diameter="10,00 mm", FlatRadius="4 mm", CuttingEdgeHeight="25 mm",
                                         Length="7.5 cm", Flutes=0)})
    data = good(tmp_path)
    data["tools"] = str(lib.relative_to(tmp_path))
    job = job_of(tmp_path, data)
    assert [t.name for t in job.tools] == ["T9 my bullnose", "T10 my ballend"]   # by tool number
    bull, ball = job.tools
    assert bull.corner_radius == 1.0 and bull.length == 75.0 and bull.shank_diameter is None
    assert bull.diameter == 10.0 and bull.flutes == 2   # a decimal comma; 1.1's unset Flutes 0: the default
    assert ball.diameter == pytest.approx(6.35) and ball.flute_length == 12.5 and ball.flutes == 3
    assert job.notes == ()


BAD_LIBRARY = [
    (lambda p: p.write_text("{not json"), ["tools", "shop.fctl", "not readable as JSON"]),
    (lambda p: p.write_text(json.dumps({"version": 1})), ["tools", "not a FreeCAD tool library"]),
    (lambda p: p.write_text(json.dumps({"tools": [{"nr": "one", "path": "b.fctb"}]})), ["tools[0]", "'one'"]),
    (lambda p: p.write_text(json.dumps({"tools": [{"nr": 1, "path": "gone.fctb"}]})),
     ["the ToolBit 'gone.fctb' is not there", "Bit"]),
    (lambda p: (p.parent.parent / "Bit" / "b.fctb").write_text(json.dumps(bit("ballend", Diameter="6 mm"))),
     ["ToolBit b.fctb", "no CuttingEdgeHeight"]),
    (lambda p: (p.parent.parent / "Bit" / "b.fctb").write_text(json.dumps(
        bit("ballend", Diameter="6 furlongs", CuttingEdgeHeight=10))), ["ToolBit b.fctb", "Diameter", "6 furlongs"]),
    (lambda p: (p.parent.parent / "Bit" / "b.fctb").write_text(json.dumps(
        bit("ballend", Diameter="-6 mm", CuttingEdgeHeight=10))), ["shop.fctl", "my ballend", "diameter", "-6.0"]),
    (lambda p: (p.parent.parent / "Bit" / "b.fctb").write_text(json.dumps(
        bit("bullnose", Diameter="6 mm", CuttingEdgeHeight=10))), ["ToolBit b.fctb", "no FlatRadius",
                                                                   "CornerRadius or FlatRadius"]),
    (lambda p: (p.parent.parent / "Bit" / "b.fctb").write_text(json.dumps(bit("drill", Diameter="6 mm"))),
     ["tools", "shop.fctl", "end mill, ball or bull-nose", "shape 'drill'"]),
]


@pytest.mark.parametrize("spoil, words", BAD_LIBRARY, ids=[str(i) for i in range(len(BAD_LIBRARY))])
def test_bad_library_exit_2(tmp_path: Path, capsys, spoil, words) -> None:
    lib = library(tmp_path, {"b": bit("ballend", Diameter="6 mm", CuttingEdgeHeight="20 mm")})
    spoil(lib)
    data = good(tmp_path)
    data["tools"] = str(lib)
    assert run_job(tmp_path, data) == launch.BAD_INPUT
    err = capsys.readouterr().err
    for w in words:
        assert w in err, (w, err)
    assert not (tmp_path / "out").exists()


def test_tool_shank_and_length_fields(tmp_path: Path) -> None:
    data = good(tmp_path)
    data["tools"][0].update(shank_diameter=6, length=60)
    t = job_of(tmp_path, data).tools[0]
    assert t.shank_diameter == 6.0 and t.length == 60.0
    for change, words in ((dict(length=10), ["tools[0].length", "10", "[20, 1000]"]),
                          (dict(shank_diameter=0), ["tools[0].shank_diameter", "(0, 100]"])):
        data = good(tmp_path)
        data["tools"][0].update(change)
        text = refused(tmp_path, data)
        assert all(w in text for w in words), text
    data = good(tmp_path)
    data["tools"][1].update(length=30)   # the holder's stick-out is 30: the tool must be longer
    assert "tools[1].length" in refused(tmp_path, data)


# --- the machine's rapids ------------------------------------------------------------------------------------

def test_machine_rapid(tmp_path: Path) -> None:
    data = good(tmp_path)
    data["machine"]["rapid"] = [8000, 3000]
    assert job_of(tmp_path, data).machine.rapid == (8000.0, 3000.0)
    for bad, words in (([8000], ["machine.rapid", "[xy, z]"]), ([8000, 0], ["machine.rapid[1]", "[1, 1e+06]"])):
        data["machine"]["rapid"] = bad
        text = refused(tmp_path, data)
        assert all(w in text for w in words), text


# --- the default recipe --------------------------------------------------------------------------------------

def test_model_with_the_default_recipe(tmp_path: Path, monkeypatch) -> None:
    model = tmp_path / "part.stl"
    shutil.copy(read_job(BEET_JOB).model.file, model)
    monkeypatch.chdir(tmp_path)
    job, again = launch.job_of(str(model))
    assert job.material == recipes.DEFAULT_MATERIAL and job.finish.cusp == 0.01 and job.stock.margin == 2
    assert job.outputs.dir == tmp_path / "part_plan" and job.outputs.name == "part"
    assert [t.name for t in job.tools] == [t.name for t in read_job(recipes.SHOP_LIBRARY.parent / "beet.yaml").tools]
    assert again["outputs"]["dir"] == "."
    job, _ = launch.job_of(str(model), [(("finish", "cusp"), 0.05), (("material",), "hardwood")], str(tmp_path / "o"))
    assert job.finish.cusp == 0.05 and job.material == "hardwood" and job.outputs.dir == tmp_path / "o"
    # the command: the outputs and the job file that plans it again (the stand-in plays FreeCAD)
    code = launch.main([str(model), "--cusp", "0.1", "--material", "modelling_foam", "--freecad",
                        stand_in(tmp_path, True), "--quiet"])
    assert code == launch.VERIFIED
    out = tmp_path / "part_plan"
    assert {"job.json", "part.ngc", "report.json"} <= {p.name for p in out.iterdir()}
    rerun = read_job(out / "job.json")
    assert rerun.finish.cusp == 0.1 and rerun.material == "modelling_foam" and rerun.outputs.dir == out
    assert json.loads((out / "report.json").read_text())["stock"]["type"] == "box"


def test_default_recipe_bad_input(tmp_path: Path, capsys, monkeypatch) -> None:
    monkeypatch.chdir(tmp_path)
    assert launch.main([str(tmp_path / "none.stl"), "--quiet"]) == launch.BAD_INPUT
    assert "model.file" in capsys.readouterr().err
    model = tmp_path / "part.stl"
    shutil.copy(read_job(BEET_JOB).model.file, model)
    assert launch.main([str(model), "--cusp", "9", "--quiet"]) == launch.BAD_INPUT
    assert "finish.cusp: got 9.0" in capsys.readouterr().err
    assert launch.main([str(model), "--tools", "no_tools.fctl", "--quiet"]) == launch.BAD_INPUT
    assert "no_tools.fctl" in capsys.readouterr().err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["part.stl"]


def test_library_notes_in_the_report(tmp_path: Path) -> None:
    """The bits left out of a library are said in report.json's notes and on the page's setup sheet."""
    data = good(tmp_path)
    data["planner"]["compare_cutters"] = False
    data["tools"] = str(FC_TOOLS / "v0_20" / "Library" / "Default.fctl")
    data["machine"]["rapid"] = [6000, 2000]
    assert run_job(tmp_path, data, stand_in(tmp_path, True)) == launch.VERIFIED
    report = json.loads((tmp_path / "out" / "report.json").read_text())
    assert len(report["notes"]) == 6 and "T2 5mm_Drill.fctb" in report["notes"][0]
    assert report["machine"]["rapid_mm_min"] == [6000, 2000]
    assert [t["name"] for t in report["tools"]] == ["T1 5mm Endmill", "T3 6mm Ball End", "T4 6 mm Bull Nose"]
    assert report["tools"][1]["shank_diameter"] == 3.0 and report["tools"][1]["length"] == 50.0
    page = (tmp_path / "out" / "report.html").read_text()
    assert "left out T2 5mm_Drill.fctb" in page and "rapids XY 6000 Z 2000 mm/min" in page
    assert report["stock"]["describe"].startswith("box ") and report["stock"]["describe"] in page
