"""scripts/lab sweep: recorded sessions re-simulated under every combination
of configuration values (docs/sessions.md "Sweeps"): the same inputs under
another design. (--closed-loop flies each design afresh instead:
sweep_closed.py, docs/studies.md.)

On this machine the cells run in one rms_resim --cells process
(scripts/sweep-cell --cells), --jobs cells at once on its threads; on a
lab's hosts (--hosts LABFILE) through GNU parallel (Debian's `parallel`:
its ssh logins; a "netns:NAME" host through
scripts/rmslab_launcher/netns-login), in batches, one rms_resim --cells a
batch; with --slurm, as a Slurm array job written for a cluster. A cell is
what rms_resim SESSION --set KEY=VALUE... --discard --result-json gives.
Results are cached by the log's hash, the configuration's hash and
the software's version, so a rerun does only what is missing.

Here: the grid, its cells and the run of a sweep; the cache is
sweep_cache.py, the table sweep_table.py; each runner a module of its own
(sweep_here.py, sweep_parallel.py, sweep_slurm.py), what they share
sweep_cells.py.
"""
import argparse
import collections
import contextlib
import hashlib
import itertools
import json
import os
import signal
import subprocess
import time
import tomllib

from . import sweep_cache, sweep_table
from .common import (ROOT, LabError, binary, file_sha256, install_and_build, read_folder_json, read_toml, replacing,
                     require_session_file, say)
from .sweep_cells import Interrupted, MAX_JOBS, Progress, timeout_override, write_manifest
from .sweep_here import run_here
from .sweep_parallel import check_parallel_paths, lab_workers, run_parallel
from .sweep_slurm import rerun_command, write_slurm

FAILED_SHOWN = 20  # failed cells named on the terminal (the table has them all)


def split_values(text):
    """'0.3,0.4,[1, 2]' -> ['0.3', '0.4', '[1, 2]']: commas inside brackets,
    braces and quotes do not split."""
    out, depth, quote, cur, escaped = [], 0, None, "", False
    for c in text:
        if escaped:  # a backslash escape inside a basic string
            escaped = False
        elif quote == '"' and c == "\\":
            escaped = True
        elif quote:
            quote = None if c == quote else quote
        elif c in "\"'":
            quote = c
        elif c in "[{":
            depth += 1
        elif c in "]}":
            depth -= 1
        elif c == "," and depth == 0:
            out.append(cur.strip())
            cur = ""
            continue
        cur += c
    out.append(cur.strip())
    return out


def same_value(a, b):
    """Two TOML values that make the same design: numbers by value (a float
    key given an integer keeps a float, as set_key does: 1 is 1.0), arrays
    and tables element by element, anything else of the same kind and equal
    (true is not 1)."""
    def number(x):
        return isinstance(x, (int, float)) and not isinstance(x, bool)
    if number(a) and number(b):
        return a == b
    if isinstance(a, list) and isinstance(b, list):
        return len(a) == len(b) and all(same_value(x, y) for x, y in zip(a, b))
    if isinstance(a, dict) and isinstance(b, dict):
        return a.keys() == b.keys() and all(same_value(a[k], b[k]) for k in a)
    return type(a) is type(b) and a == b


def parse_vary(texts):
    """--vary KEY=V1,V2,... (repeatable) -> [(key, [values])]."""
    grid = []
    for t in texts:
        key, eq, values = t.partition("=")
        key = key.strip()
        if not eq or not key or not values.strip():
            raise LabError(f"--vary '{t}': must be KEY=V1,V2,... (e.g. dcp.tpob_ft=0.2,0.3,0.4)")
        vals = split_values(values)
        if any(v == "" for v in vals):
            raise LabError(f"--vary {key}: an empty value in '{values}'")
        parsed = [toml_value(key, v) for v in vals]
        for i, v in enumerate(parsed):
            twin = next((vals[j] for j in range(i) if same_value(parsed[j], v)), None)
            if twin is not None:
                raise LabError(f"--vary {key}: '{twin}' and '{vals[i]}' are the same value")
        if any("\t" in v or "\n" in v for v in vals) or "\t" in key:
            raise LabError(f"--vary {key}: tabs and line breaks are not allowed in keys or values")
        if any(k == key for k, _ in grid):
            raise LabError(f"--vary {key}: given twice (give every value in one --vary)")
        grid.append((key, vals))
    return grid


