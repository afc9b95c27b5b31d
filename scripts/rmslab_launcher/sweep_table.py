"""A sweep's one result table (docs/sessions.md "Sweeps"): sweep.csv, a row
a cell, and sweep.html, the same table with a plot per varied key (the
share of cells that acquired and docked, and the docking time, against the
key's value), self-contained: Chart.js (Debian's libjs-chart.js) embedded."""
import csv
import html
import json
import os

from .common import replacing

CHART_JS = "/usr/share/javascript/chart.js/chart.min.js"

# (column, unit, how it is had from a cell's result)
OUTCOME_COLUMNS = [
    ("acquired", "", lambda r: r["outcome"]["acquired"]),
    ("docked", "", lambda r: r["outcome"]["docked"]),
    ("final_mode", "", lambda r: r["outcome"]["final_mode"]),
    ("acquired_at", "s", lambda r: r["outcome"]["reached_s"]["acquired"]),
    ("clear_of_bay_at", "s", lambda r: r["outcome"]["reached_s"]["clear_of_bay"]),
    ("docked_at", "s", lambda r: r["outcome"]["reached_s"]["docked"]),
    ("acquisition", "s", lambda r: (r["outcome"]["phase_durations_s"] or {}).get("acquisition")),
    ("extraction", "s", lambda r: (r["outcome"]["phase_durations_s"] or {}).get("extraction")),
    ("maneuvering", "s", lambda r: (r["outcome"]["phase_durations_s"] or {}).get("maneuvering")),
    ("docking", "s", lambda r: (r["outcome"]["phase_durations_s"] or {}).get("docking")),
    ("collisions", "", lambda r: r["outcome"]["collisions"]),
    ("held_frames", "", lambda r: r["outcome"]["held_frames"]),
    ("dock_distance", "ft", lambda r: (r["outcome"]["docking"] or {}).get("distance_ft")),
    ("dock_angle", "deg", lambda r: (r["outcome"]["docking"] or {}).get("angle_deg")),
    ("recorded_docked", "", lambda r: r["recorded_outcome"]["docked"]),
    ("first_divergence_frame", "", lambda r: (r["first_divergence"] or {}).get("frame")),
    ("first_divergence_at", "s", lambda r: (r["first_divergence"] or {}).get("time_s")),
    ("first_output_difference_at", "s", lambda r: (r.get("first_difference") or {}).get("time_s")),
    ("frames_identical", "", lambda r: r["frames_identical"]),
    ("frames_compared", "", lambda r: r["frames_compared"]),
    ("changes", "", lambda r: len(r["changes"])),
]


def cell_text(v, unit=""):
    """A cell as the CSV writes it: a time (unit s: session time, docs/sessions.md
    "Session time") at full precision, the shortest text that reads back as the
    same double; any other number to 9 significant digits."""
    if v is None:
        return ""
    if isinstance(v, bool):
        return "1" if v else "0"
    if isinstance(v, float):
        return repr(v) if unit == "s" else f"{v:.9g}"
    return str(v)


def changes_text(res):
    try:
        return "; ".join(f"{c['field']}: {cell_text(c['recorded']) or '-'} -> {cell_text(c['now']) or '-'}"
                         for c in res["changes"])
    except (KeyError, TypeError):
        return "(not readable)"


def header(grid):
    cols = ["cell", "session", "subject"] + [k for k, _ in grid] + ["status"]
    cols += [f"{n} [{u}]" if u else n for n, u, _ in OUTCOME_COLUMNS]
    return cols + ["what changed", "note", "error"]


def row_values(cell, res, grid):
    sets = dict(cell["sets"])
    row = [cell["index"], cell["session"], cell["subject"]] + [sets[k] for k, _ in grid]
    if res is None:
        return row + ["failed"] + [""] * len(OUTCOME_COLUMNS) + ["", "", cell.get("error", "")]
    row.append("ok")
    for _, unit, get in OUTCOME_COLUMNS:
        try:
            row.append(cell_text(get(res), unit))
        except (KeyError, TypeError, AttributeError):
            row.append("")
    return row + [changes_text(res), res.get("note", ""), ""]


def numeric(text):
    try:
        return float(text)
    except ValueError:
        return None


def plots(grid, rows):
    """Per varied key: for each value, the share of cells that acquired and
    docked and the mean docking time of those that docked."""
    out = []
    for key, values in grid:
        per = []
        for v in values:
            done = [res for c, res in rows if res is not None and dict(c["sets"])[key] == v]
            n = len(done)
            docked_at = [r["outcome"]["reached_s"].get("docked") for r in done if r["outcome"]["docked"]]
            docked_at = [t for t in docked_at if isinstance(t, (int, float)) and not isinstance(t, bool)]
            per.append({"value": v, "cells": n,
                        "acquired": sum(r["outcome"]["acquired"] for r in done) / n if n else None,
                        "docked": sum(r["outcome"]["docked"] for r in done) / n if n else None,
                        "docked_at": round(sum(docked_at) / len(docked_at), 3) if docked_at else None})
        out.append({"key": key, "numeric": all(numeric(v) is not None for v in values), "points": per})
    return out


