"""The planner's page for people: report.html, built from the report (core.plan.launch's report.json dict) and its
pictures. The verdict, the numbers the verification found, the setup sheet (stock, zero point, tools with their
holders and stick-outs, the ops with their times), every decision with its reason, the heat map and the tool path.

One self-contained file (the pictures embedded as data URIs, so it can be mailed or printed alone), all text
escaped, nothing that changes from run to run (no dates): the same report and pictures give the same bytes.
"""
from __future__ import annotations

import base64
from html import escape
from typing import Any, Iterable, Mapping, Optional, Sequence

STYLE = """
body{font-family:sans-serif;margin:1.5em auto;max-width:70em;color:#222}
h1{font-size:1.5em}h2{font-size:1.2em;margin-top:1.6em;border-bottom:1px solid #ccc}
table{border-collapse:collapse;margin:.5em 0}td,th{border:1px solid #ccc;padding:.25em .6em;text-align:left;
vertical-align:top}th{background:#f2f2f2}td.n{text-align:right;font-variant-numeric:tabular-nums}
.verdict{font-size:1.3em;font-weight:bold;padding:.4em .8em;display:inline-block}
.passed{background:#d9f2d9;color:#165016}.failed{background:#f8d7d7;color:#7a1212}
img{max-width:100%;border:1px solid #ddd}figure{margin:1em 0}figcaption{color:#555}
@media print{h2{page-break-after:avoid}figure{page-break-inside:avoid}}
"""


def minutes(seconds: float) -> str:
    """1:07 for 67 s (the machinist's clock), with the seconds for sums."""
    s = round(seconds)
    return f"{s // 60}:{s % 60:02d} ({seconds:g} s)"


def mm(value: Any) -> str:
    return "-" if value is None else f"{value:g} mm"


def table(head: Sequence[str], rows: Iterable[Sequence[Any]], numeric: Sequence[int] = ()) -> str:
    """An HTML table, every cell escaped; the columns in `numeric` right-aligned; no head row without `head`."""
    out = ["<table>" + ("<tr>" + "".join(f"<th>{escape(h)}</th>" for h in head) + "</tr>" if head else "")]
    for row in rows:
        cells = (f'<td class="n">{escape(str(c))}</td>' if i in numeric else f"<td>{escape(str(c))}</td>"
                 for i, c in enumerate(row))
        out.append("<tr>" + "".join(cells) + "</tr>")
    return "\n".join(out) + "</table>"


def pairs(rows: Iterable[tuple[str, Any]]) -> str:
    """A table of names and values."""
    return table((), rows)


def summary(report: Mapping) -> str:
    v = report["verification"]
    state = "passed" if report["passed"] else "failed"
    words = "VERIFIED" if report["passed"] else "VERIFICATION FAILED"
    parts = [f'<p class="verdict {state}">{words}</p>']
    if report["problems"]:
        parts.append("<ul>" + "".join(f"<li>{escape(p)}</li>" for p in report["problems"]) + "</ul>")
    pct = ", ".join(f"{k} %: {val:g} mm" for k, val in v.get("left_percentiles_mm", {}).items())
    rows = [("deepest gouge", f"{mm(v['deepest_gouge_mm'])} (tolerance {mm(report['finish']['tolerance_mm'])})"),
            ("most material left", mm(v["most_material_left_mm"])),
            ("material left, percentiles", pct or "-"),
            ("volume removed", f"{v['removed_volume_mm3']:g} mm3"),
            ("volume left above the model", f"{v['remaining_volume_mm3']:g} mm3"),
            ("cycle time", minutes(v["cycle_seconds"])),
            ("finish asked", f"cusp {mm(report['finish']['cusp_mm'])}"),
            ("verified on a grid of", mm(v.get("sim_cell_mm")))]
    rows += [("plan changed", change) for change in v.get("replanned", [])]
    reach = v.get("left_in_reach")
    if reach:
        rows.append((f"left where {reach['tool']} reaches (along the normal)",
                     f"{reach['left_above_tolerance_mm2']:g} mm2 above the tolerance"
                     + (f" ({reach['left_above_allowance_mm2']:g} mm2 above the cusp asked, "
                        f"{mm(reach['allowance_mm'])})"
                        if reach.get("allowance_mm", 0) > report["finish"]["tolerance_mm"] else "")
                     + f", most {mm(reach['most_left_mm'])}"
                     f", 99 %: {mm(reach['left_99_percentile_mm'])}; out of its reach from above: "
                     f"{reach['out_of_reach_mm2']:g} mm2 of {reach['reached_mm2'] + reach['out_of_reach_mm2']:g}"))
    return "\n".join(parts) + pairs(rows)


def machine(m: Mapping) -> str:
    """The setup sheet's machine: its type (the Tarus with its tilt limit), post, travels and rapids."""
    rapid = m.get("rapid_mm_min")
    kind = (f"Tarus 5-axis (tarus5), the tool at most {m['tilt_limit_deg']:g} deg from the surface normal, "
            if m.get("type") == "tarus5" else "")
    travels = "not checked (the post checks the joints)" if m.get("type") == "tarus5" and \
        min(m["travels_mm"]) >= 1e4 else " x ".join(f"{t:g}" for t in m["travels_mm"]) + " mm"
    return (f"{kind}{m['post']} post, travels {travels}"
            + (f", rapids XY {rapid[0]:g} Z {rapid[1]:g} mm/min" if rapid else ""))


