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

Each try recomputes the op and those after it and simulates the whole Job again: on a large model with a D1 pencil
and clean-up (mount_rush) one try took over 15 minutes on a loaded machine. The tries are bounded (Budget): at most
MAX_TRIES, and none started that would likely end after MAX_SECONDS (the longest try so far, at first the Job's
first verification, taken as the next one's length); an op not tried is left out with that reason.
"""
from __future__ import annotations

import time
from dataclasses import dataclass, field
from typing import Callable

MAX_TRIES = 3            # changed ops verified again in one plan run
MAX_SECONDS = 1200.0     # s of wall time the tries may take together


def retries(op: dict) -> list[tuple[dict, str]]:
    """The changes (API keyword arguments) to try, in order, on the plan's `op` (OpPlan.as_dict()) that failed
    the verification for its shank or holder, each with its reason; none for an op that is not optional (a
    failing roughing or finishing op stops the plan) or already leaves those moves out."""
    if not op.get("optional") or op["kwargs"].get("holder_collision", "lift") == "leave_out":
        return []
    return [({"holder_collision": "leave_out"},
             "its moves where the shank or holder would come too close left out (the linker retracts over them) in "
             "place of lifting the tool there: lifted moves passed inside the clearance")]


@dataclass
class Budget:
    """How many re-plan tries and how much wall time are left; `first`: s the Job's first verification took (the
    first try's expected length)."""
    first: float
    tries: int = MAX_TRIES
    seconds: float = MAX_SECONDS
    clock: Callable[[], float] = time.monotonic
    used: int = field(default=0, init=False)
    longest: float = field(default=0.0, init=False)

    def __post_init__(self) -> None:
        if not (self.tries >= 0 and self.seconds >= 0 and self.first >= 0):
            raise ValueError(f"re-plan budget: tries {self.tries!r}, seconds {self.seconds!r} and the first "
                             f"verification's {self.first!r} s must be >= 0")
        self.start = self.clock()

    def refusal(self) -> str:
        """Why no further try is started ('' when one may be)."""
        if self.used >= self.tries:
            return f"the re-plan's limit of {self.tries} tries reached"
        spent = self.clock() - self.start
        expected = max(self.longest, self.first)
        if spent + expected > self.seconds:
            return (f"the re-plan's time limit: {spent:.0f} s spent, a try takes about {expected:.0f} s, "
                    f"{self.seconds:.0f} s allowed")
        return ""

    def spend(self, seconds: float) -> None:
        self.used += 1
        self.longest = max(self.longest, seconds)


def change_failing(failing: list[str], ops: dict, attempt: Callable[[str, dict], bool], budget: Budget
                   ) -> list[str]:
    """Each of the `failing` ops' changes (retries(ops[label])) tried in turn by `attempt(label, change)`, which
    applies it, verifies the Job and keeps it (True: the op no longer fails) or sets it back (False), while
    `budget` allows. The report's notes: 'changed <op>: <why>' for a change kept, 'not changed <op>: <why not>'
    for an op the budget stopped (it is then left out as an op no change clears)."""
    notes = []
    for label in failing:
        for change, why in retries(ops[label]):
            refusal = budget.refusal()
            if refusal:
                notes.append(f"not changed {label}: {refusal}")
                break
            start = budget.clock()
            kept = attempt(label, change)
            budget.spend(budget.clock() - start)
            if kept:
                notes.append(f"changed {label}: {why}")
                break
    return notes
