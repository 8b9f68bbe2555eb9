"""Where a planner run stands, for whoever waits on it (the web page): the step it is on, out of how many, and what
it does, in a small JSON file named by $TMM_PROGRESS_FILE (written whole: a reader never sees half a note). The
planner's command writes the first note (the analysis and the plan), its FreeCAD run the others (one per op, then the
simulation, the post, the document); without the variable nothing is written."""
from __future__ import annotations

import json
import os
from pathlib import Path
from typing import Optional

ENV = "TMM_PROGRESS_FILE"


def note(step: int, steps: int, doing: str) -> None:
    """Step `step` of `steps` (0: not known yet) is `doing`."""
    path = os.environ.get(ENV)
    if not path:
        return
    part = f"{path}.part"
    try:
        with open(part, "w", encoding="utf-8") as f:
            json.dump({"step": int(step), "steps": int(steps), "doing": str(doing)}, f)
        os.replace(part, path)
    except OSError:   # progress is for people: a full disk or a removed folder never fails the plan
        pass


def read(path: Path) -> Optional[dict]:
    """The last note at `path`, None when there is none (not started, or finished and cleared)."""
    try:
        data = json.loads(Path(path).read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None
    if not isinstance(data, dict) or not {"step", "steps", "doing"} <= data.keys():
        return None
    return data


def words(data: dict) -> str:
    """'computing TMM Waterline (step 3 of 6)'."""
    if data["steps"]:
        return f"{data['doing']} (step {data['step']} of {data['steps']})"
    return str(data["doing"])
