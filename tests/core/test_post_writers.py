"""Tarus G-code and APT CL writers: output parsed back (Tarus through forward kinematics) reproduces the
tool path; feeds, units, tool changes, limits, arcs, arguments, FreeCAD-like objects."""
from __future__ import annotations

import math
import re
from types import SimpleNamespace

import numpy as np
import pytest

from tmm_workbench.core import path5
from tmm_workbench.core.errors import TmmError
from tmm_workbench.core.machine import JointLimitError, Joints, TarusMachine, rotary
from tmm_workbench.app import post_objects as objects
from tmm_workbench.core.post import Operation, ToolInfo, apt_writer, tarus_writer
from tmm_workbench.core.post.apt_writer import AptOptions, write_apt
from tmm_workbench.core.post.tarus_writer import TarusOptions, write_tarus
from tmm_workbench.core.toolpath import MoveKind, Toolpath
from tests.core import machine_view

TOOL = ToolInfo(number=3, label="6 mm ball", shape="ballend", diameter=6.0, corner_radius=3.0, cutting_height=20.0,
                spindle_rpm=12000, spindle_dir="CW")
HORIZ, VERT = 20.0, 5.0  # mm/s, as FreeCAD keeps feeds
EXACT = TarusOptions(precision=10, angle_precision=12)

_WORD = re.compile(r"([A-Z])\s*([-+]?\d*\.?\d+)")


def parse_tarus(text: str, inches: bool = False) -> list[dict]:
    """Every motion line of Tarus G-code: {'G', 'X'.., 'A', 'C' (rad), 'F', 'mode' (G93|G94)} with modal
    coordinates carried; lengths back in mm."""
    scale = 25.4 if inches else 1.0
    state = {"X": math.nan, "Y": math.nan, "Z": math.nan, "A": math.nan, "C": math.nan}
    mode, motion, out = "G94", None, []
    for raw in text.splitlines():
        line = re.sub(r"\(.*?\)", "", raw).strip()
        if not line or line == "%":
            continue
        words = _WORD.findall(line)
        gs = [float(v) for k, v in words if k == "G"]
        for g in gs:
            if g in (93, 94):
                mode = f"G{int(g)}"
            if g in (0, 1, 2, 3):
                motion = f"G{int(g)}"
        if not any(k in state for k, _ in words):
            continue
        feed = None
        for k, v in words:
            if k in "XYZ":
                state[k] = float(v) * scale
            elif k in "AC":
                state[k] = math.radians(float(v))
            elif k == "F":
                feed = float(v)
        out.append(dict(state, G=motion, F=feed, mode=mode,
                        IJ={k: float(v) * scale for k, v in words if k in "IJK"}))
    return out


def tilted_path(n: int = 240) -> Toolpath:
    """A rapid, a plunge, then a wavy cut whose axis turns round (A past +-180 deg), passes through the
    vertical and tilts up to 40 deg; a retract at the end."""
    tp = Toolpath()
    tp.add(MoveKind.RAPID, -30, 0, 60)
    tp.add(MoveKind.RAPID, -30, 0, 5)
    tp.add(MoveKind.PLUNGE, -30, 0, 0)
    for k in range(n):
        s = k / (n - 1)
        c = math.radians(40) * abs(math.sin(2.5 * math.pi * s))  # vertical at s = 0, 0.4, 0.8
        a = 1.5 * math.pi * s + 0.4
        axis = (math.sin(c) * math.cos(a), math.sin(c) * math.sin(a), math.cos(c))
        tp.add(MoveKind.FEED, -30 + 60 * s, 10 * math.sin(6 * s), 2 * math.cos(5 * s) - 2, axis=axis)
    last = tp.moves[-1]
    tp.add(MoveKind.FEED, last.x, last.y, last.z + 0.5, axis=last.axis)  # a plain linear move, same axis
    tp.add(MoveKind.RAPID, last.x, last.y, 60, axis=last.axis)
    return tp


def program(tp: Toolpath, label: str = "Surface") -> list:
    return [TOOL, Operation(label, [("(TMM 5-axis)", {})] + path5.encode_toolpath(tp, HORIZ, VERT), "Flood")]


# joint-mode subdivision off: one line per programmed move (the subdivision has tests of its own)
WHOLE = dict(tip_tolerance=1e9, axis_tolerance=1.5)


