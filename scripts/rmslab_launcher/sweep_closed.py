"""scripts/lab sweep --closed-loop: designs judged by flying them
(docs/studies.md "Designs judged by flying them").

Each design -- every combination of the --vary values over the
configuration -- is flown from the start by --runs virtual subjects of each
kind in --subjects: the autopilot, and the scripted operator at an offline
station (it reads only the status screen and types only keys), each run
with a reaction time, a rate gain and a noise seed drawn from --seed
(rms_fly), in closed loop with the real DCP and no network. The flights go
out as cells (a design, a kind of subject, up to --runs-per-cell runs) the
way a replay sweep's do (sweep.py and its runners): on this machine's cores, on a lab's
hosts through GNU parallel (--hosts LABFILE), or as a Slurm array job
(--slurm; then --cached-only for the table); each cell's result is cached,
so a sweep stopped part way runs only what is missing. One table a design
and kind of subject: the share docked with its interval, the times to
acquire and to dock, the docking margins, collisions, keys, and why the
others failed (flight_stats.py, with Debian's python3 for scipy). Without
--closed-loop, `scripts/lab sweep SESSION...` replays recorded inputs: the
same inputs under another design.
"""
import argparse
import csv
import hashlib
import itertools
import json
import os
import shlex
import subprocess
import time

from . import sweep, sweep_cache, sweep_cells, sweep_parallel, sweep_slurm
from .common import (ROOT, LabError, binary, file_sha256, install_and_build, replacing, require_built,
                     run_statistics, say)

SUBJECTS = ("autopilot", "scripted")
FLIGHT_COLUMNS = ["design", "subject", "run", "seed", "reaction_s", "latency_frames", "rate_gain", "docked",
                  "failure", "time_s", "acquired_s", "cleared_s", "docked_s", "dock_distance_ft", "dock_angle_deg",
                  "distance_margin_ft", "angle_margin_deg", "collision_events", "held_frames", "key_actions"]
# A cell's time limit (a batch's, as sweep_cells.py's): a flight of max_s session
# seconds takes well under a tenth of that here, loaded (the scripted
# operator, the slower, about 1 s for 90 s); this is several times that.
CELL_S_BASE, CELL_S_A_FLIGHT_S = 10.0, 0.1


