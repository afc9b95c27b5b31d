"""scripts/lab sweep: recorded sessions re-simulated under every combination
of configuration values (docs/sessions.md "Sweeps").

The cells run through GNU parallel (Debian's `parallel`): on this machine's
cores, or on a lab's hosts (--hosts LABFILE: parallel's ssh logins; a
"netns:NAME" host through scripts/rmslab_launcher/netns-login), or, with
--slurm, as a Slurm array job written for a cluster. Each cell is
scripts/sweep-cell: rms_resim SESSION --set KEY=VALUE... --discard
--result-json. Results are cached by the log's hash, the configuration's
hash and the software's version, so a rerun does only what is missing.
"""
import argparse
import hashlib
import itertools
import json
import os
import shlex
import shutil
import subprocess
import sys
import threading
import time
import tomllib

from . import sweep_table
from .common import BUILD, ROOT, LabError, binary, install_and_build, read_toml, say

CELL = os.path.join(ROOT, "scripts", "sweep-cell")
NETNS_LOGIN = os.path.join(ROOT, "scripts", "rmslab_launcher", "netns-login")
SSH_OPTIONS = "ssh -o BatchMode=yes -o ConnectTimeout=5"


def split_values(text):
    """'0.3,0.4,[1, 2]' -> ['0.3', '0.4', '[1, 2]']: commas inside brackets,
    braces and quotes do not split."""
    out, depth, quote, cur = [], 0, None, ""
    for c in text:
        if quote:
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
        if len(set(vals)) != len(vals):
            raise LabError(f"--vary {key}: a value given twice in '{values}'")
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
    """cfg with key ("a.b[2].c") set to value, as rms_resim's --set does
    (a float key given an integer keeps a float)."""
    node = cfg
    parts = key.split(".")
    for i, part in enumerate(parts):
        name, index = part, None
        if part.endswith("]") and "[" in part:
            name, _, idx = part[:-1].partition("[")
            index = int(idx) if idx.isdigit() else None
        last = i == len(parts) - 1
        if last and index is None:
            if isinstance(node.get(name), float) and isinstance(value, int) and not isinstance(value, bool):
                value = float(value)
            node[name] = value
            return
        node = node[name] if index is None else node[name][index]
        if last:
            raise LabError(f"--vary {key}: an element of an array of tables cannot be set whole")