def fk(machine: TarusMachine, rows: list[dict], tcp: bool) -> tuple[np.ndarray, np.ndarray]:
    j = np.array([[r["X"], r["Y"], r["Z"], r["A"], r["C"]] for r in rows])
    tips, axes = machine.forward_path(j)
    if tcp:
        tips = j[:, :3]
    return tips, axes


@pytest.mark.parametrize("tcp", [False, True])
def test_tarus_gcode_round_trip_through_fk(tcp):
    m = TarusMachine(pivot_length=160.0, tool_length=90.0)
    tp = tilted_path()
    res = write_tarus(program(tp), m, TarusOptions(tcp=tcp, precision=10, angle_precision=12, **WHOLE))
    rows = parse_tarus(res.text)
    assert len(rows) == len(tp) == res.moves
    tips, axes = fk(m, rows, tcp)
    assert np.abs(tips - tp.points()).max() < 1e-6
    assert np.abs(axes - tp.axes()).max() < 1e-9
    a = np.array([r["A"] for r in rows])
    assert np.abs(np.diff(a)).max() < math.radians(30)  # unwrapped: no 360 deg jumps
    assert a.max() > math.pi  # the head really went round past 180 deg
    assert [r["G"] for r in rows][:3] == ["G0", "G0", "G1"]
    assert ("G43.4 H3" in res.text) is tcp


def test_default_precision_round_trip():
    m = TarusMachine()
    tp = tilted_path(60)
    rows = parse_tarus(write_tarus(program(tp), m, TarusOptions(**WHOLE)).text)
    tips, axes = fk(m, rows, False)
    # 4 decimals of mm, 6 of degrees on a 250 mm lever: 5e-5 + 250 * 2 * 8.7e-9 mm
    assert np.abs(tips - tp.points()).max() < 1e-4
    assert np.abs(axes - tp.axes()).max() < 1e-7


def test_inverse_time_feeds():
    m = TarusMachine()
    tp = tilted_path(80)
    text = write_tarus(program(tp), m, TarusOptions(precision=10, angle_precision=12, **WHOLE)).text
    rows = parse_tarus(text)
    pts = tp.points()
    joints = np.array([[r["X"], r["Y"], r["Z"], r["A"], r["C"]] for r in rows])
    n_g93, n_capped = 0, 0
    for k in range(1, len(rows)):
        r, p = rows[k], rows[k - 1]
        if r["G"] == "G0":
            assert r["F"] is None
            continue
        turns = abs(r["A"] - p["A"]) > 1e-12 or abs(r["C"] - p["C"]) > 1e-12
        feed = VERT if tp.moves[k].kind is MoveKind.PLUNGE else HORIZ
        dist = float(np.linalg.norm(pts[k] - pts[k - 1]))
        # the move's time: the tip distance at the feed, or longer if the joints need longer
        seconds = max(dist / feed, m.motion_time(joints[k - 1], joints[k]))
        n_capped += seconds > dist / feed * (1 + 1e-9)
        if turns:
            n_g93 += 1
            assert r["mode"] == "G93"
            assert r["F"] == pytest.approx(60.0 / seconds, rel=1e-6)
        else:
            assert r["mode"] == "G94"
            assert r["F"] == pytest.approx((dist / seconds if seconds > 0 else feed) * 60, rel=1e-6)
    assert n_g93 > 50 and n_capped > 0  # some moves turn A faster than the head can: slowed down
    assert rows[-2]["mode"] == "G94" and rows[-2]["F"] == pytest.approx(HORIZ * 60)  # the plain linear move
    assert "G93 G1" in text and "G94 G1" in text


def test_pure_reorientation_uses_joint_time():
    m = TarusMachine()
    tp = Toolpath()
    tp.add(MoveKind.FEED, 0, 0, 0)
    tp.add(MoveKind.FEED, 0, 0, 0, axis=(math.sin(0.3), 0, math.cos(0.3)))
    rows = parse_tarus(write_tarus(program(tp), m, TarusOptions(precision=10, angle_precision=12, **WHOLE)).text)
    t = m.motion_time(m.inverse((0, 0, 0), (0, 0, 1)), m.inverse((0, 0, 0), (math.sin(0.3), 0, math.cos(0.3))))
    assert t == pytest.approx(1.0)  # C 0.3 rad at 0.3 rad/s
    assert rows[1]["mode"] == "G93" and rows[1]["F"] == pytest.approx(60.0 / t)