def parse_args(argv):
    p = argparse.ArgumentParser(prog="scripts/lab sweep --closed-loop", description=__doc__.split("\n\n")[1])
    p.add_argument("--closed-loop", action="store_true", required=True)
    p.add_argument("--vary", action="append", default=[], metavar="KEY=V1,V2,...",
                   help="a configuration key and its values (TOML), e.g. arm.upper_boom_ft=18,20.9")
    p.add_argument("--config", default=os.path.join(ROOT, "config", "rmslab.toml"),
                   help="the configuration the designs start from (default config/rmslab.toml)")
    p.add_argument("--subjects", default=",".join(SUBJECTS),
                   help="who flies each design: autopilot, scripted, or both (default autopilot,scripted)")
    p.add_argument("--runs", type=int, default=20, help="virtual subjects a design, of each kind (default 20)")
    p.add_argument("--seed", type=int, default=1, help="every run's draws come from it (default 1; printed)")
    p.add_argument("--reaction-s", default="0.2,0.5", help="reaction time, s: LO,HI, uniform (default 0.2,0.5)")
    p.add_argument("--rate-gain", default="0.8,1.2",
                   help="the autopilot's rates, the scripted operator's timed taps, times this: LO,HI "
                        "(default 0.8,1.2)")
    p.add_argument("--tremor-deg", default="0.01", help="the autopilot's joint command tremor, deg (default 0.01)")
    p.add_argument("--reaction-sd-s", default="0.05",
                   help="the scripted operator's: each reaction drawn about the run's, s (default 0.05)")
    p.add_argument("--max-s", default="300", help="session time a flight may take (default 300)")
    p.add_argument("--runs-per-cell", type=int, default=10,
                   help="runs a cell (the unit a host, a Slurm task, the cache takes; default 10)")
    p.add_argument("--jobs", type=int, default=0,
                   help="flights at once: on this machine (default: its CPUs); with --hosts, cells on each host "
                        "(default: its cores)")
    p.add_argument("--hosts", metavar="LABFILE", help="fly the cells on the lab's hosts (GNU parallel over ssh)")
    p.add_argument("--slurm", action="store_true", help="write a Slurm array job instead of flying")
    p.add_argument("--cached-only", action="store_true",
                   help="fly nothing: the table from the cache (after a Slurm job); a missing cell is said")
    p.add_argument("--cache", help="the cells' cache (default sessions/sweep-cache)")
    p.add_argument("--retries", type=int, default=2, help="a failed cell is tried again up to N times (default 2)")
    p.add_argument("--out", help="the sweep's folder (default sessions/sweep-closed-<UTC time>)")
    p.add_argument("--no-build", action="store_true")
    a = p.parse_args(argv)
    if not a.vary:
        raise LabError("scripts/lab sweep --closed-loop: give at least one --vary KEY=V1,V2,...")
    if not 1 <= a.runs <= 100000:
        raise LabError(f"--runs {a.runs}: 1..100000")
    if not 1 <= a.runs_per_cell <= 100000:
        raise LabError(f"--runs-per-cell {a.runs_per_cell}: 1..100000")
    if not 0 <= a.seed < 2**64:
        raise LabError(f"--seed {a.seed}: 0..2^64-1")
    if a.jobs < 0 or a.jobs > sweep_cells.MAX_JOBS:
        raise LabError(f"--jobs {a.jobs}: 0 (this machine's CPUs) .. {sweep_cells.MAX_JOBS}")
    if a.retries < 0:
        raise LabError(f"--retries {a.retries}: must not be negative")
    if a.slurm and a.hosts:
        raise LabError("--slurm and --hosts: give one (a Slurm cluster places the cells itself)")
    if a.cached_only and (a.slurm or a.hosts):
        raise LabError("--cached-only flies nothing: not with --slurm or --hosts")
    a.subject_list = [s.strip() for s in a.subjects.split(",") if s.strip()]
    bad = [s for s in a.subject_list if s not in SUBJECTS]
    if bad or not a.subject_list or len(set(a.subject_list)) != len(a.subject_list):
        raise LabError(f"--subjects {a.subjects}: autopilot, scripted or both, each once")
    for name in ("reaction_s", "rate_gain", "tremor_deg", "reaction_sd_s", "max_s"):
        v = getattr(a, name)
        if any(c in v for c in "\t\n\r"):
            raise LabError(f"--{name.replace('_', '-')}: tabs and line breaks are not allowed")
    try:
        a.max_s_value = float(a.max_s)
    except ValueError:
        a.max_s_value = float("nan")
    if not 1 <= a.max_s_value <= 3600:  # (rms_fly's range; nan and inf fail it)
        raise LabError(f"--max-s {a.max_s}: a number of seconds, 1 to 3600")
    if any(c in a.config for c in "\t\n\r"):
        raise LabError(f"--config {a.config!r}: tabs and line breaks are not allowed in its path")
    a.grid = sweep.parse_vary(a.vary)
    a.cell_mode = "--fly-cells"  # the runners (sweep_here, sweep_parallel): scripts/sweep-cell --fly-cells
    return a


def designs(grid):
    keys = [k for k, _ in grid]
    return [dict(zip(keys, combo)) for combo in itertools.product(*[vals for _, vals in grid])]


def fly_options(a, runs, max_s):
    """rms_fly's options every flight of the sweep shares."""
    return ["--seed", str(a.seed), "--reaction-s", a.reaction_s, "--rate-gain", a.rate_gain, "--tremor-deg",
            a.tremor_deg, "--reaction-sd-s", a.reaction_sd_s, "--max-s", max_s, "--runs", str(runs)]


def check_config(a):
    """The configuration every cell reads (again and again, wherever it
    flies): a regular file, named by its real path (a link followed once)."""
    real = os.path.realpath(a.config)
    if os.path.isdir(real):
        raise LabError(f"--config {a.config}: a folder, not a configuration file")
    if not os.path.exists(real):
        raise LabError(f"--config {a.config}: no such file")
    if not os.path.isfile(real):
        raise LabError(f"--config {a.config}: not a regular file (each cell reads it again: a FIFO or a device "
                       "cannot be)")
    a.config = real


