"""The session's processes, started, watched, restarted and stopped
(docs/sessions.md "The launcher", "Faults").

Each process runs in a process group of its own (its own session), so a
signal to the launcher's terminal does not reach it and it is stopped as a
group. Nothing outlives the launcher, even when it is killed with SIGKILL:
- each process's standard input is a pipe whose other end only the launcher
  holds (its "lifeline"): rmslab's processes stop when it closes
  (RMSLAB_LIFELINE=stdin, transport/include/rms/transport/process.h WatchLifeline);
- each gets the parent-death signal SIGTERM (prctl), for lcm-logger and
  ffmpeg's parent;
- a reaper, a small process of its own session started first, holds a
  lifeline too: when the launcher dies without saying "done", it stops every
  process group the launcher recorded in run/children and writes the
  session's summary (rmslab_launcher/reaper.py).

A process that exits before it is ready, or with code 2 (a usage or
configuration error), is not restarted: its message is shown and the session
stops. One that dies mid-session (a signal, a crash) is restarted at once,
then with a growing delay, at most MAX_RESTARTS times in RESTART_WINDOW_S.
"""
import ctypes
import json
import os
import signal
import subprocess
import sys
import time

from .common import ROOT, say, write_run_file

MAX_RESTARTS = 5
RESTART_WINDOW_S = 60.0
READY_TIMEOUT_S = 30.0
STOP_TIMEOUT_S = 5.0

_libc = ctypes.CDLL(None, use_errno=True)
_PR_SET_PDEATHSIG = 1


def _child_setup(launcher_pid):
    def setup():
        _libc.prctl(_PR_SET_PDEATHSIG, signal.SIGTERM, 0, 0, 0)
        if os.getppid() != launcher_pid:  # the launcher died before prctl took
            os._exit(1)
    return setup


def log_tail(path, lines=12):
    try:
        with open(path, errors="replace") as f:
            text = f.read().splitlines()
    except OSError:
        return []
    # The log's error lines first, else its last lines.
    errors = [line for line in text if "[error]" in line or "rror" in line.split("]")[-1][:60]]
    return (errors or text)[-lines:]


class Spec:
    """What to run: name, host, argv (without the host's wrapping), env,
    the log file, how to tell it is ready, and how it is supervised."""

    def __init__(self, name, host, argv, log_path, env=None, ready=None, restart=True, tty=False, lifeline=True,
                 remote_run=None, next_argv=None, pilot=False, may_restart=None):
        self.name, self.host, self.argv, self.log_path = name, host, list(argv), log_path
        self.env = dict(env or {})
        self.ready = ready          # callable(child) -> bool; None: ready at once
        self.restart = restart
        self.tty = tty              # inherits the terminal and the launcher's process group (flying by hand)
        self.lifeline = lifeline and not tty
        self.remote_run = remote_run
        self.next_argv = next_argv  # callable(n) -> argv for restart n (the recorder's next part)
        self.pilot = pilot          # the operator station: its end is the session's end
        self.may_restart = may_restart  # callable() -> None, or why the session must stop instead


class Child:
    def __init__(self, spec):
        self.spec = spec
        self.popen = None
        self.lifeline_w = None
        self.n = 0                  # restarts so far
        self.ready = False
        self.started_at = 0.0
        self.down_at = None
        self.last_rc = None
        self.restart_times = []
        self.pending_restart_at = None
        self.exit_code = None       # final

    @property
    def pid(self):
        return self.popen.pid if self.popen else None

    def running(self):
        return self.popen is not None and self.popen.poll() is None


