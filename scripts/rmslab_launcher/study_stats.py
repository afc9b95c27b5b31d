"""A study's statistics and page (docs/studies.md "The report"), from its
tidy table alone: per-condition means with 95 % confidence intervals, each
subject's learning curve, and a linear mixed-effects comparison of the
conditions with the subject as a random effect.

Run with Debian's python3, which has python3-pandas, -scipy and
-statsmodels (scripts/install-deps):

    python3 -m rmslab_launcher.study_stats STUDY.csv OUTDIR [--title TEXT]

writes OUTDIR/stats.json and OUTDIR/study.html. The methods, named on the
page:
- a proportion (docked): Wilson's score interval;
- a mean: Student's t interval, mean +- t(0.975, n-1) s / sqrt(n);
- conditions compared: statsmodels MixedLM (REML), METRIC ~ C(condition)
  with the first condition as the reference and a random intercept for
  each subject; each other condition's coefficient (its difference from
  the reference), its 95 % Wald interval and p-value.
The unit is a trial: each measured trial's result attempt (its last that
docked, or else its last), as scripts/lab compare takes it.
"""
import argparse
import html
import json
import math
import os
import sys
import warnings

METRICS = [  # (column, what, unit, only docked trials)
    ("task_time_s", "task time (docked trials)", "s", True),
    ("collisions", "collisions", "", False),
    ("actions", "key actions", "", False),
]
PALETTE = ["#1f77b4", "#d62728", "#2ca02c", "#9467bd", "#ff7f0e", "#8c564b", "#e377c2", "#17becf"]


def wilson(k, n, z=1.959963984540054):
    if n == 0:
        return None, None, None
    p = k / n
    d = 1 + z * z / n
    centre = (p + z * z / (2 * n)) / d
    half = z * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / d
    return p, max(0.0, centre - half), min(1.0, centre + half)


def t_interval(values):
    from scipy import stats
    n = len(values)
    if n == 0:
        return {"n": 0, "mean": None, "low": None, "high": None, "sd": None}
    mean = sum(values) / n
    if n == 1:
        return {"n": 1, "mean": mean, "low": None, "high": None, "sd": None}
    sd = math.sqrt(sum((v - mean) ** 2 for v in values) / (n - 1))
    half = stats.t.ppf(0.975, n - 1) * sd / math.sqrt(n)
    return {"n": n, "mean": mean, "low": mean - half, "high": mean + half, "sd": sd}


def mixed_model(df, column, conditions):
    """METRIC ~ C(condition) + (1 | subject), REML; None and why when it
    cannot be fit (too few trials, one subject, no variance)."""
    import statsmodels.formula.api as smf
    d = df[[column, "condition", "subject"]].dropna()
    present = [c for c in conditions if c in set(d["condition"])]
    if len(present) < 2:
        return {"fitted": False, "why": "fewer than two conditions have trials with this figure"}
    if d["subject"].nunique() < 2:
        return {"fitted": False, "why": "fewer than two subjects have trials with this figure"}
    if len(d) <= len(present) + 1:
        return {"fitted": False, "why": f"{len(d)} trials: too few for {len(present)} conditions and the subjects"}
    if d[column].nunique() < 2:
        return {"fitted": False, "why": "every trial has the same value"}
    ref = present[0]
    formula = f"Q('{column}') ~ C(condition, Treatment(reference={ref!r}))"
    try:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            fit = smf.mixedlm(formula, d, groups=d["subject"]).fit(reml=True)
    except Exception as e:  # singular matrices and the like: said, not raised
        return {"fitted": False, "why": f"the model could not be fit ({type(e).__name__}: {e})"}
    ci = fit.conf_int()
    if not all(math.isfinite(float(v)) for v in list(ci.values.ravel()) + list(fit.pvalues.values)):
        # A degenerate fit (every trial of a condition alike: a dry run's
        # deterministic autopilot) has no intervals: said, not shown as figures.
        return {"fitted": False, "why": "the model's intervals are undefined (no variation left within the "
                                        "conditions once each subject's level is taken out)"}
    out = {"fitted": True, "reference": ref, "trials": int(len(d)), "subjects": int(d["subject"].nunique()),
           "converged": bool(getattr(fit, "converged", True)),
           "warnings": sorted({str(w.message).splitlines()[0] for w in caught}),
           "subject_variance": float(fit.cov_re.iloc[0, 0]) if fit.cov_re.size else None,
           "residual_variance": float(fit.scale), "differences": []}
    for c in present[1:]:
        name = f"C(condition, Treatment(reference={ref!r}))[T.{c}]"
        if name not in fit.params.index:
            continue
        out["differences"].append({"condition": c, "estimate": float(fit.params[name]),
                                   "low": float(ci.loc[name, 0]), "high": float(ci.loc[name, 1]),
                                   "p": float(fit.pvalues[name])})
    return out