def tool_numbers(report: Mapping) -> dict[str, int]:
    """The library tools' numbers in the G-code: T1, T2, ... in the order the ops first use them."""
    numbers: dict[str, int] = {}
    for op in report["plan"]["ops"]:
        numbers.setdefault(op["tool"], len(numbers) + 1)
    return numbers


def setup_sheet(report: Mapping) -> str:
    box = report["plan"]["stock_box_mm"]
    lo, hi = box[:3], box[3:]
    size = " x ".join(f"{b - a:.2f}" for a, b in zip(lo, hi))
    shape = report["stock"]["describe"] if "stock" in report else f"box {size} mm"
    stock = pairs([("stock", f"{shape} (X x Y x Z over all: {size} mm)"),
                   ("material", report["material"].replace("_", " ")),
                   ("stock corner (lowest X, Y, Z)", "X{:g} Y{:g} Z{:g}".format(*lo)),
                   ("stock top", f"Z{hi[2]:g}"),
                   ("zero point (G54)", "the model's origin: X0 Y0 Z0 of the model file as placed (the stock's "
                    f"top is Z{hi[2]:g}, its lowest corner X{lo[0]:g} Y{lo[1]:g})"),
                   ("machine", machine(report["machine"]))]
                  + [("note", n) for n in report.get("notes", [])])
    numbers = tool_numbers(report)
    cutting = report["plan"]["tools"]
    tools = []
    for t in sorted(report.get("tools", []), key=lambda t: numbers.get(t["name"], len(numbers) + 1)):
        if t["name"] not in numbers:
            continue
        c = cutting.get(t["name"], {})
        shape = t["type"] + (f" r{t['corner_radius']:g}" if t["type"] == "bull" else "")
        tools.append((f"T{numbers[t['name']]}", t["name"], shape, f"{t['diameter']:g}", t["flutes"],
                      f"{t['flute_length']:g}", f"{t['stick_out_mm']:g}", t["holder"] or "none (not checked)",
                      c.get("rpm", "-"), c.get("feed_mm_min", "-")))
    tool_table = table(("T", "tool", "type", "D mm", "flutes", "flute length mm", "stick-out mm", "holder", "rpm",
                        "feed mm/min"), tools, numeric=(3, 4, 5, 6, 8, 9))
    verified = {o["label"]: o for o in report["verification"]["ops"]}
    ops = []
    for i, op in enumerate(report["plan"]["ops"], 1):
        v = verified.get(op["label"])
        time = minutes(v["cycle_seconds"]) if v else "left out"
        ops.append((i, op["label"], f"T{numbers[op['tool']]}", time, v["moves"] if v else "-",
                    (v["rapids_through_stock"] if v else "-")))
    op_table = table(("#", "op", "tool", "cycle time m:ss", "moves", "rapids through stock"), ops, numeric=(0, 4, 5))
    total = f"<p>Whole Job: {escape(minutes(report['verification']['cycle_seconds']))}</p>"
    return stock + "<h3>Tools</h3>" + tool_table + "<h3>Operations</h3>" + op_table + total


def decisions(report: Mapping) -> str:
    rows = [(d["topic"], d["choice"], d["reason"]) for d in report["plan"]["decisions"]]
    return table(("decision", "choice", "reason"), rows)


def analysis(report: Mapping) -> str:
    a = report["analysis"]
    shares = table(("slope deg", "share of the surface"),
                   ((band, f"{share * 100:.1f} %") for band, share in a["slope_area_share"].items()), numeric=(1,))
    rows = [("size", " x ".join(f"{s:g}" for s in a["size_mm"]) + " mm"), ("triangles", a["triangles"]),
            ("surface", f"{a['surface_area_mm2']:g} mm2"), ("flat (under 1 deg)", f"{a['flat_share'] * 100:.1f} %"),
            ("steep (over 60 deg)", f"{a['steep_share'] * 100:.1f} %"),
            ("facing down", f"{a['facing_down_share'] * 100:.1f} %")]
    return pairs(rows) + shares


def figure(png: Optional[bytes], caption: str) -> str:
    if not png:
        return f"<p>{escape(caption)}: not drawn.</p>"
    data = base64.b64encode(png).decode("ascii")
    return (f'<figure><img alt="{escape(caption)}" src="data:image/png;base64,{data}">'
            f"<figcaption>{escape(caption)}</figcaption></figure>")


def report_html(report: Mapping, name: str, heat_map: Optional[bytes] = None,
                toolpath: Optional[bytes] = None) -> str:
    """The page for `report` (a part called `name`), the PNG bytes of its heat map and tool path embedded."""
    title = f"TMM plan: {name}"
    body = [f"<h1>{escape(title)}</h1>", f"<p>From the job file {escape(report['job_file'])}.</p>",
            summary(report), "<h2>Setup sheet</h2>", setup_sheet(report),
            "<h2>Decisions</h2>", decisions(report),
            "<h2>Pictures</h2>",
            figure(heat_map, "the simulated part against the model: material left (above) and gouges (below)"),
            figure(toolpath, "the tool path of the whole Job, read back from the G-code"),
            "<h2>The model</h2>", analysis(report),
            "<h2>Files</h2><ul>" + "".join(f"<li>{escape(f)}</li>" for f in report["files"]) + "</ul>"]
    return ("<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">"
            f"<title>{escape(title)}</title><style>{STYLE}</style></head><body>\n"
            + "\n".join(body) + "\n</body></html>\n")
