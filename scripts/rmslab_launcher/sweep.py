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
"""
import argparse
import collections
import contextlib
import hashlib
import itertools
import json
import os
import select
import shlex
import shutil
import signal
import subprocess
import sys
import threading
import time
import tomllib

from . import sweep_cache, sweep_table
from .common import (BUILD, ROOT, LabError, binary, file_sha256, install_and_build, read_folder_json, read_toml,
                     replacing, require_session_file, say)

CELL = os.path.join(ROOT, "scripts", "sweep-cell")
NETNS_LOGIN = os.path.join(ROOT, "scripts", "rmslab_launcher", "netns-login")
# A login that stops answering part way (a host down, a link dropped) ends
# within a minute (ServerAlive), as one that never answers does (ConnectTimeout).
SSH_OPTIONS = "ssh -o BatchMode=yes -o ConnectTimeout=5 -o ServerAliveInterval=15 -o ServerAliveCountMax=4"
FAILED_SHOWN = 20  # failed cells named on the terminal (the table has them all)
PROBE_TIMEOUT_S = 10  # a login that runs `true`, as GNU parallel allows its own probes
MAX_JOBS = 256  # cells at once (rms_resim --cells --jobs takes up to this many)


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


def write_manifest(path, cells):
    """cells.tsv: INDEX, cache KEY, SESSION, KEY=VALUE... a line a cell
    (what scripts/sweep-cell MANIFEST INDEX reads); a closed-loop sweep's
    cell: INDEX, KEY and its rms_fly options (c["fields"]: sweep_closed.py)."""
    with replacing(path) as f:
        for c in cells:
            rest = c["fields"] if "fields" in c else [c["session"]] + [f"{k}={v}" for k, v in c["sets"]]
            f.write("\t".join([str(c["index"]), c["key"]] + rest) + "\n")


def lab_workers(labfile, jobs):
    """GNU parallel's ssh logins for a lab file's hosts ([sweep] hosts, or
    every distinct host of [hosts]; the file read strictly by rms_session
    labfile, as scripts/lab demo reads it), each with the command that
    checks it answers; the remote tree's sweep-cell and its build."""
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
            logins.append(Login(h, n, ":", None))
        elif h.startswith("netns:"):
            logins.append(Login(h, n, f"{NETNS_LOGIN} {h[6:]}", [NETNS_LOGIN, h[6:], "--", "true"]))
        else:  # ssh:[USER@]HOST (the reader allows nothing else)
            logins.append(Login(h, n, h[4:], shlex.split(SSH_OPTIONS) + [h[4:], "true"]))
    remote_root = lab["remote_root"] or ROOT
    return logins, os.path.join(remote_root, "scripts", "sweep-cell"), lab["remote_build"], per_host


class Login:
    """A lab host as GNU parallel's --sshlogin (jobs "N/" before the login,
    as the joblog's Host column does not show them), and the command (None:
    this machine) that logs in and runs `true` there."""

    def __init__(self, host, jobs, login, probe):
        self.host, self.login, self.probe = host, login, probe
        self.sshlogin = jobs + login


def probe_once(logins, timeout_s):
    """Each login's command started at once; {login: why} for those that
    did not answer within timeout_s (its exit code or the timeout, and
    the last line it printed). Every probe is killed however this ends."""
    procs, whys = {}, {}
    try:
        for login in logins:
            try:
                procs[login] = subprocess.Popen(login.probe, stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL,
                                                stderr=subprocess.PIPE, text=True, start_new_session=True)
            except OSError as e:
                whys[login] = str(e)
        deadline = time.monotonic() + timeout_s
        for login, p in procs.items():
            try:
                _, err = p.communicate(timeout=max(0.0, deadline - time.monotonic()))
            except subprocess.TimeoutExpired:
                whys[login] = f"no answer within {timeout_s:g} s"
                continue
            if p.returncode != 0:
                last = (err.strip().splitlines() or [""])[-1]
                whys[login] = f"the login exited {p.returncode}" + (f": {last}" if last else "")
    finally:
        for p in procs.values():
            if p.poll() is None:
                with contextlib.suppress(ProcessLookupError, PermissionError):
                    os.killpg(p.pid, signal.SIGKILL)
                p.wait()
    return whys


