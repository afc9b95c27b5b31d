"""scripts/lab study report: a study's trials as one tidy table and one page
(docs/studies.md "The report").

The table has a row an attempt of every trial counted (the run that was
done; lost runs are not in it): the study's columns (study, subject,
condition, trial, trial_kind, run, session, result) and every figure of the
attempt's scorecard as `scripts/lab compare` gives it (rms_compare, the one
reader of the sessions' summaries). It is written as study.csv and as
study.jsonl (one JSON object a row: pandas.read_json(path, lines=True)).
The statistics and the page come from the table alone (study_stats.py,
run with Debian's python3 for pandas, scipy and statsmodels).
"""
import argparse
import csv
import json
import os
import shutil
import subprocess
import sys
import tempfile

from .common import LabError, binary, read_folder_json, replacing, require_built, run_statistics, say
from .study import StudyFolder, build, progress
from .study_file import StudyFile

STUDY_COLUMNS = ["study", "subject", "condition", "trial", "trial_kind", "run", "session", "result", "docked",
                 "duration_s"]
DROPPED = {"session", "subject", "note", "kind", "started_utc", "resimulation_of"}  # compare's, said above
NUMERIC_TEXT = {"trial", "run", "result", "docked"}


def csv_field(v):
    """A cell a spreadsheet shows as text (as rms::CsvField): text that
    would start a formula gets a leading quote."""
    if isinstance(v, str) and v[:1] in ("=", "+", "-", "@", "\t", "\r"):
        return "'" + v
    return v


def counted_runs(folder, study):
    """[(subject, trial plan entry, session path)] of every trial done, in
    each subject's order; and how many runs were lost."""
    plan, out, lost = study.plan(), [], 0
    for subject, trials in plan.items():
        rows, _ = progress(folder, subject, trials)
        for t in rows:
            lost += t["lost"]
            done = next((r for r in t["runs"] if r["status"] == "done"), None)
            if done is None:
                continue
            if not os.path.isfile(os.path.join(folder.dir, done["session"], "summary.json")):
                say(f"{subject}'s trial {t['trial']}: its session {done['session']} is missing (or has no "
                    f"summary.json): left out of the report")
                continue
            out.append((subject, t, done))
    return out, lost


def number(text):
    if text == "" or text is None:
        return None
    try:
        v = float(text)
    except ValueError:
        return text
    return int(v) if v.is_integer() and "." not in text and "e" not in text.lower() else v


def rows_of(folder, study, runs):
    sessions = [os.path.join(folder.dir, r["session"]) for _, _, r in runs]
    with tempfile.TemporaryDirectory(prefix="rmslab-study-report-") as tmp:
        r = subprocess.run([binary("tools/rms_compare"), *sessions, "--out", tmp], capture_output=True, text=True)
        if r.returncode != 0:
            raise LabError(f"rms_compare refused the study's sessions: {r.stderr.strip()}", 1)
        with open(os.path.join(tmp, "compare.csv"), newline="") as f:
            compare = list(csv.DictReader(f))
        html = os.path.join(tmp, "compare.html")
        compare_html = open(html, encoding="utf-8").read() if os.path.exists(html) else None
    by_session = {}
    for row in compare:
        by_session.setdefault((row["subject"], row["session"]), []).append(row)
    rows = []
    for subject, t, run in runs:
        path = os.path.join(folder.dir, run["session"])
        summary = read_folder_json(os.path.join(path, "summary.json"))
        attempts = by_session.get((subject, os.path.basename(path)), [])
        if not attempts:
            raise LabError(f"{path}: rms_compare gave no attempt of it", 1)
        for a in attempts:
            row = {"study": study.name, "subject": subject, "condition": t["condition"], "trial": t["trial"],
                   "trial_kind": t["kind"], "run": run.get("run"), "session": run["session"],
                   "result": int(number(a["attempt"]) == summary.get("result_attempt")),
                   "docked": int(a.get("outcome") == "docked"), "duration_s": summary.get("duration_s")}
            for k, v in a.items():
                if k not in DROPPED:
                    row[k] = number(v)
            rows.append(row)
    return rows, compare_html


def write_table(rows, out):
    columns = list(dict.fromkeys(STUDY_COLUMNS + [k for r in rows for k in r]))
    with replacing(os.path.join(out, "study.csv"), newline="", encoding="utf-8") as f:
        w = csv.writer(f)
        w.writerow(columns)
        for r in rows:
            w.writerow(["" if r.get(c) is None else csv_field(r.get(c)) for c in columns])
    with replacing(os.path.join(out, "study.jsonl"), encoding="utf-8") as f:
        for r in rows:
            f.write(json.dumps({c: r.get(c) for c in columns}) + "\n")


def run(argv):
    p = argparse.ArgumentParser(prog="scripts/lab study report", description="One tidy table (study.csv, "
                                "study.jsonl) and one page (study.html: per-condition means with 95 % "
                                "intervals, learning curves, a mixed-effects comparison of the conditions).")
    p.add_argument("study")
    p.add_argument("--dir", help="the study's folder (default sessions/studies/NAME)")
    p.add_argument("--out", help="where the report goes (default the study's folder, report/)")
    p.add_argument("--no-build", action="store_true")
    a = p.parse_args(argv)
    study = StudyFile(a.study)
    build(a.no_build)
    require_built("tools/rms_compare")
    folder = StudyFolder(study, a.dir)
    folder.open(create=False)
    runs, lost = counted_runs(folder, study)
    if not runs:
        raise LabError(f"no trial of study '{study.name}' is done yet: nothing to report "
                       f"(scripts/lab study status {a.study})", 1)
    out = os.path.abspath(a.out or os.path.join(folder.dir, "report"))
    os.makedirs(out, exist_ok=True)
    rows, compare_html = rows_of(folder, study, runs)
    write_table(rows, out)
    if compare_html:
        with replacing(os.path.join(out, "compare.html"), encoding="utf-8") as f:
            f.write(compare_html)
    r = run_statistics("study_stats", os.path.join(out, "study.csv"), out,
                       "--title", f"Study {study.name}" + (f": {study.description}" if study.description else ""),
                       "--conditions", ",".join(c["name"] for c in study.conditions), "--lost", str(lost))
    if r.returncode != 0:
        raise LabError(f"the study's statistics failed: {(r.stderr or r.stdout).strip()}", 1)
    measured = sum(1 for x in rows if x["result"] and x["trial_kind"] == "measured")
    say(f"study '{study.name}': {len(runs)} trials ({measured} measured), {len(rows)} attempts; {lost} lost runs "
        f"not counted")
    say(f"  {out}/study.csv, study.jsonl (one row an attempt), study.html (the conditions compared), stats.json, "
        f"compare.html (the scorecards side by side)")
    if shutil.which("xdg-open") and os.environ.get("DISPLAY") and sys.stdout.isatty():
        say(f"  open {out}/study.html in a browser")
    return 0
