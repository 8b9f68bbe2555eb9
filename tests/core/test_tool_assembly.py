"""The tool assembly (cutter, neck, shank, holder) as the frusta the assembly drop query takes, and the
holder library: shipped entries, a user's extension file, validation messages, names."""
from __future__ import annotations

import json
import math
from pathlib import Path

import pytest

from tmm_workbench.core.errors import TmmError
from tmm_workbench.core.tools import holders
from tmm_workbench.core.tools.assembly import ToolAssembly
from tmm_workbench.core.tools.cutter import Cutter
from tmm_workbench.core.tools.holders import Holder

T45 = math.tan(math.radians(4.5))


def approx_bodies(actual, expected) -> None:
    assert len(actual) == len(expected), actual
    for a, e in zip(actual, expected):
        assert a == pytest.approx(e, abs=1e-9), (a, e)


def check_stacking(bodies) -> None:
    """Sorted by z, touching, each of positive height: the convention the drop query relies on."""
    for z0, z1, r0, r1, c in bodies:
        assert z1 > z0 and r0 > 0 and r1 > 0 and c >= 0
    for (_, z1, *_), (z0, *_) in zip(bodies, bodies[1:]):
        assert z0 == pytest.approx(z1, abs=1e-12)


def test_flat_in_er32_nut() -> None:
    # 6 mm flat, 20 mm flutes, 6 mm shank, 35 mm out of an ER32 nut (D50 x 22.5)
    a = ToolAssembly(Cutter.flat(6), 6, 35, flute_length=20, holder="ER32 nut")
    approx_bodies(a.bodies(), [(20, 35, 3, 3, 1.0), (35, 57.5, 25, 25, 1.0)])
    assert a.top == pytest.approx(57.5)
    assert a.minimum_stick_out == 20


def test_reduced_shank_steps_down_at_the_flutes() -> None:
    # FreeCAD's default ball bit: D6 on a 3 mm shank; no holder: the shank up to the stick-out only
    a = ToolAssembly(Cutter.ball(6), 3, 41, flute_length=40, shank_clearance=0.5)
    approx_bodies(a.bodies(), [(40, 41, 1.5, 1.5, 0.5)])


def test_long_reach_ball_with_neck_cone_and_shrink_fit() -> None:
    # D2 ball, 3 mm flutes, neck D1.9 x 10, 15 deg cone to the 6 mm shank, 30 mm out of a 6 mm shrink-fit chuck
    a = ToolAssembly(Cutter.ball(2), 6, 30, flute_length=3, holder="HSK63A shrink 6x80", neck_diameter=1.9,
                     neck_length=10, shank_cone_deg=15, shank_clearance=0.2, holder_clearance=2)
    cone = (3 - 0.95) / math.tan(math.radians(15))
    approx_bodies(a.bodies(), [(3, 13, 0.95, 0.95, 0.2), (13, 13 + cone, 0.95, 3, 0.2), (13 + cone, 30, 3, 3, 0.2),
                               (30, 84, 10.5, 14.75, 2), (84, 110, 31.5, 31.5, 2)])
    check_stacking(a.bodies())
    assert a.minimum_stick_out == pytest.approx(13 + cone)
    # the shipped shrink-fit nose is the 4.5 degree contour
    z0, z1, r0, r1, _ = a.bodies()[3]
    assert (r1 - r0) / (z1 - z0) == pytest.approx(T45, abs=1e-4)


def test_wider_shank_is_a_step_by_default() -> None:
    # D3 flat on a 6 mm shank: without a cone angle the shank starts right above the flutes (encloses the cone)
    a = ToolAssembly(Cutter.flat(3), 6, 25, flute_length=8, holder="SK40 ER32x70")
    approx_bodies(a.bodies(), [(8, 25, 3, 3, 1), (25, 47.5, 25, 25, 1), (47.5, 79.1, 25, 25, 1),
                               (79.1, 95, 31.775, 31.775, 1)])


def test_cone_cutter_flutes_above_its_profile() -> None:
    # a 90 deg V-bit D10: its cone is 5 mm high; side flutes up to 8 mm at the cutter clearance
    v = Cutter.vbit(10, 90)
    assert v.cutting_length == pytest.approx(5)
    a = ToolAssembly(v, 10, 20, flute_length=8)
    approx_bodies(a.bodies(), [(5, 8, 5, 5, 0), (8, 20, 5, 5, 1)])
    b = ToolAssembly(v, 6, 20)  # flute length defaults to the cone: the 6 mm shank right above it
    approx_bodies(b.bodies(), [(5, 20, 3, 3, 1)])