def answering(logins, tries=2, timeout_s=PROBE_TIMEOUT_S):
    """The logins of the hosts that answer: each logged in to at once, a
    host that does not tried once more. One that still does not is named,
    with why, and left out of this try (GNU parallel's own --filter-hosts is
    not used: when a host's answer to its probe comes back short, it stops
    the whole run with an internal error, "ncores missing", instead of
    leaving that host out)."""
    whys = {}
    pending = [login for login in logins if login.probe is not None]
    for _ in range(tries):
        whys = probe_once(pending, timeout_s)
        pending = [login for login in pending if login in whys]
        if not pending:
            break
    for login in pending:
        say(f"sweep: host {login.host} does not answer ({whys[login]}): left out of this try")
    return [login for login in logins if login not in pending], {login.host: whys[login] for login in pending}


class Progress:
    """A progress bar on a terminal; a line every tenth otherwise."""

    def __init__(self, total, done, cached):
        """done: cells with their result before this try (cached: of them,
        those that came from the cache)."""
        self.total, self.done, self.failed, self.t0 = total, done, 0, time.monotonic()
        self.start, self.cached, self.tty, self.last_tenth = done, cached, sys.stderr.isatty(), -1
        self.last_said = None
        self.show()

    def recovered(self, ok):
        """A cell that had failed, tried again."""
        if ok:
            self.failed -= 1
            self.show()

    def step(self, ok):
        self.done += 1
        self.failed += not ok
        self.show()

    def show(self, end=False):
        frac = self.done / self.total if self.total else 1.0
        rate = (self.done - self.start) / max(time.monotonic() - self.t0, 1e-9)
        bar = "#" * int(30 * frac) + "." * (30 - int(30 * frac))
        line = (f"sweep [{bar}] {self.done}/{self.total} cells ({self.cached} cached, "
                f"{self.failed} failed) {rate:.1f} cells/s")
        if self.tty:
            print("\r" + line + ("\n" if end else ""), end="", file=sys.stderr, flush=True)
        elif (end or int(10 * frac) != self.last_tenth) and line[:line.rindex(")")] != self.last_said:
            # (the end's line is not said again when only its rate is new)
            self.last_tenth, self.last_said = int(10 * frac), line[:line.rindex(")")]
            say(line)