def write(sweep_dir, grid, rows):
    """sweep.csv and sweep.html in sweep_dir; returns their paths."""
    cols = header(grid)
    table = [row_values(c, res, grid) for c, res in rows]
    csv_path = os.path.join(sweep_dir, "sweep.csv")
    with replacing(csv_path, newline="") as f:
        w = csv.writer(f, lineterminator="\n")
        w.writerow(cols)
        w.writerows(table)
    html_path = os.path.join(sweep_dir, "sweep.html")
    with replacing(html_path) as f:
        f.write(page(grid, cols, table, plots(grid, rows), rows))
    return csv_path, html_path


def page(grid, cols, table, plot_data, rows):
    try:
        with open(CHART_JS) as f:
            chart_js = f.read()
    except OSError:
        chart_js = ""  # the table stands alone; the plots say why they are missing
    ok = sum(1 for _, res in rows if res is not None)
    docked = sum(1 for _, res in rows if res is not None and res["outcome"]["docked"])
    e = html.escape
    h = ["<!DOCTYPE html><html><head><meta charset='utf-8'><title>rmslab sweep</title><style>",
         "body{font-family:sans-serif;margin:1em} table{border-collapse:collapse;font-size:12px}",
         "td,th{border:1px solid #bbb;padding:2px 5px} tr.failed{background:#fdd}",
         "td.yes{background:#dfd} td.no{background:#fee} .plot{width:480px;display:inline-block;margin:8px}",
         "</style></head><body>",
         f"<h1>Sweep: {len(rows)} cells</h1>",
         f"<p id='totals'>{ok} ran, {len(rows) - ok} failed; {docked} docked. Varied: "
         + ", ".join(f"<code>{e(k)}</code> = {e(', '.join(v))}" for k, v in grid) + "</p>",
         "<h2>Outcome against each varied key</h2>"]
    if not chart_js:
        h.append(f"<p>No plots: Chart.js is not at {e(CHART_JS)} (libjs-chart.js; scripts/install-deps).</p>")
    for i, _ in enumerate(plot_data):
        h.append(f"<div class='plot'><canvas id='plot{i}'></canvas></div>")
    h.append("<h2>Cells</h2><table id='cells'><tr>" + "".join(f"<th>{e(c)}</th>" for c in cols) + "</tr>")
    status_col = cols.index("status")
    for r in table:
        cls = " class='failed'" if r[status_col] == "failed" else ""
        cells = []
        for name, v in zip(cols, r):
            kind = ""
            if name in ("acquired", "docked") and v in ("0", "1"):
                kind = " class='yes'" if v == "1" else " class='no'"
            cells.append(f"<td{kind}>{e(str(v))}</td>")
        h.append(f"<tr{cls}>" + "".join(cells) + "</tr>")
    h.append("</table>")
    h.append(f"<script>{chart_js}</script>" if chart_js else "")
    # Inside <script>, the JSON's < > & written as \u escapes (the same
    # strings to JavaScript): no value, e.g. "<!--<script>", can end the
    # script or change how the HTML parser reads it.
    data = json.dumps(plot_data).replace("<", "\\u003c").replace(">", "\\u003e").replace("&", "\\u0026")
    h.append("<script>const plots = " + data + ";\n" + PLOT_JS + "</script>")
    h.append("</body></html>\n")
    return "\n".join(h)


PLOT_JS = """
if (typeof Chart !== 'undefined') plots.forEach((p, i) => {
  const labels = p.points.map(q => q.value);
  new Chart(document.getElementById('plot' + i), {
    type: 'line',
    data: {labels, datasets: [
      {label: 'acquired (share)', data: p.points.map(q => q.acquired), yAxisID: 'share'},
      {label: 'docked (share)', data: p.points.map(q => q.docked), yAxisID: 'share'},
      {label: 'docked at (s; mean of the cells that docked)', data: p.points.map(q => q.docked_at), yAxisID: 'time',
       borderDash: [4, 4]}]},
    options: {animation: false, plugins: {title: {display: true, text: p.key}},
      scales: {share: {type: 'linear', min: 0, max: 1, position: 'left',
                       title: {display: true, text: 'share of cells'}},
               time: {type: 'linear', position: 'right', title: {display: true, text: 's'}},
               x: {title: {display: true, text: p.key}}}}
  });
  document.getElementById('plot' + i).dataset.drawn = '1';
});
"""
