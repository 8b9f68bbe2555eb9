"""TMM's 5-axis Path representation: X Y Z tip, U V W tool axis, modal within one Path."""
from __future__ import annotations

import math

import numpy as np
import pytest

from tmm_workbench.core import path5
from tmm_workbench.core.errors import TmmError
from tmm_workbench.core.toolpath import Move, MoveKind, Toolpath

RNG = np.random.default_rng(5)


def random_toolpath(n: int = 500) -> Toolpath:
    tp = Toolpath()
    for k in range(n):
        c, a = RNG.uniform(0, math.radians(45)), RNG.uniform(-math.pi, math.pi)
        axis = (math.sin(c) * math.cos(a), math.sin(c) * math.sin(a), math.cos(c))
        kind = [MoveKind.RAPID, MoveKind.PLUNGE, MoveKind.FEED][k % 3]
        tp.add(kind, *RNG.uniform(-100, 100, 3), axis=axis)
    return tp


def test_encode_decode_is_exact():
    tp = random_toolpath()
    cmds = path5.encode_toolpath(tp, horiz_feed=20.0, vert_feed=5.0)
    assert all(set("XYZUVW") <= set(p) for _, p in cmds)
    assert [n for n, _ in cmds[:3]] == ["G0", "G1", "G1"]
    assert "F" not in cmds[0][1] and cmds[1][1]["F"] == 5.0 and cmds[2][1]["F"] == 20.0
    back = path5.decode_commands(cmds)
    for m, d in zip(tp, back):
        assert d.tip == (m.x, m.y, m.z)
        assert np.abs(np.array(d.axis) - np.array(m.axis)).max() <= 2.3e-16  # floating point, at worst 1 ulp
    again = path5.moves_from_commands(cmds)
    assert len(again) == len(tp)
    assert [m.kind for m in again][:2] == [MoveKind.RAPID, MoveKind.FEED]


def test_three_axis_paths_need_no_axis_words():
    tp = Toolpath()
    tp.add(MoveKind.RAPID, 0, 0, 10)
    tp.add(MoveKind.FEED, 1, 0, 0)
    cmds = path5.encode_toolpath(tp, 10.0, 5.0)
    assert all(not set("UVW") & set(p) for _, p in cmds)
    assert [m.axis for m in path5.decode_commands(cmds)] == [(0.0, 0.0, 1.0)] * 2
    name, params = path5.encode(Move(MoveKind.FEED, 1, 2, 3, (0.6, 0.0, 0.8)), feed=7.0)
    assert name == "G1" and params == {"X": 1, "Y": 2, "Z": 3, "U": 0.6, "V": 0.0, "W": 0.8, "F": 7.0}


def test_modal_rules():
    cmds = [("(op)", {}), ("G0", {"Z": 50.0}),
            ("G0", {"X": 1.0, "Y": 2.0, "U": 0.6, "V": 0.0, "W": 0.8}),
            ("G1", {"Z": 3.0, "F": 4.0}),
            ("M8", {}),
            ("G1", {"X": 2.0})]
    moves = path5.decode_commands(cmds)
    assert [m.index for m in moves] == [1, 2, 3, 5]
    assert math.isnan(moves[0].tip[0]) and moves[0].tip[2] == 50.0 and moves[0].axis == (0, 0, 1)
    assert moves[1].tip == (1.0, 2.0, 50.0) and moves[1].axis == (0.6, 0.0, 0.8)
    assert moves[2].tip == (1.0, 2.0, 3.0) and moves[2].axis == (0.6, 0.0, 0.8) and moves[2].feed == 4.0
    assert moves[3].tip == (2.0, 2.0, 3.0) and moves[3].feed == 4.0
    # a new Path starts vertical again
    assert path5.decode_commands([("G1", {"X": 0.0, "Y": 0.0, "Z": 0.0})])[0].axis == (0.0, 0.0, 1.0)


def test_axis_words_errors_and_normalising():
    with pytest.raises(TmmError, match="W missing"):
        path5.decode_commands([("G1", {"X": 0.0, "U": 1.0, "V": 0.0})])
    with pytest.raises(TmmError, match="no direction"):
        path5.axis_of({"U": 0.0, "V": 0.0, "W": 0.0})
    assert path5.axis_of({"X": 1.0}) is None
    # a vector rounded to 6 decimals (a saved document) comes back unit
    u = path5.axis_of({"U": 0.267261, "V": 0.534522, "W": 0.801784})
    assert abs(math.sqrt(sum(c * c for c in u)) - 1) < 1e-15
    with pytest.raises(TmmError, match="arcs"):
        path5.moves_from_commands([("G1", {"X": 0.0, "Y": 0.0, "Z": 0.0}), ("G2", {"X": 1.0, "I": 0.5})])
    with pytest.raises(TmmError, match="never given"):
        path5.moves_from_commands([("G0", {"Z": 5.0})])