def batch_size(cells, slots):
    """Cells a job: one rms_resim process re-simulates a batch (each
    session's log read once, no process started a cell), about two batches
    a job slot, so a slot that finishes first takes another while the
    other's last runs; at most 32. (Each of GNU parallel's --pipe jobs
    costs tens of ms here: 100 cells on 2 slots took 0.63 to 0.69 s in 4
    batches or 2, 0.76 to 0.81 s in 8, 0.92 to 0.99 s in 15.)"""
    return max(1, min(32, -(-cells // (2 * max(slots, 1)))))


# A batch's time limit (docs/sessions.md "Sweeps"): each of its cells
# CELL_S_BASE + CELL_S_A_MIB for each MiB of the largest log of the sweep
# (a cell re-simulates a 3.4 MiB, 63 s session in about 0.01 s here: this is
# hundreds of times that), and BATCH_S_BASE for the login and the process's
# start. RMSLAB_SWEEP_BATCH_TIMEOUT_S sets it in seconds instead.
CELL_S_BASE, CELL_S_A_MIB, BATCH_S_BASE = 2.0, 0.5, 30.0


def timeout_override():
    """RMSLAB_SWEEP_BATCH_TIMEOUT_S in seconds, None when unset or empty;
    checked before anything is made (GNU parallel checks its --timeout about
    once a second: less than 1 s is refused, as it would not be kept)."""
    env = os.environ.get("RMSLAB_SWEEP_BATCH_TIMEOUT_S", "").strip()
    if not env:
        return None
    try:
        value = float(env)
    except ValueError:
        value = float("nan")
    if not 1 <= value <= 1e6:
        raise LabError(f"RMSLAB_SWEEP_BATCH_TIMEOUT_S={env!r}: must be a number of seconds from 1 to 1000000 "
                       "(GNU parallel checks its --timeout about once a second)", 2)
    return value


def batch_timeout_s(todo, per_job):
    """The seconds after which GNU parallel stops a batch of per_job cells
    (--timeout) and tries it again (on another host, if there is one), or
    this machine's process that gave no line for that long is stopped: a
    host that stalls part way does not hold the sweep for ever."""
    value = timeout_override()
    if value is not None:
        return value
    if todo and "cell_s" in todo[0]:  # a closed-loop sweep's cells say their own
        return round(BATCH_S_BASE + per_job * max(c["cell_s"] for c in todo))
    mib = 0.0
    for s in {c["session"] for c in todo}:
        with contextlib.suppress(OSError):
            mib = max(mib, os.path.getsize(os.path.join(s, "lcmlog")) / 2**20)
    return round(BATCH_S_BASE + per_job * (CELL_S_BASE + CELL_S_A_MIB * mib))


class NoHostAnswers(Exception):
    """No host of the lab answered its login: why each did not."""


def parallel_command(args, joblog, todo):
    """GNU parallel's command line for the lab's hosts, the cells a job and
    its time limit: the cells' lines (cells.tsv's form) on its standard
    input, --pipe hands each job a batch of them. Raises NoHostAnswers when
    no host of the lab answers."""
    cells, env_build = len(todo), {}
    cmd = ["parallel", "--will-cite", "--pipe", "--line-buffer", "--halt", "never", "--joblog", joblog]
    logins, cell, remote_build, per_host = args.workers
    live, whys = answering(logins)
    if not live:
        raise NoHostAnswers("; ".join(f"{host}: {why}" for host, why in whys.items()))
    for login in live:
        cmd += ["--sshlogin", login.sshlogin]
    cmd += ["--ssh", SSH_OPTIONS]
    if per_host > 0:
        cmd += ["--jobs", str(per_host)]
    if len(live) > 1:
        # A batch that fails on one host (an error line, or no line) is
        # tried on another within the try.
        cmd += ["--retries", str(len(live))]
    if remote_build:
        env_build = {"RMSLAB_BUILD": remote_build}
    slots = len(live) * (per_host if per_host > 0 else 2)
    # Nothing of the user's in the command: GNU parallel reads {...} in it
    # as its replacement strings (check_parallel_paths refused braces in these).
    prefix = " ".join(f"{k}={shlex.quote(v)}" for k, v in env_build.items())
    template = f"{prefix} {shlex.quote(cell)} {cell_mode(args)}".strip()
    k = batch_size(cells, slots)
    timeout = batch_timeout_s(todo, k)
    return cmd + ["--timeout", f"{timeout:g}", "-N", str(k), template], k, timeout


def cell_mode(args):
    """scripts/sweep-cell's mode for the sweep's cells: --cells (re-simulations)
    or --fly-cells (a closed-loop sweep's flights)."""
    return getattr(args, "cell_mode", "--cells")


def check_parallel_paths(workers):
    """GNU parallel reads braces in its command as replacement strings (even
    perl code, {=...=}): the paths that go into it must have none."""
    paths = [CELL] + ([workers[1], workers[2]] if workers else [])
    for p in paths:
        if p and ("{" in p or "}" in p):
            raise LabError(f"{p}: a path with braces cannot go into GNU parallel's command "
                           "(it reads them as its replacement strings)")


def job_ends(joblog):
    """{job number: (host, exit code, signal, run time s)} of each job of
    the joblog (its last try)."""
    ends = {}
    with contextlib.suppress(OSError):
        with open(joblog) as f:
            next(f, None)  # the header
            for line in f:
                col = line.rstrip("\n").split("\t")
                if len(col) >= 8 and col[0].isdigit():
                    try:
                        runtime = float(col[3])
                    except ValueError:
                        runtime = 0.0
                    ends[int(col[0])] = (col[1], col[6], col[7], runtime)
    return ends


def why_no_line(todo, joblog, per_job, workers, timeout_s):
    """The reason of each cell of todo that had no line: its batch's end as
    the joblog tells it (job N got todo's lines (N-1)K+1..NK, in order)."""
    ends = job_ends(joblog)
    names = {login.login: login.host for login in workers[0]}
    for i, c in enumerate(todo):
        if "line" in c:
            continue
        job = i // per_job + 1
        if job not in ends:
            c["error"] = ("no result: its batch never ended (GNU parallel's joblog has no line for its job "
                          f"{job}: a host that did not answer? see GNU parallel's lines below, if any)")
            continue
        host, code, sig, runtime = ends[job]
        where = names.get(host, host)
        if sig != "0" and runtime >= timeout_s:
            c["error"] = (f"no result: its batch (GNU parallel's job {job}, on {where}) ran past its time limit "
                          f"({timeout_s:g} s) and was stopped (a host that stalled?)")
        elif code == "0" and sig == "0":
            c["error"] = (f"no result: its batch (GNU parallel's job {job}, on {where}) ended with exit code 0 "
                          "but gave no line for it (the job did not run the cells: see GNU parallel's lines "
                          "below, if any)")
        else:
            c["error"] = (f"no result: its batch (GNU parallel's job {job}, on {where}) ended with exit code "
                          f"{code}" + (f", signal {sig}" if sig != "0" else "") + " before this cell's line")


class ResultLines:
    """The cells' result lines ("INDEX<TAB>JSON") as they arrive: each
    cell's first usable line is its result (a batch tried again on another
    host says its cells again); a line that is no cell's is kept in errors."""

    def __init__(self, todo, progress, on_result, errors):
        self.by_index = {c["index"]: c for c in todo}
        self.done = set()
        self.progress, self.on_result, self.errors = progress, on_result, errors
        for c in todo:
            c.pop("line", None)

    def take(self, line):
        idx, _, payload = line.rstrip("\n").partition("\t")
        try:
            res, cell = json.loads(payload), self.by_index[int(idx)]
        except (ValueError, KeyError):
            self.errors.append(line.rstrip())
            return
        if cell["index"] in self.done:
            return
        first = "line" not in cell
        cell["line"] = True
        ok = self.on_result(cell, res)
        if ok:
            self.done.add(cell["index"])
        self.progress.step(ok) if first else self.progress.recovered(ok)

    def count_lost(self):
        """The progress of the cells that had no line (failed)."""
        for c in self.by_index.values():
            if "line" not in c:
                self.progress.step(False)


@contextlib.contextmanager
def cells_process(cmd, todo, sweep_dir, errors, stop, prefix=""):
    """A process (cmd) with the cells' lines (cells.tsv's form) on its
    standard input, each line of its standard error kept in errors (after
    prefix); stopped with stop(proc) when the block is left by an exception,
    waited for when it ends."""
    todo_file = os.path.join(sweep_dir, f"todo-{os.getpid()}.tsv")
    write_manifest(todo_file, todo)
    try:
        with open(todo_file) as cells_in:
            # RMSLAB_SWEEP names the sweep in the environment of what runs its cells (on this machine).
            proc = subprocess.Popen(cmd, stdin=cells_in, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                                    text=True, start_new_session=True,
                                    env=dict(os.environ, RMSLAB_SWEEP=sweep_dir))
        t = threading.Thread(target=lambda: errors.extend(prefix + line.rstrip() for line in proc.stderr),
                             daemon=True)
        t.start()
        try:
            yield proc
            proc.wait()
        except BaseException:
            stop(proc)
            raise
        t.join(timeout=5)
    finally:
        with contextlib.suppress(OSError):
            os.remove(todo_file)


def run_parallel(todo, sweep_dir, args, progress, round_no, on_result):
    """The cells through GNU parallel on the lab's hosts; on_result(cell,
    result) as each line arrives (so a sweep stopped part way keeps what it
    finished). Returns the lines GNU parallel wrote to its standard error."""
    if not shutil.which("parallel"):
        raise LabError("GNU parallel is not installed: run scripts/install-deps", 1)
    joblog = os.path.join(sweep_dir, f"joblog-{time.strftime('%Y%m%dT%H%M%S')}-{os.getpid()}-try{round_no}")
    try:
        cmd, per_job, timeout = parallel_command(args, joblog, todo)
    except NoHostAnswers as why:
        for c in todo:
            c["error"] = f"no host of {args.hosts} answered ({why})"
            progress.step(False)
        return []
    errors = []
    lines = ResultLines(todo, progress, on_result, errors)
    with cells_process(cmd, todo, sweep_dir, errors, stop_parallel, "parallel: ") as proc:
        for line in proc.stdout:
            lines.take(line)
    why_no_line(todo, joblog, per_job, args.workers, timeout)
    lines.count_lost()
    return errors


class Stalled(Exception):
    """No line came for the time limit."""


def lines_within(stream, limit_s):
    """A process's standard output line by line as each is written (text,
    the newline dropped); raises Stalled when nothing comes for limit_s."""
    fd, rest = stream.fileno(), b""
    while True:
        ready, _, _ = select.select([fd], [], [], limit_s)
        if not ready:
            raise Stalled()
        chunk = os.read(fd, 1 << 16)
        if not chunk:
            if rest:
                yield rest.decode("utf-8", "replace")
            return
        *whole, rest = (rest + chunk).split(b"\n")
        for line in whole:
            yield line.decode("utf-8", "replace")


def run_here(todo, sweep_dir, args, progress, on_result):
    """The cells on this machine: one rms_resim --cells process
    (scripts/sweep-cell --cells), --jobs cells at once on its threads
    (default: the CPUs this process may use); on_result(cell, result) as
    each line arrives. A process that writes no line for its time limit
    (a batch's, for the cells a CPU runs at once: more cells at once than
    CPUs share them, each taking longer) is stopped. Returns what it wrote
    to its standard error."""
    cpus = len(os.sched_getaffinity(0))
    jobs = args.jobs or min(MAX_JOBS, cpus)
    limit = batch_timeout_s(todo, -(-jobs // cpus))
    errors = []
    lines = ResultLines(todo, progress, on_result, errors)
    stalled = False
    with cells_process([CELL, cell_mode(args), "--jobs", str(jobs)], todo, sweep_dir, errors, stop_here) as proc:
        try:
            for line in lines_within(proc.stdout, limit):
                lines.take(line)
            proc.wait(timeout=limit)  # (its output closed, it ends)
        except (Stalled, subprocess.TimeoutExpired):
            stalled = True
            stop_here(proc)
    tool = "rms_fly" if cell_mode(args) == "--fly-cells" else "rms_resim"
    why = f"no result: its process on this machine ({tool} --cells) "
    if stalled:
        why += (f"ran past its time limit ({limit:g} s) and was stopped: no line came for that long "
                "(a cell that stalled?)")
    elif proc.returncode < 0:
        try:
            name = f" ({signal.Signals(-proc.returncode).name})"
        except ValueError:
            name = ""
        why += f"ended on signal {-proc.returncode}{name} before this cell's line"
    else:
        why += (f"ended with exit code {proc.returncode} before this cell's line"
                + (" (see its lines below)" if errors else ""))
    for c in todo:
        if "line" not in c:
            c["error"] = why
    lines.count_lost()
    return errors


def stop_here(proc):
    """The process running the cells on this machine stopped with its group:
    SIGTERM, then SIGKILL to what is left after 5 s (at once, when a Ctrl-C
    or signal comes while it waits: that interruption is raised again once
    the process is stopped)."""
    interrupted = None
    for sig in (signal.SIGTERM, signal.SIGKILL):
        with contextlib.suppress(ProcessLookupError, PermissionError):
            os.killpg(proc.pid, sig)
        try:
            proc.wait(timeout=5)
            break
        except subprocess.TimeoutExpired:
            pass
        except Interrupted as e:
            interrupted = e
    if interrupted:
        raise interrupted


def stop_parallel(proc):
    """GNU parallel stopped with the cells it runs: its SIGINT (it sends its
    --termseq to each job's process group; a job on another host ends when
    its login does), then SIGKILL to what is left of its group."""
    with contextlib.suppress(ProcessLookupError):
        proc.send_signal(signal.SIGINT)
    interrupted = None
    try:
        proc.wait(timeout=10)
    except subprocess.TimeoutExpired:
        pass
    except Interrupted as e:  # (another signal: on at once, and raised again at the end)
        interrupted = e
    with contextlib.suppress(ProcessLookupError, PermissionError):
        os.killpg(proc.pid, signal.SIGKILL)
    try:
        proc.wait()
    except Interrupted as e:
        interrupted = e
        proc.wait()
    if interrupted:
        raise interrupted


def write_slurm(sweep_dir, cells, cache_dir, rerun, cell_args=""):
    """A Slurm array job: task N runs cell N of cells.tsv and stores its
    result in the cache; `scripts/lab sweep ... --cached-only` afterwards
    makes the table from the cache. cell_args: scripts/sweep-cell's mode
    before the manifest ("--fly": a closed-loop sweep's cells)."""
    if any(c.isspace() for c in sweep_dir + cache_dir + ROOT + BUILD):
        raise LabError("--slurm: the sweep's folder, the cache and the tree must have no spaces in their "
                       "paths (#SBATCH lines cannot quote them)")
    script = os.path.join(sweep_dir, "sweep.sbatch")
    manifest = os.path.join(sweep_dir, "cells.tsv")
    with replacing(script) as f:
        f.write(f"""#!/bin/sh
# A Slurm array job of {len(cells)} cells (docs/sessions.md "Sweeps"), written by scripts/lab sweep --slurm.
#   sbatch {shlex.quote(script)}
# then, when it has run, the table (every cell from the cache, nothing run here):
#   {rerun}
#SBATCH --job-name=rmslab-sweep
#SBATCH --array=1-{len(cells)}
#SBATCH --cpus-per-task=1
#SBATCH --output={os.path.join(sweep_dir, 'slurm-%A_%a.out')}
export RMSLAB_BUILD={shlex.quote(BUILD)}
exec {shlex.quote(CELL)} {cell_args + " " if cell_args else ""}{shlex.quote(manifest)} \\
  "$SLURM_ARRAY_TASK_ID" --store {shlex.quote(cache_dir)}
""")
    os.chmod(script, 0o755)
    return script


def rerun_command(a, sessions, sweep_dir, cache_dir):
    """The command that makes the table from the cache: absolute paths, every option spelled out."""
    argv = [os.path.join(ROOT, "scripts", "lab"), "sweep"] + [s.path for s in sessions]
    for k, vals in a.grid:
        argv += ["--vary", f"{k}={','.join(vals)}"]
    argv += ["--out", sweep_dir, "--cache", cache_dir, "--cached-only", "--no-build"]
    return " ".join(shlex.quote(x) for x in argv)


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
    """The missing cells through GNU parallel, tried again up to --retries
    times; each result cached as it arrives. Returns (tries again, errors)."""
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


class Interrupted(Exception):
    def __init__(self, signum):
        super().__init__(signal.Signals(signum).name)
        self.signum, self.name = signum, signal.Signals(signum).name


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
