"""The batch's summary: a CSV a program reads and an HTML page people read (parts, how each ended, cycle times,
failures with their reasons, links to each part's files), both written whole then renamed."""
from __future__ import annotations

import csv
import html
import io
import os
from pathlib import Path
from typing import Sequence

COLUMNS = ("part", "state", "exit_code", "seconds", "peak_mb", "cycle_s", "deepest_gouge_mm", "most_left_mm",
           "worker", "folder", "problems", "reason")


def write_summary(rows: Sequence[dict], out_root: Path, wall_s: float, workers: int) -> tuple[Path, Path]:
    rows = sorted(rows, key=lambda r: r.get("part", ""))
    buf = io.StringIO()
    w = csv.DictWriter(buf, COLUMNS, extrasaction="ignore", lineterminator="\n")
    w.writeheader()
    w.writerows(rows)
    csv_path = _write(out_root / "summary.csv", buf.getvalue())
    return csv_path, _write(out_root / "summary.html", _page(rows, out_root, wall_s, workers))


def _write(path: Path, text: str) -> Path:
    part = path.with_name(path.name + ".part")
    part.write_text(text, encoding="utf-8")
    os.replace(part, path)
    return path


def _page(rows: Sequence[dict], out_root: Path, wall_s: float, workers: int) -> str:
    ok = sum(r.get("state") in ("verified", "done before (skipped)") for r in rows)
    head = ("<tr><th>part</th><th>result</th><th>cycle</th><th>deepest gouge mm</th><th>most left mm</th>"
            "<th>planning s</th><th>peak MB</th><th>worker</th><th>files / reason</th></tr>")
    body = "\n".join(_row(r, out_root) for r in rows)
    return f"""<!doctype html>
<html><head><meta charset="utf-8"><title>TMM batch</title>
<style>body{{font-family:sans-serif;margin:1.5em}} table{{border-collapse:collapse}}
td,th{{border:1px solid #bbb;padding:4px 8px;text-align:left;vertical-align:top}}
.good{{background:#dfd}} .bad{{background:#fdd}} .skip{{background:#eef}}</style></head>
<body><h1>TMM batch</h1>
<p>{len(rows)} parts, {ok} verified, {len(rows) - ok} not; {workers} worker(s), {wall_s:.0f} s in all.</p>
<table>{head}
{body}
</table></body></html>
"""


def _row(r: dict, out_root: Path) -> str:
    state = r.get("state", "?")
    css = "good" if state == "verified" else "skip" if state.startswith("done before") else "bad"
    cycle = f"{r['cycle_s'] / 60:.1f} min" if isinstance(r.get("cycle_s"), (int, float)) else ""
    folder = Path(r.get("folder", ""))
    rel = os.path.relpath(folder, out_root) if r.get("folder") else ""
    if css == "bad":
        detail = html.escape(str(r.get("problems") or r.get("reason") or ""))
    else:
        detail = " ".join(f'<a href="{html.escape(rel)}/{html.escape(f)}">{html.escape(f)}</a>'
                          for f in r.get("files", []))
    cells = [html.escape(str(r.get("part", ""))), html.escape(state), cycle, _num(r.get("deepest_gouge_mm")),
             _num(r.get("most_left_mm")), _num(r.get("seconds")), _num(r.get("peak_mb")),
             html.escape(str(r.get("worker", ""))), detail]
    return f'<tr class="{css}">' + "".join(f"<td>{c}</td>" for c in cells) + "</tr>"


def _num(v) -> str:
    return f"{v:g}" if isinstance(v, (int, float)) else ""
