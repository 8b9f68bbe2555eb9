"""The re-plan of an optional op (a rest, a pencil) that alone fails the verification for its shank or holder:
before it is left out (its material reported as left), the op itself is changed and the Job verified again, the
first change that passes kept and written into the report with its reason.

The change keeps the tool (what it reaches stays reachable): where the shank or holder would come too close, the
moves are left out (`holder_collision: leave_out`, the linker retracts over the gap) in place of lifting the tool
there. A lifted move climbing past a wall's top passed under the shank's clearance between its samples
(wheel_in_box's rest D4: 0.157 mm on 35 moves), a lifted pencil move brought the shank within its clearance of
the stock the rest left (beet's pencil D1: 0.029 mm on 2 moves); left out, both verified (2026-12-07). Growing the
clearance was tried and did not clear either (the verification judges the op at its own clearance: wheel_in_box
at 1.3 mm 0.194 mm inside it, beet at 1.2 mm 0.041 mm), so it is not tried.
"""
from __future__ import annotations


def retries(op: dict) -> list[tuple[dict, str]]:
    """The changes (API keyword arguments) to try, in order, on the plan's `op` (OpPlan.as_dict()) that failed
    the verification for its shank or holder, each with its reason; none for an op that is not optional (a
    failing roughing or finishing op stops the plan) or already leaves those moves out."""
    if not op.get("optional") or op["kwargs"].get("holder_collision", "lift") == "leave_out":
        return []
    return [({"holder_collision": "leave_out"},
             "its moves where the shank or holder would come too close left out (the linker retracts over them) in "
             "place of lifting the tool there: lifted moves passed inside the clearance")]
