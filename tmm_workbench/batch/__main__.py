"""`python3 -m tmm_workbench.batch JOBS...` (also `tmm batch`): see tmm_workbench.batch.run."""
from tmm_workbench.batch.run import main

if __name__ == "__main__":
    raise SystemExit(main())