def check_design(a, design):
    """A design's configuration checked by one short flight (rms_fly here):
    a bad key or value is refused, naming it, before anything is flown."""
    cmd = [binary("tools/rms_fly"), "--config", a.config, "--jobs", "1"] + fly_options(a, 1, "1")
    for k, v in design.items():
        cmd += ["--set", f"{k}={v}"]
    r = subprocess.run(cmd, capture_output=True, text=True)
    if r.returncode != 0:
        lines = [line for line in r.stderr.strip().splitlines()
                 if line.strip() and not line.startswith("Run with --help")]
        why = (lines[-1] if lines else f"exit code {r.returncode}").removeprefix("rms_fly: ")
        about = [k for k in design if k in why]
        raise LabError(f"design {', '.join(f'{k}={v}' for k, v in design.items())}: {why}" if about else why)


def software_id():
    """rms_fly --software-id: its version and the SHA-256 of the binary (a
    tree rebuilt with uncommitted changes has the same version, not the same
    binary). Each cell names it, and rms_fly refuses to fly a cell that
    names another."""
    r = subprocess.run([binary("tools/rms_fly"), "--software-id"], capture_output=True, text=True)
    if r.returncode != 0 or not r.stdout.strip() or any(c in r.stdout.strip() for c in "\t\n"):
        raise LabError(f"{binary('tools/rms_fly')} --software-id failed: build first (drop --no-build)", 1)
    return r.stdout.strip()


def make_cells(a, ds, software):
    """Every design x subject x chunk of runs, in order: dicts with index
    (from 1), design (from 1), subject, first, runs, fields (rms_fly's
    options: the configuration, its SHA-256 and the software, which rms_fly
    checks before it flies), key (the SHA-256 of the fields joined by tabs,
    which rms_fly --cells checks too: what is cached under a key is what its
    options fly) and cell_s (its time limit)."""
    config_sha = file_sha256(a.config)
    cells = []
    for i, d in enumerate(ds, 1):
        for subject in a.subject_list:
            for first in range(0, a.runs, a.runs_per_cell):
                n = min(a.runs_per_cell, a.runs - first)
                fields = (["--config", a.config, "--config-sha256", config_sha, "--software", software,
                           "--subject", subject, "--first-run", str(first)] + fly_options(a, n, a.max_s) +
                          [x for k, v in d.items() for x in ("--set", f"{k}={v}")])
                key = hashlib.sha256("\t".join(fields).encode()).hexdigest()
                cells.append({"index": len(cells) + 1, "design": i, "subject": subject, "first": first, "runs": n,
                              "fields": fields, "key": key,
                              "cell_s": CELL_S_BASE + n * CELL_S_A_FLIGHT_S * a.max_s_value})
    return cells


def cell_result_why(cell, res):
    """None when res holds the flights its cell flies (each run of it, by
    its subject), else why not: a cached entry is checked against the cell
    it stands for."""
    flights = res.get("flights") if isinstance(res, dict) else None
    if not isinstance(flights, list):
        return "not a closed-loop cell's result"
    runs = [f.get("run") for f in flights if isinstance(f, dict)]
    if runs != list(range(cell["first"], cell["first"] + cell["runs"])):
        return f"its runs are not the cell's ({cell['first']}..{cell['first'] + cell['runs'] - 1})"
    if any(f.get("subject") != cell["subject"] for f in flights):
        return f"its flights are not all the {cell['subject']}'s"
    return None


def manifest_text(cells):
    return "".join("\t".join([str(c["index"]), c["key"]] + c["fields"]) + "\n" for c in cells)


def check_out(a, out, cells):
    """A new folder, an empty one, or this very sweep's (its cells.tsv the
    same: the same command again, after a stop, goes on where it stopped):
    a sweep never writes over another's results or into a session's
    folder. With --cached-only: the folder --slurm wrote for this sweep."""
    if os.path.lexists(out) and not os.path.isdir(out):
        raise LabError(f"--out {out}: not a folder")
    try:
        same = open(os.path.join(out, "cells.tsv")).read() == manifest_text(cells)
    except (OSError, UnicodeDecodeError):
        same = False
    if a.cached_only and not same:
        raise LabError(f"--out {out}: --cached-only needs the folder --slurm wrote for this very sweep (its "
                       "cells.tsv is not this sweep's, or there is none): give the command --slurm printed")
    if not same and os.path.isdir(out) and os.listdir(out):
        raise LabError(f"--out {out}: the folder has files already (another sweep's, a session's): give a new one")
    sweep.check_out(out)
    if a.slurm and any(c.isspace() for c in out):
        raise LabError("--slurm: the sweep's folder must have no spaces in its path (#SBATCH lines cannot "
                       "quote it)")


