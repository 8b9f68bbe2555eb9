"""The re-plan of an optional op that alone fails the verification for its shank or holder (core.plan.replan):
the change tried before it is left out, and the ops it is never tried on."""
from __future__ import annotations

import pytest

from tmm_workbench.core.plan import decide, replan


def op(optional: bool, **kwargs: object) -> dict:
    return decide.OpPlan("run_surface", "Rest T5 ball D3", "T5 ball D3",
                         {"tool": "ballend", "diameter": 3.0, "region": "rest", **kwargs}, optional=optional).as_dict()


def test_a_failing_rest_leaves_the_moves_out_in_place_of_lifting() -> None:
    changes = replan.retries(op(True))
    assert [c for c, _ in changes] == [{"holder_collision": "leave_out"}]
    assert "left out" in changes[0][1] and "lifting" in changes[0][1]


def test_nothing_tried_on_a_required_op_or_one_leaving_them_out_already() -> None:
    assert replan.retries(op(False)) == []     # a roughing or finishing op: the plan stops with the reason
    assert replan.retries(op(True, holder_collision="leave_out")) == []
    assert replan.retries(op(True, holder_collision="lift")) != []


class Clock:
    """A wall clock the attempts move on."""

    def __init__(self) -> None:
        self.now = 0.0

    def __call__(self) -> float:
        return self.now


def failing_ops(n: int) -> dict:
    return {f"Rest {k}": dict(op(True), label=f"Rest {k}") for k in range(n)}


def test_the_replan_stops_at_its_limit_of_tries_with_the_reason() -> None:
    clock, tried = Clock(), []

    def attempt(label: str, change: dict) -> bool:
        tried.append(label)
        clock.now += 10.0
        return False                       # no change clears any op

    ops = failing_ops(4)
    notes = replan.change_failing(list(ops), ops, attempt, replan.Budget(10.0, tries=2, seconds=1e6, clock=clock))
    assert tried == ["Rest 0", "Rest 1"]
    assert notes == ["not changed Rest 2: the re-plan's limit of 2 tries reached",
                     "not changed Rest 3: the re-plan's limit of 2 tries reached"]


def test_the_replan_starts_no_try_that_would_end_after_its_time_limit() -> None:
    # mount_rush's tries took over 15 minutes each: a budget of 1000 s after a first verification of 300 s allows
    # three tries of 300 s (900 s), not a fourth; a try found longer than the first counts as the next one's length
    clock, tried = Clock(), []
    took = {"Rest 0": 300.0, "Rest 1": 300.0, "Rest 2": 300.0, "Rest 3": 300.0}

    def attempt(label: str, change: dict) -> bool:
        tried.append(label)
        clock.now += took[label]
        return label == "Rest 1"

    ops = failing_ops(4)
    budget = replan.Budget(300.0, tries=10, seconds=1000.0, clock=clock)
    notes = replan.change_failing(list(ops), ops, attempt, budget)
    assert tried == ["Rest 0", "Rest 1", "Rest 2"]
    assert notes[0].startswith("changed Rest 1: ")
    assert notes[1] == ("not changed Rest 3: the re-plan's time limit: 900 s spent, a try takes about 300 s, "
                        "1000 s allowed")
    clock.now, tried[:] = 0.0, []
    took["Rest 0"] = 700.0                  # the first try twice the first verification: the second would not end
    notes = replan.change_failing(list(ops), ops, attempt, replan.Budget(300.0, tries=10, seconds=1000.0, clock=clock))
    assert tried == ["Rest 0"] and len(notes) == 3 and all("700 s spent" in n for n in notes)


def test_the_replan_budget_refuses_negative_limits() -> None:
    with pytest.raises(ValueError, match="tries -1"):
        replan.Budget(1.0, tries=-1)
