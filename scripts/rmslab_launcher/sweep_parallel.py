"""A sweep's cells on a lab's hosts (--hosts LABFILE) through GNU parallel
(Debian's `parallel`: its ssh logins; a "netns:NAME" host through
scripts/rmslab_launcher/netns-login), in batches, one rms_resim --cells a
batch; hosts that do not answer are left out and said (docs/sessions.md
"Sweeps")."""
import contextlib
import json
import os
import shlex
import shutil
import signal
import subprocess
import time

from .common import ROOT, LabError, binary, say
from .sweep_cells import CELL, Interrupted, ResultLines, batch_timeout_s, cell_mode, cells_process


NETNS_LOGIN = os.path.join(ROOT, "scripts", "rmslab_launcher", "netns-login")


# A login that stops answering part way (a host down, a link dropped) ends
# within a minute (ServerAlive), as one that never answers does (ConnectTimeout).
SSH_OPTIONS = "ssh -o BatchMode=yes -o ConnectTimeout=5 -o ServerAliveInterval=15 -o ServerAliveCountMax=4"


PROBE_TIMEOUT_S = 10  # a login that runs `true`, as GNU parallel allows its own probes


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


def batch_size(cells, slots):
    """Cells a job: one rms_resim process re-simulates a batch (each
    session's log read once, no process started a cell), about two batches
    a job slot, so a slot that finishes first takes another while the
    other's last runs; at most 32. (Each of GNU parallel's --pipe jobs
    costs tens of ms here: 100 cells on 2 slots took 0.63 to 0.69 s in 4
    batches or 2, 0.76 to 0.81 s in 8, 0.92 to 0.99 s in 15.)"""
    return max(1, min(32, -(-cells // (2 * max(slots, 1)))))


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