def test_inches_scale_lengths_not_angles():
    m = TarusMachine()
    tp = tilted_path(40)
    mm = write_tarus(program(tp), m, TarusOptions(precision=10, angle_precision=12, **WHOLE)).text
    inch = write_tarus(program(tp), m, TarusOptions(inches=True, precision=10, angle_precision=12, **WHOLE)).text
    assert "G20" in inch and "G21" not in inch
    rmm, rin = parse_tarus(mm), parse_tarus(inch, inches=True)
    for a, b in zip(rmm, rin):
        assert a["A"] == b["A"] and a["C"] == b["C"]  # identical degree words
        for k in "XYZ":
            assert b[k] == pytest.approx(a[k], abs=1e-7)
        if a["mode"] == "G93":
            assert a["F"] == b["F"]  # inverse time has no length unit
        elif a["F"] is not None:
            assert b["F"] == pytest.approx(a["F"] / 25.4)
    tips, _ = fk(m, rin, False)
    assert np.abs(tips - tp.points()).max() < 1e-6


def test_three_axis_path_posts_plainly():
    m = TarusMachine(pivot_length=150, tool_length=100)
    tp = Toolpath()
    tp.add(MoveKind.RAPID, 1, 2, 30)
    tp.add(MoveKind.PLUNGE, 1, 2, 0)
    tp.add(MoveKind.FEED, 5, 2, -1)
    cmds = [("G0", {"Z": 40.0})] + path5.encode_toolpath(tp, HORIZ, VERT)
    joint = write_tarus([TOOL, Operation("Op", cmds)], m).text
    assert "G0 Z290.0000 A0.000000 C0.000000" in joint  # X, Y not known yet: not printed
    assert "G1 X5.0000 Y2.0000 Z249.0000 A0.000000 C0.000000 F1200.0000" in joint
    assert "G93" not in joint
    tcp = write_tarus([TOOL, Operation("Op", cmds)], m, TarusOptions(tcp=True)).text
    assert "G1 X5.0000 Y2.0000 Z-1.0000 A0.000000 C0.000000 F1200.0000" in tcp


def test_header_tool_change_footer():
    text = write_tarus(program(tilted_path(10)), TarusMachine(), TarusOptions(line_numbers=True)).text
    lines = text.splitlines()
    assert lines[0] == "%" and lines[-1] == "%"
    body = [re.sub(r"^N\d+ ", "", ln) for ln in lines]
    for want in ("G17 G21 G40 G49 G80 G90 G94", "M5", "T3 M6", "S12000 M3", "M8", "M9", "M2"):
        assert want in body, want
    assert body.index("T3 M6") < body.index("S12000 M3") < body.index("M8")
    assert any("estimated cycle time" in ln for ln in body)
    assert all(re.match(r"N\d+ ", ln) for ln in lines[1:-1])
    quiet = write_tarus(program(tilted_path(10)), TarusMachine(), TarusOptions(comments=False)).text
    assert "(" not in quiet


def test_cycle_time_estimate():
    m = TarusMachine()
    tp = tilted_path(50)
    res = write_tarus(program(tp), m, TarusOptions(precision=10, angle_precision=12, **WHOLE))
    joints = rotary.solve_path(m, tp.points(), tp.axes(), rapid=[mv.kind is MoveKind.RAPID for mv in tp])
    feeds = [None if mv.kind is MoveKind.RAPID else (VERT if mv.kind is MoveKind.PLUNGE else HORIZ) for mv in tp]
    assert res.cycle_time == pytest.approx(m.cycle_time(joints, tp.points(), feeds), rel=1e-9)


def test_limit_violation_is_an_error():
    tp = Toolpath()
    tp.add(MoveKind.FEED, 0, 0, 0)
    tp.add(MoveKind.FEED, 1, 0, 0, axis=(math.sin(math.radians(50)), 0, math.cos(math.radians(50))))
    with pytest.raises(JointLimitError) as err:
        write_tarus(program(tp, "Steep"), TarusMachine())
    msg = str(err.value)
    assert "operation 'Steep', command 2 (G1)" in msg and "joint C = 50 deg" in msg
    assert err.value.joint == "C" and err.value.index == 2
    # allowed with a wider tilt range
    write_tarus(program(tp, "Steep"), TarusMachine(c_limits=(0.0, math.radians(60))))