def file_sha256(path):
    h = hashlib.sha256()
    with open(path, "rb") as f:
        for block in iter(lambda: f.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()


def software_version():
    r = subprocess.run([binary("tools/rms_resim"), "--version"], capture_output=True, text=True)
    if r.returncode != 0 or not r.stdout.strip():
        raise LabError(f"{binary('tools/rms_resim')} --version failed: build first (drop --no-build)", 1)
    return r.stdout.strip()


class Session:
    def __init__(self, path):
        self.path = os.path.abspath(path)
        for f in ("lcmlog", "config.toml"):
            if not os.path.isfile(os.path.join(self.path, f)):
                raise LabError(f"{path}: not a session folder (no {f})")
        self.config = read_toml(os.path.join(self.path, "config.toml"), "the session's configuration")
        self.log_sha = file_sha256(os.path.join(self.path, "lcmlog"))
        try:
            with open(os.path.join(self.path, "manifest.json")) as f:
                self.subject = json.load(f).get("subject", "")
        except (OSError, ValueError):
            self.subject = ""


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
            key = hashlib.sha256(f"{s.log_sha}\n{cfg_sha}\n{version}".encode()).hexdigest()[:32]
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


def write_manifest(path, cells):
    """cells.tsv: INDEX, cache KEY, SESSION, KEY=VALUE... a line a cell
    (what scripts/sweep-cell MANIFEST INDEX reads)."""
    with open(path, "w") as f:
        for c in cells:
            f.write("\t".join([str(c["index"]), c["key"], c["session"]] +
                              [f"{k}={v}" for k, v in c["sets"]]) + "\n")


def lab_workers(labfile, jobs):
    """GNU parallel's ssh logins for a lab file's hosts ([sweep] hosts, or
    every distinct host of [hosts]; the file read strictly by rms_session
    labfile, as scripts/lab demo reads it), the remote tree's sweep-cell and
    its build."""
    r = subprocess.run([binary("tools/rms_session"), "labfile", labfile], capture_output=True, text=True)
    if r.returncode:
        raise LabError(r.stderr.strip() or f"{labfile}: cannot be read as a lab file")
    lab = json.loads(r.stdout)
    hosts = lab["sweep_hosts"] or sorted(set(lab["hosts"].values()))
    per_host = lab["sweep_jobs_per_host"] or jobs
    logins = []
    for h in hosts:
        n = f"{per_host}/" if per_host > 0 else ""
        if h == "localhost":
            logins.append(f"{n}:")
        elif h.startswith("netns:"):
            logins.append(f"{n}{NETNS_LOGIN} {h[6:]}")
        else:  # ssh:[USER@]HOST (the reader allows nothing else)
            logins.append(f"{n}{h[4:]}")
    remote_root = lab["remote_root"] or ROOT
    return logins, os.path.join(remote_root, "scripts", "sweep-cell"), lab["remote_build"]


class Progress:
    """A progress bar on a terminal; a line every tenth otherwise."""

    def __init__(self, total, cached):
        self.total, self.done, self.failed, self.t0 = total, cached, 0, time.monotonic()
        self.cached, self.tty, self.last_tenth = cached, sys.stderr.isatty(), -1
        self.show()

    def step(self, ok):
        self.done += 1
        self.failed += not ok
        self.show()

    def show(self, end=False):
        frac = self.done / self.total if self.total else 1.0
        rate = (self.done - self.cached) / max(time.monotonic() - self.t0, 1e-9)
        bar = "#" * int(30 * frac) + "." * (30 - int(30 * frac))
        line = (f"sweep [{bar}] {self.done}/{self.total} cells ({self.cached} cached, "
                f"{self.failed} failed) {rate:.1f} cells/s")
        if self.tty:
            print("\r" + line + ("\n" if end else ""), end="", file=sys.stderr, flush=True)
        elif end or int(10 * frac) != self.last_tenth:
            self.last_tenth = int(10 * frac)
            say(line)


def run_parallel(todo, sweep_dir, args, progress, round_no):
    """The cells through GNU parallel; {index: result} as their lines arrive."""
    if not shutil.which("parallel"):
        raise LabError("GNU parallel is not installed: run scripts/install-deps", 1)
    cell, env_build = CELL, {}
    cmd = ["parallel", "--will-cite", "--colsep", "\t", "--joblog",
           os.path.join(sweep_dir, f"joblog-{time.strftime('%Y%m%dT%H%M%S')}-try{round_no}"),
           "--halt", "never"]
    if args.workers:
        logins, cell, remote_build = args.workers
        for login in logins:
            cmd += ["--sshlogin", login]
        cmd += ["--ssh", SSH_OPTIONS]
        if remote_build:
            env_build = {"RMSLAB_BUILD": remote_build}
    else:
        cmd += ["--jobs", str(args.jobs or os.cpu_count() or 1)]
    prefix = " ".join(f"{k}={shlex.quote(v)}" for k, v in env_build.items())
    ncols = 3 + len(todo[0]["sets"])
    template = (f"{prefix} {shlex.quote(cell)} --cell " +
                " ".join("{%d}" % i for i in range(1, ncols + 1))).strip()
    cmd.append(template)
    todo_file = os.path.join(sweep_dir, "todo.tsv")
    write_manifest(todo_file, todo)
    cmd += ["::::", todo_file]
    results = {}
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    errors = []

    def drain_stderr():
        for line in proc.stderr:
            errors.append(line.rstrip())
    t = threading.Thread(target=drain_stderr, daemon=True)
    t.start()
    for line in proc.stdout:
        idx, _, payload = line.rstrip("\n").partition("\t")
        try:
            res = json.loads(payload)
            idx = int(idx)
        except ValueError:
            errors.append(line.rstrip())
            continue
        ok = "error" not in res
        results[idx] = res
        progress.step(ok)
    proc.wait()
    t.join(timeout=5)
    return results, errors


def write_slurm(sweep_dir, cells, cache_dir, args):
    """A Slurm array job: task N runs cell N of cells.tsv and stores its
    result in the cache; `scripts/lab sweep` run again afterwards makes the
    table from the cache."""
    script = os.path.join(sweep_dir, "sweep.sbatch")
    manifest = os.path.join(sweep_dir, "cells.tsv")
    rerun = " ".join(shlex.quote(a) for a in [os.path.join(ROOT, "scripts", "lab"), "sweep"] + args.raw_argv
                     if a != "--slurm")
    with open(script, "w") as f:
        f.write(f"""#!/bin/sh
# A Slurm array job of {len(cells)} cells (docs/sessions.md "Sweeps"), written by scripts/lab sweep --slurm.
#   sbatch {shlex.quote(script)}
# then, when it has run, the table (every cell from the cache):
#   {rerun}
#SBATCH --job-name=rmslab-sweep
#SBATCH --array=1-{len(cells)}
#SBATCH --cpus-per-task=1
#SBATCH --output={os.path.join(sweep_dir, 'slurm-%A_%a.out')}
export RMSLAB_BUILD={shlex.quote(BUILD)}
exec {shlex.quote(CELL)} {shlex.quote(manifest)} "$SLURM_ARRAY_TASK_ID" --store {shlex.quote(cache_dir)}
""")
    os.chmod(script, 0o755)
    return script, rerun


def run(argv):
    """scripts/lab sweep SESSION... --vary KEY=V1,V2,... [--vary ...] [--out DIR]
    [--hosts LABFILE] [--jobs N] [--slurm] [--cache DIR] [--retries N]: every
    session re-simulated under every combination of the varied keys; one
    table (DIR/sweep.csv, DIR/sweep.html) of what each design did."""
    p = argparse.ArgumentParser(prog="scripts/lab sweep", description=run.__doc__)
    p.add_argument("sessions", nargs="+", metavar="SESSION")
    p.add_argument("--vary", action="append", default=[], metavar="KEY=V1,V2,...",
                   help="a configuration key and its values (TOML), e.g. dcp.tpob_ft=0.2,0.3")
    p.add_argument("--out", help="the sweep's folder (default sessions/sweep-<UTC time>)")
    p.add_argument("--hosts", metavar="LABFILE", help="run the cells on the lab's hosts (GNU parallel over ssh)")
    p.add_argument("--jobs", type=int, default=0, help="cells at once (a host): default its cores")
    p.add_argument("--slurm", action="store_true", help="write a Slurm array job instead of running")
    p.add_argument("--cache", help="the results' cache (default sessions/sweep-cache)")
    p.add_argument("--retries", type=int, default=2,
                   help="a failed cell is tried again up to N times (default 2), through GNU parallel again")
    p.add_argument("--no-build", action="store_true")
    a = p.parse_args(argv)
    a.raw_argv = argv
    if not a.vary:
        raise LabError("scripts/lab sweep: give at least one --vary KEY=V1,V2,...")
    if a.slurm and a.hosts:
        raise LabError("--slurm and --hosts: give one (a Slurm cluster places the cells itself)")
    if a.jobs < 0 or a.retries < 0:
        raise LabError("--jobs and --retries: must not be negative")
    grid = parse_vary(a.vary)
    if not a.no_build:
        install_and_build()
    if not os.access(binary("tools/rms_resim"), os.X_OK):
        raise LabError(f"{binary('tools/rms_resim')} is not built (drop --no-build)", 1)
    sessions = [Session(s) for s in a.sessions]
    if len({s.path for s in sessions}) != len(sessions):
        raise LabError("a session is given twice")
    check_designs(sessions, grid)
    a.workers = lab_workers(a.hosts, a.jobs) if a.hosts else None
    version = software_version()
    cells = make_cells(sessions, grid, version)
    sweep_dir = os.path.abspath(a.out or os.path.join(
        ROOT, "sessions", "sweep-" + time.strftime("%Y%m%dT%H%M%SZ", time.gmtime())))
    cache_dir = os.path.abspath(a.cache or os.path.join(ROOT, "sessions", "sweep-cache"))
    os.makedirs(sweep_dir, exist_ok=True)
    os.makedirs(cache_dir, exist_ok=True)
    write_manifest(os.path.join(sweep_dir, "cells.tsv"), cells)
    with open(os.path.join(sweep_dir, "sweep.json"), "w") as f:
        json.dump({"sessions": [s.path for s in sessions], "vary": [{"key": k, "values": v} for k, v in grid],
                   "software": version, "cache": cache_dir, "cells": len(cells)}, f, indent=2)
    cached = {c["index"]: c for c in cells if os.path.isfile(os.path.join(cache_dir, c["key"] + ".json"))}
    todo = [c for c in cells if c["index"] not in cached]
    say(f"sweep: {len(cells)} cells ({len(sessions)} sessions x "
        f"{len(cells) // len(sessions)} designs), {len(cached)} already in the cache {cache_dir}")
    if a.slurm:
        script, rerun = write_slurm(sweep_dir, cells, cache_dir, a)
        say(f"Slurm array job written: sbatch {script}")
        say(f"then, for the table: {rerun}")
        return 0
    t0 = time.monotonic()
    errors, retried = [], 0
    pending = todo
    for round_no in range(1, a.retries + 2):
        if not pending:
            break
        if round_no > 1:
            retried += len(pending)
            say(f"sweep: trying {len(pending)} failed cells again (try {round_no} of {a.retries + 1})")
        progress = Progress(len(cells), len(cells) - len(pending))
        results, errs = run_parallel(pending, sweep_dir, a, progress, round_no)
        errors += errs
        progress.show(end=True)
        still = []
        for c in pending:
            res = results.get(c["index"])
            if res is not None and "error" not in res:
                c.pop("error", None)
                tmp = os.path.join(cache_dir, c["key"] + ".json.tmp")
                with open(tmp, "w") as f:
                    json.dump(res, f)
                os.replace(tmp, os.path.join(cache_dir, c["key"] + ".json"))
            else:
                c["error"] = (res or {}).get("error") or "no result: its job failed before rms_resim ran " \
                    "(the host? see the joblog and the lines of GNU parallel below)"
                still.append(c)
        pending = still
    elapsed = time.monotonic() - t0
    rows = []
    for c in cells:
        res = None
        if "error" not in c:
            try:
                with open(os.path.join(cache_dir, c["key"] + ".json")) as f:
                    res = json.load(f)
            except (OSError, ValueError) as e:
                c["error"] = f"its cached result cannot be read ({e})"
        rows.append((c, res))
    failed = [c for c in cells if "error" in c]
    csv_path, html_path = sweep_table.write(sweep_dir, grid, rows)
    ran = len(todo) - len(failed)
    say(f"sweep: {ran} cells run in {elapsed:.2f} s"
        + (f" ({ran / elapsed:.1f} cells/s)" if ran and elapsed > 0 else "")
        + f", {len(cached)} from the cache, {retried} tries again, {len(failed)} failed")
    for c in failed:
        say(f"  cell {c['index']} FAILED ({os.path.basename(c['session'])} "
            f"{' '.join(f'{k}={v}' for k, v in c['sets'])}): {c['error']}")
    for e in errors[-5:]:
        say(f"  parallel: {e}")
    say(f"table: {csv_path}")
    say(f"page:  {html_path}")
    return 1 if failed else 0
