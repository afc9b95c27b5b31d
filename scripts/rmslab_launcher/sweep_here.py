"""A sweep's cells on this machine: one rms_resim --cells process, --jobs
cells at once on its threads (docs/sessions.md "Sweeps")."""
import contextlib
import os
import select
import signal
import subprocess

from .sweep_cells import CELL, Interrupted, MAX_JOBS, ResultLines, batch_timeout_s, cell_mode, cells_process


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