def test_arcs_and_unsupported_commands():
    m = TarusMachine()
    u = (0.6, 0.0, 0.8)
    start = {"X": 0.0, "Y": 0.0, "Z": 0.0, "U": u[0], "V": u[1], "W": u[2], "F": 10.0}
    arc = ("G2", {"X": 10.0, "Y": 0.0, "Z": 0.0, "I": 5.0, "J": 0.0, "F": 10.0})
    rows = parse_tarus(write_tarus([TOOL, Operation("Arc", [("G1", start), arc])], m, EXACT).text)
    assert rows[1]["G"] == "G2" and rows[1]["IJ"] == {"I": 5.0, "J": 0.0}
    tips, axes = fk(m, rows, False)
    np.testing.assert_allclose(tips[1], [10, 0, 0], atol=1e-9)
    np.testing.assert_allclose(axes[1], u, atol=1e-12)
    turned = ("G2", dict(arc[1], U=0.0, V=0.0, W=1.0))
    with pytest.raises(TmmError, match="orientation"):
        write_tarus([TOOL, Operation("Arc", [("G1", start), turned])], m)
    with pytest.raises(TmmError, match="G81"):
        write_tarus([TOOL, Operation("Drill", [("G81", {"X": 1.0, "Y": 1.0, "Z": -3.0, "R": 2.0})])], m)
    with pytest.raises(TmmError, match="feed"):
        write_tarus([TOOL, Operation("NoFeed", [("G1", {"X": 1.0, "Y": 1.0, "Z": 1.0})])], m)
    passthrough = write_tarus([Operation("Fixture", [("G54", {})])], m).text
    assert "\nG54\n" in passthrough


def test_tarus_arguments():
    machine, opts = tarus_writer.parse_args("--tcp --inches --no-show-editor --pivot-length 200 --tool-length 50 "
                                            "--c-max 60 --a-min -360 --a-max 360 --precision 5")
    assert opts.tcp and opts.inches and opts.precision == 5
    assert machine.pivot_length == 200 and machine.tool_length == 50
    assert machine.c_limits == (0.0, pytest.approx(math.radians(60)))
    assert machine.a_limits == (pytest.approx(-2 * math.pi), pytest.approx(2 * math.pi))
    machine, opts = tarus_writer.parse_args("")
    assert not opts.tcp and machine == TarusMachine()
    with pytest.raises(TmmError, match="unrecognized"):
        tarus_writer.parse_args("--bogus")
    with pytest.raises(TmmError, match="both"):
        tarus_writer.parse_args("--a-min 0")
    assert "--tcp" in tarus_writer.TOOLTIP_ARGS


# --- APT CL ------------------------------------------------------------------------------------
_NUM = r"(-?\d+\.\d+)"


def parse_goto(text: str) -> np.ndarray:
    rows = [[float(v) for v in ln[len("GOTO/"):].split(",")] for ln in text.splitlines() if ln.startswith("GOTO/")]
    return np.array(rows).reshape(-1, 6)


def test_apt_cl_records():
    tp = tilted_path(30)
    text = write_apt(program(tp), AptOptions(date="Monday"))
    lines = text.splitlines()
    assert lines[0] == "$$ -----"
    for want in ("PARTNO PART TO BE MACHINED", "UNITS/MM", "MULTAX/ON", "LOADTL/3", "SPINDL/ 12000.0000,RPM,CLW",
                 "COOLNT/ON", "COOLNT/OFF", "SPINDL/OFF", "FINI"):
        assert want in lines, want
    assert "CUTTER/ 6.000000, 3.000000, 0.000000, 3.000000, 0.000000, 0.000000, 20.000000" in lines
    assert "TOOLNO/3, 6.000000" in lines and "TPRINT/T3 6 mm ball" in lines
    assert "FEDRAT/ 300.0000,MMPM" in lines and "FEDRAT/ 1200.0000,MMPM" in lines
    assert "$$ OPERATION NAME : Surface" in lines
    gotos = [ln for ln in lines if ln.startswith("GOTO/")]
    assert all(re.fullmatch(r"GOTO/ " + ",".join([_NUM] * 6), g) for g in gotos)
    g = parse_goto(text)
    assert len(g) == len(tp)
    assert np.abs(g[:, :3] - tp.points()).max() <= 5e-7
    assert np.abs(g[:, 3:] - tp.axes()).max() <= 5e-7
    assert np.abs(np.linalg.norm(g[:, 3:], axis=1) - 1).max() < 2e-6
    # RAPID before each rapid GOTO, FEDRAT before the first feed GOTO
    idx = [i for i, ln in enumerate(lines) if ln.startswith("GOTO/")]
    rapid = [lines[i - 1] == "RAPID" for i in idx]
    assert rapid == [m.kind is MoveKind.RAPID for m in tp]
    assert lines.index("LOADTL/3") < lines.index("SPINDL/ 12000.0000,RPM,CLW") < idx[0]