def compute(df, conditions):
    """stats.json's content from the tidy table (a pandas DataFrame)."""
    trials = df[(df["trial_kind"] == "measured") & (df["result"] == 1)].copy()
    out = {"unit": "measured trial (its result attempt)", "trials": int(len(trials)),
           "subjects": sorted(map(str, trials["subject"].unique())), "conditions": {}, "models": {}}
    for c in conditions:
        t = trials[trials["condition"] == c]
        p, lo, hi = wilson(int(t["docked"].sum()), len(t))
        row = {"trials": int(len(t)), "docked": int(t["docked"].sum()),
               "docked_rate": {"p": p, "low": lo, "high": hi}}
        for col, _, _, docked_only in METRICS:
            v = t[t["docked"] == 1][col] if docked_only else t[col]
            row[col] = t_interval([float(x) for x in v.dropna()])
            if col != "task_time_s" and row[col]["low"] is not None:
                row[col]["low"] = max(0.0, row[col]["low"])  # a count's interval is cut at 0
        out["conditions"][c] = row
    for col, _, _, docked_only in METRICS:
        d = trials[trials["docked"] == 1] if docked_only else trials
        out["models"][col] = mixed_model(d, col, conditions)
    return out


def fmt(v, unit="", digits=3):
    if v is None or (isinstance(v, float) and math.isnan(v)):
        return "-"
    text = f"{v:.{digits}g}" if abs(v) < 1000 else f"{v:.0f}"
    return f"{text} {unit}".strip()


def page(stats, df, conditions, title):
    e = html.escape
    rows = []
    for c in conditions:
        s = stats["conditions"][c]
        r = s["docked_rate"]
        share = "-" if r["p"] is None else (
            f"{s['docked']} of {s['trials']} ({100 * r['p']:.0f} %; {100 * r['low']:.0f} to {100 * r['high']:.0f} %)")
        cells = [e(c), str(s["trials"]), share]
        for col, _, unit, _ in METRICS:
            m = s[col]
            cells.append("-" if m["mean"] is None else fmt(m["mean"], unit) + (
                "" if m["low"] is None else f" ({fmt(m['low'])} to {fmt(m['high'])}, n {m['n']})"))
        rows.append("<tr>" + "".join(f"<td>{x}</td>" for x in cells) + "</tr>")
    head = "".join(f"<th>{e(x)}</th>" for x in ["condition", "measured trials", "docked (95 % CI)"] +
                   [f"{w} (95 % CI)" for _, w, _, _ in METRICS])
    verdicts = []
    for col, what, unit, _ in METRICS:
        m = stats["models"][col]
        if not m["fitted"]:
            verdicts.append(f"<li><b>{e(what)}</b>: no model: {e(m['why'])}.</li>")
            continue
        for d in m["differences"]:
            if d["low"] > 0:
                sure = f"higher with {e(d['condition'])}: the 95 % interval lies above 0"
            elif d["high"] < 0:
                sure = f"lower with {e(d['condition'])}: the 95 % interval lies below 0"
            else:
                sure = "not shown to differ: the 95 % interval includes 0"
            verdicts.append(
                f"<li><b>{e(what)}</b>: {e(d['condition'])} minus {e(m['reference'])}: "
                f"{fmt(d['estimate'], unit)} (95 % CI {fmt(d['low'])} to {fmt(d['high'])}; p = {d['p']:.3g}): "
                f"{sure}{'' if m['converged'] else '. The fit did not converge: read it with care'}"
                + (f"<br><small>the fit warned: {e('; '.join(m['warnings']))}</small>" if m["warnings"] else "")
                + "</li>")
    return f"""<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8"><title>{e(title)}</title>
<style>body{{font-family:sans-serif;margin:2em;max-width:72em}}table{{border-collapse:collapse}}
td,th{{border:1px solid #999;padding:.3em .6em;text-align:left}}figure{{display:inline-block;margin:1em}}</style>
</head><body><main>
<h1>{e(title)}</h1>
<p>{stats['trials']} measured trials of {len(stats['subjects'])} subjects; the unit is a trial, its result
attempt (its last that docked, or else its last). Practice trials are in the table, not in these figures.
{stats['lost_runs']} runs were lost for a technical reason and flown again: not counted.</p>
<h2>By condition</h2>
<table><thead><tr>{head}</tr></thead><tbody>{''.join(rows)}</tbody></table>
<h2>Conditions compared</h2>
<ul>{''.join(verdicts)}</ul>
<p>Method: a linear mixed-effects model (statsmodels MixedLM, REML) of each figure on the condition, the
first condition ({e(conditions[0])}) the reference, with a random intercept for each subject; each
difference with its 95 % Wald interval and p-value. The docked share's interval is Wilson's; a mean's,
Student's t. Task time counts docked trials only.</p>
<h2>Learning curves</h2>
<p>Each subject's task time (docked) or session time (not docked, hollow) by trial, coloured by
condition; practice trials included.</p>
{curves(df, conditions)}
</main></body></html>
"""


