"""scripts/lab sweep --closed-loop: designs judged by flying them
(docs/studies.md "Designs judged by flying them").

Each design -- every combination of the --vary values over the
configuration -- is flown from the start by --runs virtual subjects
(rms_fly: the autopilot with a reaction time, a rate gain and a tremor
drawn for each run from --seed), in closed loop with the real DCP and no
network, on this machine's cores. One table a design: the share docked
with its interval, the times to acquire and to dock, the docking margins,
collisions, and why the others failed (flight_stats.py, with Debian's
python3 for scipy). Without --closed-loop, `scripts/lab sweep SESSION...`
replays recorded inputs: the same inputs under another design.
"""
import argparse
import csv
import itertools
import json
import os
import subprocess
import time

from .common import ROOT, LabError, binary, install_and_build, replacing, require_built, run_statistics, say
from .sweep import parse_vary

FLIGHT_COLUMNS = ["design", "run", "seed", "reaction_s", "latency_frames", "rate_gain", "docked", "failure", "time_s",
                  "acquired_s", "cleared_s", "docked_s", "dock_distance_ft", "dock_angle_deg", "distance_margin_ft",
                  "angle_margin_deg", "collision_events", "held_frames"]


def parse_args(argv):
    p = argparse.ArgumentParser(prog="scripts/lab sweep --closed-loop", description=__doc__.split("\n\n")[1])
    p.add_argument("--closed-loop", action="store_true", required=True)
    p.add_argument("--vary", action="append", default=[], metavar="KEY=V1,V2,...",
                   help="a configuration key and its values (TOML), e.g. arm.upper_boom_ft=18,20.9")
    p.add_argument("--config", default=os.path.join(ROOT, "config", "rmslab.toml"),
                   help="the configuration the designs start from (default config/rmslab.toml)")
    p.add_argument("--runs", type=int, default=20, help="virtual subjects a design (default 20)")
    p.add_argument("--seed", type=int, default=1, help="every run's draws come from it (default 1; printed)")
    p.add_argument("--reaction-s", default="0.2,0.5", help="reaction time, s: LO,HI, uniform (default 0.2,0.5)")
    p.add_argument("--rate-gain", default="0.8,1.2", help="rates over the autopilot's: LO,HI (default 0.8,1.2)")
    p.add_argument("--tremor-deg", default="0.01", help="joint command tremor, deg (default 0.01)")
    p.add_argument("--max-s", default="300", help="session time a flight may take (default 300)")
    p.add_argument("--jobs", type=int, default=0, help="flights at once (default: this machine's CPUs)")
    p.add_argument("--out", help="the sweep's folder (default sessions/sweep-closed-<UTC time>)")
    p.add_argument("--no-build", action="store_true")
    a = p.parse_args(argv)
    if not a.vary:
        raise LabError("scripts/lab sweep --closed-loop: give at least one --vary KEY=V1,V2,...")
    if not 1 <= a.runs <= 100000:
        raise LabError(f"--runs {a.runs}: 1..100000")
    if not 0 <= a.seed < 2**64:
        raise LabError(f"--seed {a.seed}: 0..2^64-1")
    if a.jobs < 0 or a.jobs > 256:
        raise LabError(f"--jobs {a.jobs}: 0 (this machine's CPUs) .. 256")
    a.grid = parse_vary(a.vary)
    return a


def designs(grid):
    keys = [k for k, _ in grid]
    return [dict(zip(keys, combo)) for combo in itertools.product(*[vals for _, vals in grid])]


def fly(a, design, jobs, runs=None, max_s=None):
    cmd = [binary("tools/rms_fly"), "--config", a.config, "--runs", str(runs or a.runs), "--seed", str(a.seed),
           "--reaction-s", a.reaction_s, "--rate-gain", a.rate_gain, "--tremor-deg", a.tremor_deg,
           "--max-s", max_s or a.max_s, "--jobs", str(jobs)]
    for k, v in design.items():
        cmd += ["--set", f"{k}={v}"]
    r = subprocess.run(cmd, capture_output=True, text=True)
    if r.returncode != 0:
        lines = [l for l in r.stderr.strip().splitlines() if l.strip() and not l.startswith("Run with --help")]
        why = (lines[-1] if lines else f"exit code {r.returncode}").removeprefix("rms_fly: ")
        about = [k for k in design if k in why]
        raise LabError(f"design {', '.join(f'{k}={v}' for k, v in design.items())}: {why}" if about else why)
    return [json.loads(line) for line in r.stdout.splitlines() if line.strip()]


def check_out(out):
    """A new folder, or an empty one: a sweep never writes over another's
    results or into a session's folder."""
    if os.path.lexists(out) and not os.path.isdir(out):
        raise LabError(f"--out {out}: not a folder")
    if os.path.isdir(out) and os.listdir(out):
        raise LabError(f"--out {out}: the folder has files already (another sweep's, a session's): give a new one")


def run(argv):
    a = parse_args(argv)
    if not os.path.isfile(a.config):
        raise LabError(f"--config {a.config}: no such file")
    if not a.no_build:
        install_and_build()
    require_built("tools/rms_fly")
    jobs = a.jobs or len(os.sched_getaffinity(0))
    ds = designs(a.grid)
    out = os.path.abspath(a.out or os.path.join(ROOT, "sessions",
                                                 "sweep-closed-" + time.strftime("%Y%m%dT%H%M%SZ", time.gmtime())))
    check_out(out)
    for d in ds:  # every design and setting checked before any is flown (one short flight each)
        fly(a, d, 1, runs=1, max_s="1")
    os.makedirs(out, exist_ok=True)
    say(f"sweep: {len(ds)} design{'' if len(ds) == 1 else 's'} x {a.runs} closed-loop flights by virtual subjects (seed {a.seed}; reaction "
        f"{a.reaction_s} s, rate gain {a.rate_gain}, tremor {a.tremor_deg} deg), {jobs} at once")
    t0 = time.monotonic()
    keys = [k for k, _ in a.grid]
    rows = []
    for i, d in enumerate(ds, 1):
        for f in fly(a, d, jobs):
            rows.append({"design": i, **d, **f})
        say(f"  design {i} of {len(ds)}: {', '.join(f'{k} = {v}' for k, v in d.items())}: flown")
    wall = time.monotonic() - t0
    with replacing(os.path.join(out, "flights.csv"), newline="") as f:
        w = csv.writer(f)
        cols = ["design"] + keys + FLIGHT_COLUMNS[1:]
        w.writerow(cols)
        for r in rows:
            w.writerow(["" if r.get(c) is None else r.get(c) for c in cols])
    with replacing(os.path.join(out, "sweep.json")) as f:
        json.dump({"kind": "closed-loop", "config": os.path.abspath(a.config), "seed": a.seed, "runs": a.runs,
                   "reaction_s": a.reaction_s, "rate_gain": a.rate_gain, "tremor_deg": a.tremor_deg,
                   "max_s": a.max_s, "keys": keys, "designs": ds, "wall_s": wall, "jobs": jobs}, f, indent=1)
    r = run_statistics("flight_stats", out)
    if r.returncode != 0:
        raise LabError(f"the sweep's statistics failed: {(r.stderr or r.stdout).strip()}", 1)
    for line in r.stdout.splitlines():
        say(line)
    say(f"{len(rows)} flights in {wall:.1f} s of wall time; {out}/designs.csv (a row a design), flights.csv "
        f"(a row a flight)")
    return 0