def test_apt_inches_bull_nose_and_arcs():
    bull = ToolInfo(number=1, shape="bullnose", diameter=10.0, corner_radius=2.0, cutting_height=30.0,
                    spindle_rpm=8000, spindle_dir="CCW")
    cmds = [("G0", {"Z": 20.0}), ("G0", {"X": 0.0, "Y": 0.0}), ("G1", {"Z": 0.0, "F": 10.0}),
            ("G3", {"X": 20.0, "Y": 0.0, "I": 10.0, "J": 0.0, "F": 10.0})]
    text = write_apt([bull, Operation("Arc", cmds)], AptOptions(inches=True, date="x"))
    lines = text.splitlines()
    assert "UNITS/INCHES" in lines and "SPINDL/ 8000.0000,RPM,CCLW" in lines
    assert f"FEDRAT/ {600 / 25.4:.4f},IPM" in lines
    d, r = 10 / 25.4, 2 / 25.4
    assert f"CUTTER/ {d:.6f}, {r:.6f}, {d / 2 - r:.6f}, {r:.6f}, 0.000000, 0.000000, {30 / 25.4:.6f}" in lines
    g = parse_goto(text) * np.array([25.4, 25.4, 25.4, 1, 1, 1])
    assert len(g) > 50  # the arc as points; the partial first rapid 'G0 Z20' is not a CL point
    pts = g[2:]
    rad = np.hypot(pts[:, 0] - 10, pts[:, 1])
    assert np.abs(rad - 10).max() < 1e-4
    assert np.all(pts[:-1, 1] <= 1e-9)  # counter-clockwise from (0,0) about (10,0): through y < 0
    np.testing.assert_allclose(pts[-1, :3], [20, 0, 0], atol=1e-5)


def test_apt_arguments_and_errors():
    opts = apt_writer.parse_args("--inches --precision 4 --partno BLADE --no-show-editor")
    assert opts.inches and opts.precision == 4 and opts.partno == "BLADE"
    with pytest.raises(TmmError):
        apt_writer.parse_args("--precision 40")
    with pytest.raises(TmmError, match="feed"):
        write_apt([Operation("Op", [("G1", {"X": 0.0, "Y": 0.0, "Z": 0.0})])])


def test_apt_without_header_is_the_same_file_whatever_the_date():
    tp = Toolpath()
    tp.add(MoveKind.RAPID, 0, 0, 10)
    tp.add(MoveKind.PLUNGE, 0, 0, 0)
    tp.add(MoveKind.FEED, 5, 0, 0)
    plain = apt_writer.parse_args("--no-header")
    texts = [write_apt(program(tp), AptOptions(date=d, header=plain.header)) for d in ("Monday", "Tuesday")]
    assert texts[0] == texts[1] and "$$" not in texts[0].split("PARTNO")[0]
    assert "Monday" in write_apt(program(tp), AptOptions(date="Monday"))


# --- FreeCAD-like objects -> program ------------------------------------------------------------
class Cmd:
    def __init__(self, name, params):
        self.Name, self.Parameters = name, params


def q(v):
    return SimpleNamespace(Value=v)


