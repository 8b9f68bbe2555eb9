"""`python3 -m tmm_workbench.plan job.yaml`: the automatic planner (core.plan.launch; docs/planner.md)."""
from tmm_workbench.core.plan.launch import main

if __name__ == "__main__":
    raise SystemExit(main())