def write_slurm(a, out, cells, cache_dir):
    rerun = [os.path.join(ROOT, "scripts", "lab"), "sweep", "--closed-loop", "--config", os.path.abspath(a.config),
             "--subjects", ",".join(a.subject_list), "--runs", str(a.runs), "--runs-per-cell", str(a.runs_per_cell),
             "--seed", str(a.seed), "--reaction-s", a.reaction_s, "--rate-gain", a.rate_gain, "--tremor-deg",
             a.tremor_deg, "--reaction-sd-s", a.reaction_sd_s, "--max-s", a.max_s]
    for k, vals in a.grid:
        rerun += ["--vary", f"{k}={','.join(vals)}"]
    rerun += ["--out", out, "--cache", cache_dir, "--cached-only", "--no-build"]
    command = " ".join(shlex.quote(x) for x in rerun)
    return sweep_slurm.write_slurm(out, cells, cache_dir, command, cell_args="--fly"), command


def fly_cells(a, cells, todo, out, cache, cached):
    """The missing cells flown (sweep.run_cells's runners), each cached as it
    arrives. Returns (tries again, errors) or raises sweep_cells.Interrupted."""
    with sweep.stopped_by_signals():
        return sweep.run_cells(a, cells, todo, out, cache, cached)


def flight_rows(a, ds, cells, results):
    rows, missing = [], []
    for c in cells:
        res = results.get(c["index"])
        if res is None:
            missing.append(c)
            continue
        for f in res["flights"]:  # the design is the cell's, whatever the result says
            rows.append({**f, "design": c["design"], **ds[c["design"] - 1]})
    return rows, missing


def write_tables(a, out, ds, rows, jobs, wall, missing):
    keys = [k for k, _ in a.grid]
    with replacing(os.path.join(out, "flights.csv"), newline="") as f:
        w = csv.writer(f)
        cols = ["design"] + keys + FLIGHT_COLUMNS[1:]
        w.writerow(cols)
        for r in rows:
            w.writerow(["" if r.get(c) is None else r.get(c) for c in cols])
    with replacing(os.path.join(out, "sweep.json")) as f:
        json.dump({"kind": "closed-loop", "config": os.path.abspath(a.config), "seed": a.seed, "runs": a.runs,
                   "subjects": a.subject_list, "reaction_s": a.reaction_s, "rate_gain": a.rate_gain,
                   "tremor_deg": a.tremor_deg, "reaction_sd_s": a.reaction_sd_s, "max_s": a.max_s,
                   "runs_per_cell": a.runs_per_cell, "keys": keys, "designs": ds, "wall_s": wall, "jobs": jobs,
                   "hosts": a.hosts,
                   "missing_cells": [{k: c[k] for k in ("index", "design", "subject", "first", "runs", "error")
                                      if k in c} for c in missing]}, f, indent=1)


def cached_results(a, cells, cache):
    """Each cell's result from the cache (None where it has none, or one not
    its cell's: said), and the cells still to fly."""
    results = {c["index"]: cache.load(c["key"]) for c in cells}
    for c in cells:  # an entry is checked against the cell it stands for
        why = results[c["index"]] is not None and cell_result_why(c, results[c["index"]])
        if why:
            cache.unreadable.append((cache.path(c["key"]), f"not its cell's ({why})"))
            results[c["index"]] = None
    for path, why in cache.unreadable:
        say(f"cache entry {path}: {why}: " + ("not used" if a.cached_only else "its cell is flown again"))
    return results, [c for c in cells if results[c["index"]] is None]


