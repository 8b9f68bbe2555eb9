"""The `tmm` command (scripts/tmm): its subcommands reach the planner and the batch, and anything else is refused."""
from __future__ import annotations

import subprocess
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]


def _tmm(*args: str, cwd: Path) -> subprocess.CompletedProcess:
    return subprocess.run([str(ROOT / "scripts" / "tmm"), *args], capture_output=True, text=True, cwd=cwd, timeout=60)


def test_subcommands_and_refusals(tmp_path):
    none = _tmm(cwd=tmp_path)
    assert none.returncode == 2 and "usage: tmm {plan|batch}" in none.stderr
    other = _tmm("mill", cwd=tmp_path)
    assert other.returncode == 2 and "got 'mill'" in other.stderr
    job = tmp_path / "job.yaml"
    job.write_text("format: tmm-plan 1\nmodel: {file: nowhere.stl, units: mm}\n")
    plan = _tmm("plan", str(job), cwd=tmp_path)
    assert plan.returncode == 2 and "bad input" in plan.stderr, plan.stderr   # the planner's own refusal
    batch = _tmm("batch", str(tmp_path / "missing"), cwd=tmp_path)
    assert batch.returncode == 2 and "JOBS: " in batch.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == ["job.yaml"]          # nothing written
