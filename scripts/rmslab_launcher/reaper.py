"""The reaper: started first by the launcher, in a session of its own, it
waits on its standard input. The launcher writes "done" there when it has
stopped everything itself. When the input closes without it -- the launcher
was killed, even with SIGKILL -- the reaper stops every process the launcher
recorded in SESSION/run/children (SIGINT, then SIGKILL after 5 s), records
that the launcher died, and writes the session's summary, so nothing is left
running and the session folder is whole (docs/sessions.md "The launcher").

    python3 -m rmslab_launcher.reaper --session DIR --launcher-pid PID --summary JSON_ARGV
"""
import argparse
import json
import os
import signal
import subprocess
import sys
import time

from .common import sudo_prefix, write_run_file
from .session import close_record, resimulate
from .hosts import SSH


def log(line):
    """A line in logs/reaper.log; a full disk does not stop the reaper."""
    try:
        print(line, flush=True)
    except OSError:
        pass


def children(run_dir):
    out = []
    try:
        with open(os.path.join(run_dir, "children")) as f:
            for line in f:
                parts = line.split()
                if len(parts) >= 5:
                    out.append((parts[0], int(parts[1]), parts[2], parts[3] == "1", parts[4]))
    except OSError:
        pass
    return out


def alive(pid):
    try:
        with open(f"/proc/{pid}/stat") as f:
            if f.read().rsplit(")", 1)[1].split()[0] == "Z":
                return False  # ended; only its parent's reaping is left
    except (OSError, IndexError):
        pass
    try:
        os.kill(pid, 0)
        return True
    except ProcessLookupError:
        return False
    except PermissionError:
        return True


def signal_child(name, pid, host, sudo, remote_run, sig):
    if host.startswith("ssh:"):
        if remote_run != "-":
            subprocess.run(SSH + [host[4:], f"kill -{int(sig)} $(cat {remote_run}/{name}.pid) 2>/dev/null"],
                           stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        # the ssh client, here
    if sudo:
        subprocess.run(sudo_prefix() + ["kill", f"-{int(sig)}", "--", f"-{pid}"], stdout=subprocess.DEVNULL,
                       stderr=subprocess.DEVNULL)
        return
    for kill in (lambda: os.killpg(pid, sig), lambda: os.kill(pid, sig)):
        try:
            kill()
            return
        except (ProcessLookupError, PermissionError):
            continue


def ours(pid, session_id, host, sudo):
    """True if the pid is still a process of this session: a local process
    must carry the session's id in its environment (RMSLAB_SESSION_ID), so a
    pid reused by something else since is never signalled. Processes behind
    sudo (namespace hosts) or ssh are taken by their entry."""
    if sudo or host != "localhost" or not session_id:
        return True
    try:
        with open(f"/proc/{pid}/environ", "rb") as f:
            return f"RMSLAB_SESSION_ID={session_id}".encode() in f.read().split(b"\0")
    except OSError:
        return False


def stop_all(kids, session_id):
    kids = [k for k in kids if alive(k[1]) and ours(k[1], session_id, k[2], k[3])]
    for name, pid, host, sudo, remote_run in kids:
        if alive(pid):
            log(f"  SIGINT to {name} (pid {pid}, {host})")
            signal_child(name, pid, host, sudo, remote_run, signal.SIGINT)
    end = time.time() + 5
    while time.time() < end and any(alive(k[1]) for k in kids):
        time.sleep(0.1)
    for name, pid, host, sudo, remote_run in kids:
        if alive(pid):
            log(f"  SIGKILL to {name} (pid {pid}): it did not stop")
            signal_child(name, pid, host, sudo, remote_run, signal.SIGKILL)


def reap(session, summary_argv):
    run_dir = os.path.join(session, "run")
    log(f"{time.strftime('%H:%M:%S')} the launcher is gone without stopping the session: stopping it")
    session_id = ""
    try:
        with open(os.path.join(session, "manifest.json")) as f:
            session_id = json.load(f).get("session_id", "")
    except (OSError, ValueError):
        pass
    kids = children(run_dir)
    # The pipeline first, the recorder last (it records everyone's last status).
    stop_all([k for k in kids if k[0] != "lcm-logger"], session_id)
    time.sleep(0.3)
    stop_all([k for k in kids if k[0] == "lcm-logger"], session_id)
    write_run_file(os.path.join(run_dir, "exit_codes"), "launcher 137\n")
    write_run_file(os.path.join(run_dir, "launcher_died"), f"{time.time():.6f}\n", append=False)
    # The journals of processes on ssh hosts, as the launcher would have
    # fetched them (docs/sessions.md "The record").
    for name, _, host, _, remote_run in kids:
        if host.startswith("ssh:") and remote_run != "-":
            subprocess.run(["scp", "-q", "-o", "BatchMode=yes", f"{host[4:]}:{remote_run}/journal/{name}.*.lcmlog",
                            os.path.join(session, "journal")], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    for note in close_record(session):
        log(f"{time.strftime('%H:%M:%S')} {note}")
    resimulate(session)  # its verdict into the summary (docs/sessions.md "Does it re-simulate")
    if summary_argv:
        r = subprocess.run(summary_argv, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
        if r.returncode != 0:
            log(f"{time.strftime('%H:%M:%S')} stopped; the summary could not be written: {r.stderr.strip()}")
            return
    log(f"{time.strftime('%H:%M:%S')} stopped; summary written")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--session", required=True)
    ap.add_argument("--launcher-pid", type=int, required=True)
    ap.add_argument("--summary", default="[]")
    a = ap.parse_args()
    signal.signal(signal.SIGINT, signal.SIG_IGN)  # a Ctrl-C is the launcher's to handle
    signal.signal(signal.SIGHUP, signal.SIG_IGN)
    data = b""
    while True:
        try:
            chunk = os.read(sys.stdin.fileno(), 64)
        except InterruptedError:
            continue
        if not chunk:
            break
        data += chunk
    if b"done" in data:
        return 0
    reap(a.session, json.loads(a.summary))
    return 0


if __name__ == "__main__":
    sys.exit(main())