def toml_value(key, text):
    try:
        return tomllib.loads("v = " + text)["v"]
    except tomllib.TOMLDecodeError as e:
        raise LabError(f"--vary {key}: '{text}' is no TOML value ({e})")


def set_key(cfg, key, value):
    """cfg with key ("a.b", "a[2].b", "a.b[1]") set to value, as rms_resim's
    --set does (base/src/config_settings.cc): an index is decimal digits; a
    float key (or element) given an integer keeps a float. rms_resim --check
    has checked the key before this runs."""
    node, parts = cfg, key.split(".")
    for i, part in enumerate(parts):
        name, index = part, None
        if part.endswith("]") and "[" in part:
            name, _, idx = part[:-1].partition("[")
            if not (idx.isascii() and idx.isdigit()):
                raise LabError(f"--vary {key}: '{part}' has no index a number")
            index = int(idx)
        container, slot = (node, name) if index is None else (node[name], index)
        if i == len(parts) - 1:
            old = container[slot]
            if isinstance(old, float) and isinstance(value, int) and not isinstance(value, bool):
                value = float(value)
            container[slot] = value
            return
        node = container[slot]


def software_version():
    """rms_resim's --version and the SHA-256 of the binary itself: a tree
    rebuilt with uncommitted changes has the same --version, not the same binary."""
    r = subprocess.run([binary("tools/rms_resim"), "--version"], capture_output=True, text=True)
    if r.returncode != 0 or not r.stdout.strip():
        raise LabError(f"{binary('tools/rms_resim')} --version failed: build first (drop --no-build)", 1)
    return f"{r.stdout.strip()} {file_sha256(binary('tools/rms_resim'))}"


class Session:
    def __init__(self, path):
        self.path = os.path.abspath(path)
        if any(c in self.path for c in "\t\n\r"):
            raise LabError(f"{path!r}: tabs and line breaks are not allowed in a session's path")
        try:
            self.path.encode("utf-8")
        except UnicodeEncodeError:
            raise LabError(f"{path!r}: a session's path must be UTF-8 text (it goes into the table)")
        for f in ("lcmlog", "config.toml"):
            require_session_file(path, f)
        if os.path.getsize(os.path.join(self.path, "lcmlog")) == 0:
            raise LabError(f"{path}: its lcmlog is empty: nothing to re-simulate")
        self.real = os.path.realpath(self.path)
        self.config = read_toml(os.path.join(self.path, "config.toml"), "the session's configuration",
                                folder_file=True)
        self.log_sha = file_sha256(os.path.join(self.path, "lcmlog"))
        self.subject = ""
        m = read_folder_json(os.path.join(self.path, "manifest.json"))
        if isinstance(m, dict) and isinstance(m.get("subject"), str):
            self.subject = m["subject"]


def make_cells(sessions, grid, version):
    """Every session under every combination, in order: dicts with index
    (from 1), session, sets [(key, value)], key (the cache key)."""
    cells = []
    for s in sessions:
        for combo in itertools.product(*[vals for _, vals in grid]):
            sets = list(zip([k for k, _ in grid], combo))
            cfg = json.loads(json.dumps(s.config))  # a deep copy
            for k, v in sets:
                set_key(cfg, k, toml_value(k, v))
            cfg_sha = hashlib.sha256(json.dumps(cfg, sort_keys=True, separators=(",", ":"),
                                                default=str).encode()).hexdigest()
            key = hashlib.sha256(f"{s.log_sha}\n{cfg_sha}\n{version}".encode()).hexdigest()
            cells.append({"index": len(cells) + 1, "session": s.path, "subject": s.subject,
                          "sets": sets, "key": key})
    return cells


def check_designs(sessions, grid):
    """Every combination checked by rms_resim --check on each distinct
    configuration before anything runs: a bad key or value is refused with
    the reason (each key alone when the grid is large)."""
    seen = set()
    combos = list(itertools.product(*[vals for _, vals in grid]))
    if len(combos) > 64:
        combos = None
    for s in sessions:
        h = json.dumps(s.config, sort_keys=True, default=str)
        if h in seen:
            continue
        seen.add(h)
        checks = ([list(zip([k for k, _ in grid], c)) for c in combos] if combos is not None else
                  [[(k, v)] for k, vals in grid for v in vals])
        for sets in checks:
            cmd = [binary("tools/rms_resim"), s.path, "--check"]
            for k, v in sets:
                cmd += ["--set", f"{k}={v}"]
            r = subprocess.run(cmd, capture_output=True, text=True)
            if r.returncode != 0:
                why = (r.stderr.strip() or r.stdout.strip()).replace("rms_resim: ", "")
                raise LabError(f"the design {' '.join(f'{k}={v}' for k, v in sets)} is refused for "
                               f"{s.path}: {why}")