@pytest.mark.parametrize("kwargs, words", [
    (dict(stick_out=15), ["stick-out 15", "at least the flute length 20"]),
    (dict(stick_out=float("nan")), ["stick-out", "nan"]),
    (dict(shank_diameter=-6), ["shank diameter", "> 0", "-6"]),
    (dict(shank_diameter=float("nan")), ["shank diameter", "nan"]),
    (dict(flute_length=-1), ["flute length", "> 0"]),
    (dict(flute_length=None), ["flute length", "flat D6"]),
    (dict(shank_clearance=-0.1), ["shank clearance", ">= 0", "-0.1"]),
    (dict(holder_clearance=float("nan")), ["holder clearance", "nan"]),
    (dict(cutter_clearance=-1), ["cutter clearance", ">= 0"]),
    (dict(neck_diameter=7, neck_length=5), ["neck diameter 7", "at most the cutter diameter 6"]),
    (dict(neck_diameter=5, neck_length=-5), ["neck length", "> 0"]),
    (dict(neck_length=5), ["neck length 5", "without a neck diameter"]),
    (dict(neck_diameter=5.5, neck_length=20), ["stick-out 35", "at least 40", "neck (20 mm)"]),
    (dict(shank_cone_deg=0), ["cone half angle", "90 degrees", "0"]),
    (dict(overall_length=30), ["stick-out 35", "overall length 30"]),
    (dict(holder="ER32 nutt"), ["unknown holder 'ER32 nutt'", "'ER32 nut'"]),
    (dict(holder="HSK63A shrink 8x80"), ["shank diameter 6", "clamping range 8-8", "HSK63A shrink 8x80"]),
    (dict(holder="ER11 nut", shank_diameter=8), ["shank diameter 8", "0.5-7", "ER11 nut"]),
    (dict(holder="ER11 nut", shank_diameter=20), ["nose (diameter 19 mm) is narrower than the shank (20 mm)"]),
    (dict(holder=42), ["holder must be a Holder"]),
])
def test_bad_input_is_refused_by_name(kwargs, words) -> None:
    args = dict(cutter=Cutter.flat(6), shank_diameter=6, stick_out=35, flute_length=20)
    args.update(kwargs)
    with pytest.raises(TmmError) as err:
        ToolAssembly(**args)
    for w in words:
        assert w in str(err.value), str(err.value)


def test_cone_must_fit_below_the_holder() -> None:
    with pytest.raises(TmmError, match="cone up to the shank"):
        ToolAssembly(Cutter.flat(2), 6, 12, flute_length=10, shank_cone_deg=30)


def test_describe() -> None:
    a = ToolAssembly(Cutter.bull(10, 1), 10, 40, flute_length=22, holder="SK40 ER32x70")
    text = a.describe()
    for w in ("bull-nose D10 r1", "flutes 22", "shank D10", "stick-out 40", "SK40 ER32x70", "holder 1"):
        assert w in text


# --- the holder library ---

def test_shipped_library_loads_and_validates() -> None:
    names = holders.names()
    for required in ("ER11 nut", "ER16 nut", "ER20 nut", "ER25 nut", "ER32 nut", "SK40 ER32x70",
                     "HSK63A ER32x100", "HSK63A shrink 3x80", "HSK63A shrink 6x80", "HSK63A shrink 12x80",
                     "HSK63A hydraulic slim 12x80"):
        assert required in names
    raw = json.loads(holders.SHIPPED_FILE.read_text(encoding="utf-8"))["holders"]
    assert len(raw) == len(names)
    for entry in raw:
        h = holders.holder(entry["name"])
        assert h.source, h.name                       # every shipped holder says where it comes from
        assert h.nose_diameter > h.shank_max
        if h.kind == "shrink-fit" or h.kind == "hydraulic":   # the slim 4.5 degree nose
            height, d0, d1 = h.stack[0]
            assert (d1 - d0) / 2 / height == pytest.approx(T45, abs=1e-4), h.name
        if h.kind == "nut":
            assert h.interface == "" and len(h.stack) == 1
    assert holders.holder("er32 NUT").name == "ER32 nut"  # names are case-insensitive


def write_user_file(tmp_path: Path, entries: list, fmt: str = holders.FORMAT) -> Path:
    path = tmp_path / "TMM" / "holders.json"
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(json.dumps({"format": fmt, "holders": entries}), encoding="utf-8")
    return path