def curves(df, conditions):
    e = html.escape
    figs = []
    colour = {c: PALETTE[i % len(PALETTE)] for i, c in enumerate(conditions)}
    res = df[df["result"] == 1]
    top = max([float(v) for v in res["task_time_s"].dropna()] + [float(v) for v in res["duration_s"].dropna()] +
              [1.0])
    last = max([int(v) for v in res["trial"]] + [1])
    w, h, m = 320, 180, 30
    for subject in sorted(map(str, res["subject"].unique())):
        t = res[res["subject"].astype(str) == subject].sort_values("trial")
        marks = []
        for _, r in t.iterrows():
            docked = int(r["docked"]) == 1
            y_v = r["task_time_s"] if docked else r["duration_s"]
            if y_v is None or (isinstance(y_v, float) and math.isnan(y_v)):
                continue
            x = m + (int(r["trial"]) - 1) * (w - 2 * m) / max(1, last - 1)
            y = h - m - float(y_v) / top * (h - 2 * m)
            c = colour.get(r["condition"], "#000")
            marks.append(f'<circle cx="{x:.1f}" cy="{y:.1f}" r="4" stroke="{c}" stroke-width="2" '
                         f'fill="{c if docked else "white"}"><title>trial {int(r["trial"])}, {e(str(r["condition"]))}'
                         f' ({e(str(r["trial_kind"]))}): {fmt(float(y_v), "s")}</title></circle>')
        figs.append(
            f'<figure><svg width="{w}" height="{h}" role="img" aria-label="learning curve of {e(subject)}">'
            f'<line x1="{m}" y1="{h - m}" x2="{w - m}" y2="{h - m}" stroke="#000"/>'
            f'<line x1="{m}" y1="{m}" x2="{m}" y2="{h - m}" stroke="#000"/>'
            f'<text x="{m}" y="{m - 8}" font-size="11">{fmt(top, "s")}</text>'
            f'<text x="{w - m}" y="{h - 8}" font-size="11" text-anchor="end">trial {last}</text>'
            + "".join(marks) + f"</svg><figcaption>{e(subject)}</figcaption></figure>")
    legend = " ".join(f'<span style="color:{colour[c]}">&#9679; {e(c)}</span>' for c in conditions)
    return f"<p>{legend}</p>" + "".join(figs)


def write(path, text):
    """Whole or not at all: a temporary file renamed over path."""
    tmp = f"{path}.{os.getpid()}.tmp"
    with open(tmp, "w", encoding="utf-8") as f:
        f.write(text)
    os.replace(tmp, path)


def clean(v):
    """NaN and infinities (a singular fit's p-value) as null: JSON has none."""
    if isinstance(v, float) and not math.isfinite(v):
        return None
    if isinstance(v, dict):
        return {k: clean(x) for k, x in v.items()}
    if isinstance(v, list):
        return [clean(x) for x in v]
    return v


def main(argv):
    p = argparse.ArgumentParser(prog="study_stats")
    p.add_argument("table")
    p.add_argument("out")
    p.add_argument("--title", default="Study")
    p.add_argument("--conditions", help="the conditions in the study file's order, comma-separated")
    p.add_argument("--lost", type=int, default=0, help="runs lost and flown again (not in the table)")
    a = p.parse_args(argv)
    try:
        import pandas as pd
    except ImportError:
        print("study_stats: needs pandas, scipy and statsmodels (Debian's python3-pandas, python3-scipy, "
              "python3-statsmodels: scripts/install-deps)", file=sys.stderr)
        return 2
    # Names stay text ("01" is not "1", "NA" is a name): only an empty cell is missing.
    df = pd.read_csv(a.table, keep_default_na=False, na_values=[""],
                     dtype={"study": str, "subject": str, "condition": str, "trial_kind": str, "outcome": str})
    conditions = a.conditions.split(",") if a.conditions else list(dict.fromkeys(df["condition"]))
    stats = compute(df, conditions)
    stats["lost_runs"] = a.lost
    stats["methods"] = {"proportion": "Wilson score interval, 95 %", "mean": "Student's t interval, 95 %",
                        "comparison": "linear mixed-effects model (statsmodels MixedLM, REML): figure ~ "
                                      "C(condition), first condition the reference, random intercept per "
                                      "subject; 95 % Wald intervals"}
    os.makedirs(a.out, exist_ok=True)
    stats = clean(stats)
    text = page(stats, df, conditions, a.title)  # made whole before anything is written
    write(os.path.join(a.out, "stats.json"), json.dumps(stats, indent=1, allow_nan=False, default=str))
    write(os.path.join(a.out, "study.html"), text)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