def check_out(out):
    """The sweep's folder: an existing writable folder, or one that can be
    made (its nearest existing folder writable)."""
    if os.path.exists(out):
        if not os.path.isdir(out) or not os.access(out, os.W_OK | os.X_OK):
            raise LabError(f"--out {out}: not a folder this user can write")
        return
    parent = os.path.dirname(out)
    while parent and not os.path.exists(parent):
        parent = os.path.dirname(parent)
    if not os.path.isdir(parent) or not os.access(parent, os.W_OK | os.X_OK):
        raise LabError(f"--out {out}: cannot be made ({parent} is not a folder this user can write)")


def parse_args(argv):
    p = argparse.ArgumentParser(prog="scripts/lab sweep", description=run.__doc__,
                                epilog="scripts/lab sweep --closed-loop --help: designs flown afresh by virtual "
                                       "subjects instead (docs/studies.md)")
    p.add_argument("sessions", nargs="+", metavar="SESSION")
    p.add_argument("--vary", action="append", default=[], metavar="KEY=V1,V2,...",
                   help="a configuration key and its values (TOML), e.g. dcp.tpob_ft=0.2,0.3")
    p.add_argument("--out", help="the sweep's folder (default sessions/sweep-<UTC time>)")
    p.add_argument("--hosts", metavar="LABFILE", help="run the cells on the lab's hosts (GNU parallel over ssh)")
    p.add_argument("--jobs", type=int, default=0,
                   help=f"cells at once: on this machine, rms_resim's threads (default: the CPUs the sweep may "
                        f"use); with --hosts, on each host (default: its cores); at most {MAX_JOBS}")
    p.add_argument("--slurm", action="store_true", help="write a Slurm array job instead of running")
    p.add_argument("--cached-only", action="store_true",
                   help="run nothing: the table from the cache (after a Slurm job); a missing cell is a failed row")
    p.add_argument("--cache", help="the results' cache (default sessions/sweep-cache)")
    p.add_argument("--retries", type=int, default=2,
                   help="a failed cell is tried again up to N times (default 2), in a new process (on a lab's "
                        "hosts through GNU parallel again)")
    p.add_argument("--no-build", action="store_true", help="do not install or build first")
    a = p.parse_args(argv)
    if not a.vary:
        raise LabError("scripts/lab sweep: give at least one --vary KEY=V1,V2,...")
    if a.slurm and a.hosts:
        raise LabError("--slurm and --hosts: give one (a Slurm cluster places the cells itself)")
    if a.cached_only and (a.slurm or a.hosts):
        raise LabError("--cached-only runs nothing: not with --slurm or --hosts")
    if a.jobs < 0 or a.retries < 0:
        raise LabError("--jobs and --retries: must not be negative")
    if a.jobs > MAX_JOBS:
        raise LabError(f"--jobs {a.jobs}: at most {MAX_JOBS} cells at once")
    a.grid = parse_vary(a.vary)
    return a


def run_cells(a, cells, todo, sweep_dir, cache, cached):
    """The missing cells on this machine (sweep_here) or through GNU parallel
    on a lab's hosts (sweep_parallel), tried again up to --retries times;
    each result cached as it arrives. Returns (tries again, errors)."""
    errors, retried, pending = [], 0, todo

    def on_result(cell, res):
        # (a closed-loop sweep checks each result against its cell too: sweep_closed.py)
        why = sweep_cache.valid_result(res) or (a.check_result(cell, res) if hasattr(a, "check_result") else None)
        if why is None:
            cache.store(cell["key"], res)
            cell.pop("error", None)
            return True
        cell["error"] = res.get("error", why) if isinstance(res, dict) else why
        return False

    for round_no in range(1, a.retries + 2):
        if not pending:
            break
        if round_no > 1:
            retried += len(pending)
            cells_word = "cell" if len(pending) == 1 else "cells"
            whys = collections.Counter(c.get("error", "") for c in pending).most_common()
            say(f"sweep: trying {len(pending)} failed {cells_word} again (try {round_no} of {a.retries + 1}): "
                + whys[0][0] + (f" (and {len(whys) - 1} other reasons)" if len(whys) > 1 else ""))
        for c in pending:
            c["error"] = "no result"  # until its line says otherwise
        progress = Progress(len(cells), len(cells) - len(pending), cached)
        errors += (run_parallel(pending, sweep_dir, a, progress, round_no, on_result) if a.workers
                   else run_here(pending, sweep_dir, a, progress, on_result))
        progress.show(end=True)
        pending = [c for c in pending if "error" in c]
    return retried, errors