def test_user_file_extends_and_overrides(tmp_path: Path) -> None:
    mine = {"name": "My ER20 side-lock", "kind": "side-lock", "shank": [6, 6], "stack": [[30, 25, 25], [10, 40, 40]]}
    nut = {"name": "ER32 nut", "kind": "nut", "shank": [2, 20], "stack": [[24, 50, 50]], "source": "measured"}
    path = write_user_file(tmp_path, [mine, nut])
    assert path == holders.user_file_in(tmp_path)
    lib = holders.library(path)
    assert len(lib) == len(holders.names()) + 1
    assert lib.holder("My ER20 side-lock").length == 40
    assert holders.holder("ER32 nut", path).stack == ((24.0, 50.0, 50.0),)   # the user's entry wins
    assert holders.holder("ER32 nut").stack == ((22.5, 50.0, 50.0),)          # the shipped one is unchanged
    a = ToolAssembly(Cutter.flat(6), 6, 20, flute_length=10, holder=lib.holder("My ER20 side-lock"))
    approx_bodies(a.bodies()[-2:], [(20, 50, 12.5, 12.5, 1), (50, 60, 20, 20, 1)])
    assert holders.names(tmp_path / "missing.json") == holders.names()        # no user file: the shipped ones


@pytest.mark.parametrize("entry, words", [
    ({"name": "A", "kind": "nut", "shank": [1, 7], "stack": [[10, 6, 6]]}, ["holder 'A'", "nose", "wider", "7"]),
    ({"name": "A", "kind": "nut", "shank": [1, 7], "stack": [[-10, 19, 19]]}, ["segment 1 height", "> 0", "-10"]),
    ({"name": "A", "kind": "nut", "shank": [1, 7], "stack": [[10, 19, "x"]]}, ["segment 1 top diameter"]),
    ({"name": "A", "kind": "nut", "shank": [1, 7], "stack": [[10, 19]]}, ["segment 1", "[height, bottom"]),
    ({"name": "A", "kind": "nut", "shank": [1, 7], "stack": []}, ["at least one segment"]),
    ({"name": "A", "kind": "nut", "shank": [8, 7], "stack": [[10, 19, 19]]}, ["shank range 8-7", "empty"]),
    ({"name": "A", "kind": "nut", "shank": [float("nan"), 7], "stack": [[10, 19, 19]]}, ["smallest shank"]),
    ({"name": "A", "kind": "chuck", "shank": [1, 7], "stack": [[10, 19, 19]]}, ["kind 'chuck'", "shrink-fit"]),
    ({"name": "A", "kind": "nut", "shank": [1, 7], "stak": [[10, 19, 19]]}, ["unknown field(s) stak"]),
    ({"name": "A", "kind": "nut", "stack": [[10, 19, 19]]}, ["holder 'A' has no 'shank'"]),
    ({"name": "", "kind": "nut", "shank": [1, 7], "stack": [[10, 19, 19]]}, ["holder name"]),
])
def test_bad_user_entries_are_refused_with_the_file_and_entry(tmp_path: Path, entry, words) -> None:
    ok = {"name": "B", "kind": "nut", "shank": [1, 7], "stack": [[10, 19, 19]]}
    path = write_user_file(tmp_path, [ok, entry])
    with pytest.raises(TmmError) as err:
        holders.library(path)
    text = str(err.value)
    assert str(path) in text and "entry 2" in text, text
    for w in words:
        assert w in text, text


def test_bad_user_files(tmp_path: Path) -> None:
    ok = {"name": "B", "kind": "nut", "shank": [1, 7], "stack": [[10, 19, 19]]}
    with pytest.raises(TmmError, match="used twice"):
        holders.library(write_user_file(tmp_path, [ok, dict(ok, name="b")]))
    with pytest.raises(TmmError, match="tmm-holders 1"):
        holders.library(write_user_file(tmp_path, [ok], fmt="other"))
    bad = tmp_path / "bad.json"
    bad.write_text("{ not json", encoding="utf-8")
    with pytest.raises(TmmError, match="not valid JSON"):
        holders.library(bad)


def test_unknown_names_suggest_close_ones() -> None:
    with pytest.raises(TmmError) as err:
        holders.holder("HSK63A shrink 6x100")
    assert "'HSK63A shrink 6x80'" in str(err.value)
    with pytest.raises(TmmError) as err:
        holders.holder("zzz")
    assert "holders.names()" in str(err.value)


def test_holder_made_in_code_is_validated() -> None:
    h = Holder("probe", "collet", 2, 10, ((20, 30, 30),))
    assert h.bodies(50, 0.5) == [(50, 70, 15, 15, 0.5)]
    with pytest.raises(TmmError, match="nose"):
        Holder("tight", "collet", 2, 10, ((20, 10, 30),))
