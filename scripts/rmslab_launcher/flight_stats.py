"""A closed-loop sweep's table (docs/studies.md "Designs judged by flying
them"): from DIR/flights.csv and DIR/sweep.json, DIR/designs.csv and
DIR/designs.json, one row a design, and the table printed. Run with
Debian's python3 (scipy): python3 -m rmslab_launcher.flight_stats DIR.
The intervals are study_stats's: Wilson's for the share docked, Student's
t for a mean.
"""
import collections
import csv
import itertools
import json
import os
import sys

from .study_stats import clean, t_interval, wilson

FIGURES = [("acquired_s", "time to acquire, s"), ("docked_s", "time to dock, s"),
           ("distance_margin_ft", "docking distance margin, ft"), ("angle_margin_deg", "docking angle margin, deg"),
           ("collision_events", "collisions"), ("key_actions", "keys pressed")]


COUNTS = {"collision_events", "key_actions"}


def number(v):
    try:
        return float(v) if v != "" else None
    except ValueError:
        return None


def summarize(meta, flights):
    """A row a design and kind of subject (in the sweep's order), of the
    flights it has (a cell without a result: fewer runs than asked)."""
    out = []
    for (i, d), subject in itertools.product(enumerate(meta["designs"], 1),
                                             meta.get("subjects") or ["autopilot"]):
        fl = [f for f in flights if int(f["design"]) == i and f.get("subject", "autopilot") == subject]
        if not fl:
            continue
        docked = sum(f["docked"] == "True" for f in fl)
        p, lo, hi = wilson(docked, len(fl))
        row = {"design": i, **d, "subject": subject, "runs": len(fl), "docked": docked, "docked_rate": p,
               "docked_low": lo, "docked_high": hi}
        for key, _ in FIGURES:
            s = t_interval([x for x in (number(f[key]) for f in fl) if x is not None])
            if key in COUNTS and s["low"] is not None:
                s["low"] = max(0.0, s["low"])  # a count's interval is cut at 0
            row.update({f"{key}_n": s["n"], f"{key}_mean": s["mean"], f"{key}_low": s["low"], f"{key}_high": s["high"]})
        failures = collections.Counter(f["failure"] for f in fl if f["failure"])
        row["failures"] = "; ".join(f"{n} x {why}" for why, n in failures.most_common())
        out.append(row)
    return out


def fmt(v, digits=3):
    return "-" if v is None else f"{v:.{digits}g}"


def main(argv):
    folder = argv[0]
    meta = json.load(open(os.path.join(folder, "sweep.json")))
    with open(os.path.join(folder, "flights.csv"), newline="") as f:
        flights = list(csv.DictReader(f))
    rows = summarize(meta, flights)
    cols = list(rows[0].keys()) if rows else []
    with open(os.path.join(folder, "designs.csv"), "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(cols)
        for r in rows:
            w.writerow(["" if r[c] is None else r[c] for c in cols])
    with open(os.path.join(folder, "designs.json"), "w") as f:
        json.dump(clean({"sweep": meta, "designs": rows}), f, indent=1, allow_nan=False)
    for r in rows:
        design = ", ".join(f"{k} = {r[k]}" for k in meta["keys"])
        print(f"design {r['design']} ({design}), {r['subject']}: docked {r['docked']} of {r['runs']} "
              f"({100 * r['docked_rate']:.0f} %; "
              f"95 % CI {100 * r['docked_low']:.0f} to {100 * r['docked_high']:.0f} %)")
        for key, what in FIGURES:
            if r[f"{key}_n"]:
                print(f"    {what}: {fmt(r[f'{key}_mean'])} (95 % CI {fmt(r[f'{key}_low'])} to "
                      f"{fmt(r[f'{key}_high'])}, n {r[f'{key}_n']})")
        if r["failures"]:
            print(f"    not docked: {r['failures']}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