@contextlib.contextmanager
def stopped_by_signals():
    """Ctrl-C, SIGTERM and SIGHUP end the cells' run the same way (Interrupted)."""
    def stop(signum, _frame):
        raise Interrupted(signum)
    old = {sig: signal.signal(sig, stop) for sig in (signal.SIGINT, signal.SIGTERM, signal.SIGHUP)}
    try:
        yield
    finally:
        for sig, h in old.items():
            signal.signal(sig, h)


def run(argv):
    """scripts/lab sweep SESSION... --vary KEY=V1,V2,... [--vary ...] [--out DIR]
    [--hosts LABFILE] [--jobs N] [--slurm | --cached-only] [--cache DIR] [--retries N]:
    every session re-simulated under every combination of the varied keys;
    one table (DIR/sweep.csv, DIR/sweep.html) of what each design did."""
    if "--closed-loop" in argv:
        from . import sweep_closed
        return sweep_closed.run(argv)
    try:
        return run_sweep(argv)
    except KeyboardInterrupt:
        say("sweep interrupted before any cell ran")
        return 130


def run_sweep(argv):
    a = parse_args(argv)
    if not a.no_build:
        install_and_build()
    if not os.access(binary("tools/rms_resim"), os.X_OK):
        raise LabError(f"{binary('tools/rms_resim')} is not built (drop --no-build)", 1)
    sessions = [Session(s) for s in a.sessions]
    if len({s.real for s in sessions}) != len(sessions):
        raise LabError("a session is given twice (the same folder, by another path or a link)")
    check_designs(sessions, a.grid)
    a.workers = lab_workers(a.hosts, a.jobs) if a.hosts else None
    check_parallel_paths(a.workers)
    sweep_dir = os.path.abspath(a.out or os.path.join(
        ROOT, "sessions", "sweep-" + time.strftime("%Y%m%dT%H%M%SZ", time.gmtime())))
    check_out(sweep_dir)
    timeout_override()
    cache = sweep_cache.Cache(a.cache or os.path.join(ROOT, "sessions", "sweep-cache"),
                              must_exist=a.cached_only)
    version = software_version()
    cells = make_cells(sessions, a.grid, version)
    if a.slurm and len(cells) > 1001:
        say(f"note: {len(cells)} cells: Slurm's default MaxArraySize is 1001 (ask the cluster's admin, "
            "or sweep a part of the grid at a time)")
    os.makedirs(sweep_dir, exist_ok=True)
    if not a.cached_only:
        write_manifest(os.path.join(sweep_dir, "cells.tsv"), cells)
        with replacing(os.path.join(sweep_dir, "sweep.json")) as f:
            json.dump({"sessions": [s.path for s in sessions],
                       "vary": [{"key": k, "values": v} for k, v in a.grid],
                       "software": version, "cache": cache.folder, "cells": len(cells)}, f, indent=2)
    results = {c["index"]: cache.load(c["key"]) for c in cells}
    spoiled = {p: why for p, why in cache.unreadable}
    for path, why in cache.unreadable:
        say(f"cache entry {path}: {why}: " +
            ("not used" if a.cached_only else "its cell is run again"))
    todo = [c for c in cells if results[c["index"]] is None]
    cached = len(cells) - len(todo)
    n_s, n_d = len(sessions), len(cells) // len(sessions)
    say(f"sweep: {len(cells)} cells ({n_s} session{'s' * (n_s != 1)} x {n_d} design{'s' * (n_d != 1)}), "
        f"{cached} already in the cache {cache.folder}")
    if a.slurm:
        rerun = rerun_command(a, sessions, sweep_dir, cache.folder)
        script = write_slurm(sweep_dir, cells, cache.folder, rerun)
        say(f"Slurm array job written: sbatch {script}")
        say(f"then, for the table: {rerun}")
        return 0
    t0, retried, errors = time.monotonic(), 0, []
    if a.cached_only:
        for c in todo:
            why = spoiled.get(cache.path(c["key"]))
            c["error"] = (f"its cache entry is not usable ({why}): run its Slurm task again" if why else
                          "not in the cache (has the Slurm job run every task? see DIR/slurm-*.out)")
    elif todo:
        try:
            with stopped_by_signals():
                try:
                    retried, errors = run_cells(a, cells, todo, sweep_dir, cache, cached)
                finally:
                    drop_if_changed(sessions, todo, cache, version)
        except Interrupted as e:
            done = sum(1 for c in todo if "error" not in c)
            say(f"sweep interrupted ({e.name}): the {done} cells finished in this run are in the cache; "
                "the same command again runs only what is missing")
            return 128 + e.signum
        except sweep_cache.CannotWrite:  # (a full disk)
            done = sum(1 for c in todo if "error" not in c)
            say(f"sweep stopped: the {done} cells finished in this run before it are in the cache; "
                "the same command again, once the reason below is put right, runs only what is missing")
            raise
        for c in todo:
            results[c["index"]] = None if "error" in c else cache.load(c["key"])
    elapsed = time.monotonic() - t0
    return finish(a, cells, results, todo, sweep_dir, cached, retried, errors, elapsed)