class Supervisor:
    def __init__(self, run_dir, session_env):
        self.run_dir = run_dir
        self.session_env = dict(session_env)
        self.children = {}
        self.order = []
        self.stopping = False
        self.fatal = None           # (message, code): the session must stop
        self.events = []            # lines said while running
        self.reaper = None
        self.reaper_argv = None
        self.pilot_done = False
        self.interrupted = False    # a signal came: stop waiting, stop the session

    # ---- the reaper ----
    def start_reaper(self, session_dir, summary_argv):
        self.reaper_args = (session_dir, summary_argv)
        env = dict(os.environ)
        env["PYTHONPATH"] = os.path.join(ROOT, "scripts") + os.pathsep + env.get("PYTHONPATH", "")
        log = open(os.path.join(session_dir, "logs", "reaper.log"), "ab")
        self.reaper = subprocess.Popen(
            [sys.executable, "-m", "rmslab_launcher.reaper", "--session", session_dir, "--launcher-pid",
             str(os.getpid()), "--summary", json.dumps(summary_argv)],
            stdin=subprocess.PIPE, stdout=log, stderr=subprocess.STDOUT, start_new_session=True, env=env)
        log.close()

    def finish_reaper(self):
        if self.reaper and self.reaper.poll() is None:
            try:
                self.reaper.stdin.write(b"done\n")
                self.reaper.stdin.close()
            except OSError:
                pass
            try:
                self.reaper.wait(5)
            except subprocess.TimeoutExpired:
                self.reaper.kill()

    # ---- starting ----
    def add(self, spec):
        c = Child(spec)
        self.children[spec.name] = c
        self.order.append(spec.name)
        self._launch(c)
        return c

    def _launch(self, c):
        s = c.spec
        env = dict(self.session_env)
        env.update(s.env)
        env["RMSLAB_RESTART"] = str(c.n)
        if s.lifeline:
            env["RMSLAB_LIFELINE"] = "stdin"
        argv = s.next_argv(c.n) if (s.next_argv and c.n > 0) else s.argv
        cmd = s.host.wrap(argv, env, s.remote_run, s.name)
        # A restart must not be taken as ready from the killed run's ready
        # file (nor its pid read from it: the summary would then refuse every
        # message of the new run as not the session's process).
        try:
            os.remove(os.path.join(self.run_dir, f"{s.name}.ready"))
        except FileNotFoundError:
            pass
        except OSError as e:
            say(f"could not remove {s.name}'s old ready file ({e.strerror})")
        full_env = dict(os.environ)
        full_env.update(env)
        stdin = None
        r = None
        if s.lifeline:
            r, c.lifeline_w = os.pipe()
            stdin = r
        elif not s.tty:
            stdin = subprocess.DEVNULL
        log = open(s.log_path, "ab")
        # By hand the station keeps the terminal: its output is the screen, its log the file.
        out = None if s.tty else log
        c.popen = subprocess.Popen(cmd, stdin=stdin, stdout=out, stderr=log, env=full_env,
                                   start_new_session=not s.tty, preexec_fn=_child_setup(os.getpid()))
        log.close()
        if r is not None:
            os.close(r)
        c.ready = False
        c.started_at = time.time()
        write_run_file(os.path.join(self.run_dir, f"{s.name}.pid"), f"{c.pid}\n", append=False)
        write_run_file(os.path.join(self.run_dir, "children"),
                       f"{s.name} {c.pid} {s.host.spec} {1 if s.host.via_sudo else 0} {s.remote_run or '-'}\n")

    def wait_ready(self, names, timeout_s=READY_TIMEOUT_S):
        """Until each is ready. Returns None, or the message saying which
        exited at start or was not ready in time, with its log."""
        end = time.time() + timeout_s
        while time.time() < end:
            if self.stopping or self.interrupted:
                return None
            pending = []
            for n in names:
                c = self.children[n]
                if not c.ready and c.spec.ready and c.spec.ready(c):
                    self._became_ready(c)
                if not c.spec.ready:
                    c.ready = True
                if not c.ready:
                    rc = c.popen.poll()
                    if rc is not None:
                        c.exit_code = rc
                        return self._exited_at_start(c, rc)
                    pending.append(n)
            if not pending:
                return None
            time.sleep(0.05)
        lines = [f"{', '.join(pending)} not ready within {timeout_s:.0f} s; the log{'s' if len(pending) > 1 else ''}:"]
        for n in pending:
            lines += [f"  {n}: {line}" for line in log_tail(self.children[n].spec.log_path, 6)]
        return "\n".join(lines)

    def _exited_at_start(self, c, rc):
        what = "with a usage or configuration error" if rc == 2 else f"with code {rc}"
        lines = [f"{c.spec.name} exited at start {what}; its log ({c.spec.log_path}):"]
        lines += ["  " + line for line in log_tail(c.spec.log_path)]
        return "\n".join(lines)

    def _became_ready(self, c):
        c.ready = True
        pid = c.pid
        ready_file = os.path.join(self.run_dir, f"{c.spec.name}.ready")
        try:
            with open(ready_file) as f:
                pid = int(json.load(f).get("pid", pid))
        except (OSError, ValueError):
            pass
        write_run_file(os.path.join(self.run_dir, "pids"), f"{c.spec.name} {pid}\n")
        if c.n > 0:
            write_run_file(os.path.join(self.run_dir, "restarts"),
                           f"{c.spec.name} {c.n} {c.last_rc} {c.down_at:.6f} {time.time():.6f}\n")

    def wake_latency_state(self, name):
        """What `name`'s CPU wake-latency request came to (its ready file's
        "cpu_wake_latency"; for a process on another host, its log's last
        "cpu wake latency:" line), or None when it did not say."""
        c = self.children.get(name)
        if c is None:
            return None
        try:
            with open(os.path.join(self.run_dir, f"{name}.ready")) as f:
                state = json.load(f).get("cpu_wake_latency")
            if isinstance(state, str):
                return state
        except (OSError, ValueError, AttributeError):
            pass
        try:
            with open(c.spec.log_path, errors="replace") as f:
                said = [line for line in f if "] cpu wake latency: " in line]
        except OSError:
            return None
        if not said:
            return None
        state = said[-1].split("] cpu wake latency: ", 1)[1].strip()
        return state.split(": frames reach the pixels later")[0]

    # ---- watching ----
    def poll(self):
        """One look at every process: restarts what died, notes what is
        ready, sets self.fatal when the session must stop."""
        now = time.time()
        if self.reaper is not None and self.reaper.poll() is not None and not self.stopping:
            # Without it a kill -9 of the launcher would leave the session running.
            self.note(f"the reaper (which stops the session if the launcher is killed) ended with code "
                      f"{self.reaper.returncode}: starting it again")
            self.start_reaper(*self.reaper_args)
        for name in self.order:
            c = self.children[name]
            if c.pending_restart_at is not None:
                if now >= c.pending_restart_at and not self.stopping:
                    c.pending_restart_at = None
                    self._launch(c)
                continue
            if not c.ready and c.spec.ready and c.popen and c.popen.poll() is None and c.spec.ready(c):
                self._became_ready(c)
            rc = c.popen.poll() if c.popen else None
            if rc is None or self.stopping or c.exit_code is not None:
                continue
            self._ended(c, rc, now)

    def _ended(self, c, rc, now):
        name = c.spec.name
        if c.lifeline_w is not None:
            os.close(c.lifeline_w)
            c.lifeline_w = None
        # The pilot ends the session when it ends by itself, or by the
        # person's or the terminal's signal; killed otherwise, it is restarted.
        if c.spec.pilot and (rc >= 0 or -rc in (signal.SIGINT, signal.SIGTERM, signal.SIGHUP)):
            c.exit_code = rc if rc >= 0 else 128 - rc
            self.pilot_done = True
            return
        if c.spec.pilot:
            c.ready = True  # a pilot killed mid-flight is restarted whatever its ready file says
        if not c.ready:
            c.exit_code = rc
            self.fatal = (self._exited_at_start(c, rc), 2 if rc == 2 else 1)
            return
        refusal = c.spec.may_restart() if c.spec.may_restart else None
        if refusal:
            c.exit_code = rc if rc >= 0 else 128 - rc
            self.fatal = (refusal, 1)
            return
        if rc == 2 or not c.spec.restart or rc == 0:
            c.exit_code = rc
            why = "a usage or configuration error" if rc == 2 else f"code {rc}"
            tail = "\n".join("  " + line for line in log_tail(c.spec.log_path))
            msg = f"{name} ended mid-session ({why}); its log:\n" + tail
            self.fatal = (msg, 2 if rc == 2 else 1)
            return
        c.restart_times = [t for t in c.restart_times if now - t < RESTART_WINDOW_S] + [now]
        if len(c.restart_times) > MAX_RESTARTS:
            c.exit_code = rc
            self.fatal = (f"{name} keeps failing ({MAX_RESTARTS} restarts within {RESTART_WINDOW_S:.0f} s, the last "
                          f"with code {rc}): stopping the session; its log:\n" +
                          "\n".join("  " + line for line in log_tail(c.spec.log_path)), 1)
            return
        c.n += 1
        c.last_rc = rc if rc >= 0 else 128 - rc
        c.down_at = now
        delay = 0.0 if len(c.restart_times) == 1 else min(4.0, 0.25 * 2 ** (len(c.restart_times) - 2))
        c.pending_restart_at = now + delay
        self.note(f"{name} ended with code {c.last_rc} mid-session; restarting it (restart {c.n}"
                  f"{f', in {delay:.2g} s' if delay else ''})")

    def note(self, line):
        self.events.append(line)
        say(line)

    # ---- stopping ----
    def stop(self, names, sig=signal.SIGINT, timeout_s=STOP_TIMEOUT_S):
        for n in names:
            c = self.children.get(n)
            if c and c.running():
                c.spec.host.signal(c.pid, sig, c.spec.remote_run, n)
        for n in names:
            c = self.children.get(n)
            if not c or not c.popen:
                continue
            try:
                rc = c.popen.wait(timeout_s)
            except subprocess.TimeoutExpired:
                say(f"{n} did not stop within {timeout_s:.0f} s; killing it")
                c.spec.host.signal(c.pid, signal.SIGKILL, c.spec.remote_run, n)
                try:
                    rc = c.popen.wait(5)
                except subprocess.TimeoutExpired:
                    rc = -9
            if c.exit_code is None:
                c.exit_code = rc if rc >= 0 else 128 - rc
            if c.lifeline_w is not None:
                os.close(c.lifeline_w)
                c.lifeline_w = None

    def record_exit_codes(self):
        lines = [f"{n} {self.children[n].exit_code}\n" for n in self.order if self.children[n].exit_code is not None]
        write_run_file(os.path.join(self.run_dir, "exit_codes"), "".join(lines))

    def begin_stop(self):
        self.stopping = True
        write_run_file(os.path.join(self.run_dir, "stopping"), "", append=False)