def test_program_from_objects():
    bit = SimpleNamespace(Label="Bull", BitShape="/x/bullnose.fcstd", Diameter=q(8.0), FlatRadius=q(3.0),
                          CuttingEdgeHeight=q(25.0), SpindlePower=True)
    tc = SimpleNamespace(Label="TC", ToolNumber=4, Tool=bit, SpindleSpeed=9000.0, SpindleDir="Reverse",
                         Path=SimpleNamespace(Commands=[Cmd("M6", {"T": 4})]))
    op = SimpleNamespace(Label="Op", Active=True, CoolantMode="Mist",
                         Path=SimpleNamespace(Commands=[Cmd("G0", {"X": 1.0, "Y": 2.0, "Z": 3.0})]))
    off = SimpleNamespace(Label="Off", Active=False, Path=SimpleNamespace(Commands=[]))
    group = SimpleNamespace(Group=[op])
    prog = objects.program_from_objects([tc, off, group, SimpleNamespace(Label="stock")])
    assert len(prog) == 2
    t, o = prog
    assert (t.number, t.shape, t.diameter, t.corner_radius, t.cutting_height) == (4, "bullnose", 8.0, 1.0, 25.0)
    assert (t.spindle_rpm, t.spindle_dir, t.label) == (9000.0, "CCW", "Bull")
    assert o.label == "Op" and o.coolant == "Mist" and o.commands == [("G0", {"X": 1.0, "Y": 2.0, "Z": 3.0})]


def test_operations_continue_from_the_previous_position():
    m = TarusMachine()
    tilted = {"X": 0.0, "Y": 0.0, "Z": 0.0, "U": 0.6, "V": 0.0, "W": 0.8}
    prog = [TOOL, Operation("One", [("G0", tilted)]), Operation("Two", [("G0", {"Z": 10.0})])]
    rows = parse_tarus(write_tarus(prog, m, EXACT).text)
    # the second Path starts vertical again (axis words are modal per Path), X Y carried from the first
    tip, axis = m.forward(Joints(rows[1]["X"], rows[1]["Y"], rows[1]["Z"], rows[1]["A"], rows[1]["C"]))
    np.testing.assert_allclose(axis, [0, 0, 1])
    np.testing.assert_allclose(tip, [0, 0, 10], atol=1e-9)


# --- the machine's view: linear joint interpolation, joint speeds, A limits (issue 11) ---------------
def test_joint_mode_moves_stay_on_their_lines_and_in_time():
    """A control without TCP interpolates X Y Z A C linearly: whole moves leave the straight line by far; the
    default post splits them so the tip stays within 0.005 mm and the axis within 0.05 deg, every line
    doable at the joint speeds, A inside +-360 deg and never 180 deg in one line."""
    m = TarusMachine()
    tp = tilted_path()
    whole = machine_view.view(m, write_tarus(program(tp), m, TarusOptions(**WHOLE)).text)
    text = write_tarus(program(tp), m).text
    split = machine_view.view(m, text)
    assert whole.largest_tip_deviation > 0.05
    assert split.largest_tip_deviation <= 0.005 + 1e-4    # + the 4-decimal rounding of the words
    assert split.largest_axis_deviation <= math.radians(0.05) + 1e-7
    assert split.lines > whole.lines
    assert not split.too_fast and not whole.too_fast
    assert split.largest_a_step < math.pi
    assert -2 * math.pi - 1e-9 <= split.a_min and split.a_max <= 2 * math.pi + 1e-9
    # every programmed tip is on the path, in order
    lines = machine_view.read_tarus(text)
    tips = [m.forward(ln.joints)[0] for ln in lines if not np.isnan(ln.joints).any()]
    k = 0
    for p in tp.points()[1:]:
        while k < len(tips) and np.linalg.norm(tips[k] - p) > 1e-3:
            k += 1
        assert k < len(tips), p
    tcp_text = write_tarus(program(tp), m, TarusOptions(tcp=True)).text
    tcp = machine_view.view(m, tcp_text, tcp=True)
    # TCP: the control keeps the tip on its line; lines split only where linear A, C leave the axis's slerp
    assert whole.lines <= tcp.lines < split.lines and not tcp.too_fast


def test_tolerance_arguments():
    m, o = tarus_writer.parse_args("--tip-tolerance 0.01 --axis-tolerance 0.2 --a-continuous")
    assert o.tip_tolerance == 0.01 and o.axis_tolerance == pytest.approx(math.radians(0.2)) and m.a_limits is None
    m, _ = tarus_writer.parse_args("")
    assert m.a_limits == (-2 * math.pi, 2 * math.pi)
    with pytest.raises(TmmError, match="tip-tolerance"):
        tarus_writer.parse_args("--tip-tolerance 0")
    with pytest.raises(TmmError, match="exclude"):
        tarus_writer.parse_args("--a-continuous --a-min -10 --a-max 10")
