"""Cycle time spent plunging (benchmarks/plunge_share.py at its quick size): entries rapid down to the entry
clearance above what is left (the roughed stock kept up to date as the op cuts; the verification's simulated
surface) instead of feeding from the safe height, and waterline loops reached from the level above with the tool
down: the plunge share falls, and the stock simulation sees no rapid cut into the stock."""
from __future__ import annotations

import pytest

from benchmarks import plunge_share as ps


def check(rows, most: float) -> None:
    before, after = rows
    assert not before.known and after.known
    assert before.rapid_hits == after.rapid_hits == 0          # never a rapid into the stock
    assert after.share < most, after.text()
    assert after.plunge_s < 0.5 * before.plunge_s, (before.text(), after.text())


def test_sphere_cavity_roughed_then_waterlined():
    rows = ps.roughed_then_waterlined("sphere cavity", ps.sphere_cavity(30.0, 60))
    check(rows, 0.10)
    assert rows[1].plunges <= 5    # the levels' loops reached from the one above with the tool down


def test_random_field_roughed_then_waterlined():
    # short loops round many bumps: each entry still feeds the clearance and the step (16 % measured: the loops
    # taken wall by wall, nearest first, enter 46 times where the level-by-level order entered 40 (14 %))
    check(ps.roughed_then_waterlined("random field", ps.random_field(30.0, 60)), 0.17)


def test_adaptive_with_verify_cusp():
    check(ps.adaptive_verify("sphere cavity", ps.sphere_cavity(30.0, 60)), 0.10)
