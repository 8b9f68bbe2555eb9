"""The re-plan of an optional op that alone fails the verification for its shank or holder (core.plan.replan):
the change tried before it is left out, and the ops it is never tried on."""
from __future__ import annotations

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