def run(argv):
    a = parse_args(argv)
    check_config(a)
    if not a.no_build:
        install_and_build()
    require_built("tools/rms_fly")
    ds = designs(a.grid)
    stamp = time.strftime("%Y%m%dT%H%M%SZ", time.gmtime())
    out = os.path.abspath(a.out or os.path.join(ROOT, "sessions", "sweep-closed-" + stamp))
    cells = make_cells(a, ds, software_id())
    check_out(a, out, cells)
    sweep_cells.timeout_override()
    a.workers = sweep_parallel.lab_workers(a.hosts, a.jobs) if a.hosts else None
    sweep_parallel.check_parallel_paths(a.workers)
    for d in ds:  # every design and setting checked before any is flown (one short flight each)
        check_design(a, d)
    cache = sweep_cache.Cache(a.cache or os.path.join(ROOT, "sessions", "sweep-cache"), must_exist=a.cached_only)
    a.check_result = cell_result_why
    if a.slurm and any(c.isspace() for c in cache.folder + ROOT):
        raise LabError("--slurm: the cache and the tree must have no spaces in their paths (#SBATCH lines cannot "
                       "quote them)")
    os.makedirs(out, exist_ok=True)
    jobs = a.jobs or len(os.sched_getaffinity(0))
    if not a.cached_only:
        sweep_cells.write_manifest(os.path.join(out, "cells.tsv"), cells)
        write_tables(a, out, ds, [], jobs, 0.0, [])  # what the sweep is, before anything is flown
    results, todo = cached_results(a, cells, cache)
    cached = len(cells) - len(todo)
    where = (f"on the hosts of {a.hosts}" if a.hosts else "as a Slurm array job" if a.slurm else
             "from the cache" if a.cached_only else f"{jobs} at once")
    say(f"sweep: {len(ds)} design{'' if len(ds) == 1 else 's'} x {' and '.join(a.subject_list)} x {a.runs} "
        f"closed-loop flights (seed {a.seed}; reaction {a.reaction_s} s, rate gain {a.rate_gain}, tremor "
        f"{a.tremor_deg} deg, reaction sd {a.reaction_sd_s} s): {len(cells)} cells, {cached} already in the cache "
        f"{cache.folder}; {where}")
    if a.slurm:
        script, command = write_slurm(a, out, cells, cache.folder)
        say(f"Slurm array job written: sbatch {script}")
        say(f"then, for the table: {command}")
        return 0
    t0 = time.monotonic()
    if a.cached_only:
        for c in todo:
            c["error"] = "not in the cache (has the Slurm job run every task? see DIR/slurm-*.out)"
    elif todo:
        try:
            _, errors = fly_cells(a, cells, todo, out, cache, cached)
        except sweep_cells.Interrupted as e:
            done = sum(1 for c in todo if "error" not in c)
            say(f"sweep interrupted ({e.name}): the {done} cells finished in this run are in the cache; "
                "the same command again flies only what is missing")
            return 128 + e.signum
        for line in errors[-10:]:
            say(f"  {line}")
        for c in todo:
            results[c["index"]] = None if "error" in c else cache.load(c["key"])
    wall = time.monotonic() - t0
    if file_sha256(a.config) != cells[0]["fields"][3]:
        say(f"the configuration {a.config} changed during the sweep: the cells flown after the change were "
            "refused (their results would not be the sweep's); put it back, or make a new sweep")
    rows, missing = flight_rows(a, ds, cells, results)
    write_tables(a, out, ds, rows, jobs, wall, missing)
    for c in missing[:sweep.FAILED_SHOWN]:
        why = c.get("error", "no result").removeprefix("no result: ")
        say(f"  cell {c['index']} (design {c['design']}, {c['subject']}, runs {c['first']}.."
            f"{c['first'] + c['runs'] - 1}): no result: {why}")
    if not rows:
        raise LabError("no cell has a result: no table", 1)
    r = run_statistics("flight_stats", out)
    if r.returncode != 0:
        raise LabError(f"the sweep's statistics failed: {(r.stderr or r.stdout).strip()}", 1)
    for line in r.stdout.splitlines():
        say(line)
    say(f"{len(rows)} flights in {wall:.1f} s of wall time; {out}/designs.csv (a row a design and subject), "
        f"flights.csv (a row a flight)" +
        (f"; {len(missing)} cell{'' if len(missing) == 1 else 's'} without a result" if missing else ""))
    return 1 if missing else 0
