"""What every runner of a sweep's cells shares (docs/sessions.md "Sweeps"):
the cell program, the manifest of cells a runner is given, the progress
line, the time a batch may take, and the reading of the result lines a
cells process prints. The runners: sweep_here.py (this machine's cores),
sweep_parallel.py (a lab's hosts through GNU parallel), sweep_slurm.py (a
Slurm array job)."""
import contextlib
import json
import os
import signal
import subprocess
import sys
import threading
import time

from .common import ROOT, LabError, replacing, say


CELL = os.path.join(ROOT, "scripts", "sweep-cell")


MAX_JOBS = 256  # cells at once (rms_resim --cells --jobs takes up to this many)


def write_manifest(path, cells):
    """cells.tsv: INDEX, cache KEY, SESSION, KEY=VALUE... a line a cell
    (what scripts/sweep-cell MANIFEST INDEX reads); a closed-loop sweep's
    cell: INDEX, KEY and its rms_fly options (c["fields"]: sweep_closed.py)."""
    with replacing(path) as f:
        for c in cells:
            rest = c["fields"] if "fields" in c else [c["session"]] + [f"{k}={v}" for k, v in c["sets"]]
            f.write("\t".join([str(c["index"]), c["key"]] + rest) + "\n")


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


def cell_mode(args):
    """scripts/sweep-cell's mode for the sweep's cells: --cells (re-simulations)
    or --fly-cells (a closed-loop sweep's flights)."""
    return getattr(args, "cell_mode", "--cells")


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


class Interrupted(Exception):
    def __init__(self, signum):
        super().__init__(signal.Signals(signum).name)
        self.signum, self.name = signum, signal.Signals(signum).name