def drop_if_changed(sessions, todo, cache, version):
    """A session whose log is not the one the cache keys were made from
    (changed, cut short or gone during the sweep), or an rms_resim that is
    not the one they were made with (rebuilt during the sweep): the cells'
    results of this run it touches are taken out of the cache and the cells
    failed, as their results may be the changed log's or binary's."""
    try:
        rebuilt = software_version() != version
    except LabError:
        rebuilt = True
    if rebuilt:
        for c in todo:
            if "error" not in c:
                with contextlib.suppress(OSError):
                    os.remove(cache.path(c["key"]))
                c["error"] = (f"{binary('tools/rms_resim')} changed during the sweep (rebuilt?): its cache key "
                              "was made from the one before; result not kept; run the sweep again")
        return
    for s in sessions:
        kept = [c for c in todo if c["session"] == s.path and "error" not in c]
        if not kept:
            continue  # nothing of this run to keep or drop: its log is not read again
        try:
            same = file_sha256(os.path.join(s.path, "lcmlog")) == s.log_sha
        except OSError:
            same = False
        if same:
            continue
        for c in kept:
            with contextlib.suppress(OSError):
                os.remove(cache.path(c["key"]))
            c["error"] = ("its session's log changed during the sweep (its SHA-256 is no longer the one "
                          "its cache key was made from): result not kept; run the sweep again")


def finish(a, cells, results, todo, sweep_dir, cached, retried, errors, elapsed):
    """The table, and what ran, what failed and why."""
    rows = [(c, results[c["index"]]) for c in cells]
    failed = [c for c, res in rows if res is None]
    for c in failed:
        c.setdefault("error", "no result")
    csv_path, html_path = sweep_table.write(sweep_dir, a.grid, rows)
    ran = len(todo) - len(failed) if not a.cached_only else 0
    say(f"sweep: {ran} cells run in {elapsed:.2f} s"
        + (f" ({ran / elapsed:.1f} cells/s)" if ran > 0 and elapsed > 0 else "")
        + f", {cached} from the cache, {retried} tries again, {len(failed)} failed")
    notes = {}  # a session's log note, once a session (its cells share it)
    for c, res in rows:
        if res is not None and res.get("note"):
            notes.setdefault(c["session"], res["note"])
    for session_path, note in notes.items():
        say(f"note: {session_path}: {note} (its cells' note column)")
    for c in failed[:FAILED_SHOWN]:
        say(f"  cell {c['index']} FAILED ({os.path.basename(c['session'])} "
            f"{' '.join(f'{k}={v}' for k, v in c['sets'])}): {c['error']}")
    if len(failed) > FAILED_SHOWN:
        say(f"  ... and {len(failed) - FAILED_SHOWN} more failed cells: each with why in {csv_path}")
    for e in errors[-5:] if failed else []:  # their last lines, when a cell failed
        say(f"  {e}")
    say(f"table: {csv_path}")
    say(f"page:  {html_path}")
    return 1 if failed else 0
