"""`python3 -m tmm_workbench plan|batch ...` (the `tmm` command, scripts/tmm): the automatic planner of one job
file (docs/planner.md), or many on Dask (docs/batch.md)."""
from __future__ import annotations

import sys
from typing import Optional, Sequence

COMMANDS = {"plan": "tmm_workbench.core.plan.launch", "batch": "tmm_workbench.batch.run"}


def main(argv: Optional[Sequence[str]] = None) -> int:
    import importlib

    args = list(sys.argv[1:] if argv is None else argv)
    if not args or args[0] not in COMMANDS:
        print(f"usage: tmm {{{'|'.join(COMMANDS)}}} ...  (got {args[0]!r})" if args else
              f"usage: tmm {{{'|'.join(COMMANDS)}}} ...", file=sys.stderr)
        return 2
    return importlib.import_module(COMMANDS[args[0]]).main(args[1:])


if __name__ == "__main__":
    raise SystemExit(main())
