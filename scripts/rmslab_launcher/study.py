"""scripts/lab study: man-in-the-loop studies (docs/studies.md).

  scripts/lab study check STUDY [--json]      the study file checked, and every subject's order
  scripts/lab study run STUDY --subject NAME [--pilot by-hand|autopilot] [--trials N] [--dir DIR]
                        [--no-build] [demo options: --window --instructor --speed --lcm-url ...]
                                             that subject's next trials, one after another
  scripts/lab study status STUDY [--dir DIR] [--json]   what is done and what is left
  scripts/lab study report STUDY [--dir DIR] [--out DIR]  one table (CSV, JSON lines) and one page

A study's folder (default sessions/studies/NAME, --dir) holds the study file
as first run, the plan, each condition's configuration and bindings, the
study's journal (trials.jsonl) and a session folder a trial run under each
subject's folder. A run stopped part way resumes at the trial it stopped
in; a trial lost for a technical reason (a process that crashed, a session
that does not re-simulate, a run stopped part way) is marked lost, never
counted, and flown again.
"""
import argparse
import fcntl
import json
import os
import signal
import subprocess
import sys
import time
import tomllib

from .common import ROOT, LabError, file_sha256, install_and_build, read_folder_json, replacing, require_built, say
from .study_file import StudyFile

JOURNAL = "trials.jsonl"
DOCKED_S = 2.0  # by hand, a trial ends this long after docking (the autopilot's own)
MAX_LOST_IN_A_ROW = 3  # then something is wrong that flying again will not mend
PILOTS = ("by-hand", "autopilot")
# Demo options a trial passes on as given (the rest are the study's).
PASSED_FLAGS = ("--window", "--no-video")
PASSED_VALUES = ("--speed", "--lcm-url", "--channel-suffix", "--png-every", "--width", "--height", "--gl",
                 "--cpu-wake-latency-us", "--lab")


def run(argv):
    cmd = argv[0] if argv else "--help"
    if cmd in ("-h", "--help", "help"):
        print(__doc__.split("\n", 2)[2])
        return 0
    rest = argv[1:]
    if cmd == "check":
        return check(rest)
    if cmd == "run":
        return run_trials(rest)
    if cmd == "status":
        return status(rest)
    if cmd == "report":
        from . import study_report
        return study_report.run(rest)
    raise LabError(f"study: unknown command '{cmd}' (check, run, status or report; scripts/lab study --help)")


# ---- the study's folder ----
class StudyFolder:
    """DIR: study.toml (the file as first run), plan.json, conditions/NAME/,
    trials.jsonl, SUBJECT/SESSION folders."""

    def __init__(self, study, folder):
        self.study = study
        self.dir = os.path.abspath(folder or os.path.join(ROOT, "sessions", "studies", study.name))
        self.journal = os.path.join(self.dir, JOURNAL)
        if os.path.lexists(self.dir) and not os.path.isdir(self.dir):
            raise LabError(f"--dir {self.dir}: not a folder (a study's folder holds its trials)")

    def exists(self):
        return os.path.isfile(os.path.join(self.dir, "study.toml"))

    def subject_dir(self, subject):
        """A subject's sessions: trials/SUBJECT (apart from the folder's own files, whatever the name)."""
        return os.path.join(self.dir, "trials", subject)

    def in_flight(self, subject):
        """A study run holds the subject's lock now: its started run is under way, not lost."""
        path = os.path.join(self.subject_dir(subject), ".lock")
        if not os.path.exists(path):
            return False
        with open(path, "a+") as f:
            try:
                fcntl.flock(f, fcntl.LOCK_EX | fcntl.LOCK_NB)
            except BlockingIOError:
                return True
            fcntl.flock(f, fcntl.LOCK_UN)
        return False

    def open(self, create):
        """Checks the folder's study file against this one; makes the folder
        (the conditions written and checked) when create and it is new."""
        if self.exists():
            self._same_study(update=True)
        elif not create:
            raise LabError(f"{self.dir}: no trial of study '{self.study.name}' has been run "
                           f"(scripts/lab study run {self.study.path} --subject NAME)")
        else:
            os.makedirs(os.path.join(self.dir, "conditions"), exist_ok=True)
            self._write_conditions()
            self._write_plan_and_copy()
        self.sha256 = file_sha256(os.path.join(self.dir, "study.toml"))

    def _write_plan_and_copy(self):
        """plan.json and study.toml, the study file's copy, from this file."""
        with replacing(os.path.join(self.dir, "plan.json")) as f:
            json.dump({"study": self.study.name, "order": self.study.order, "seed": self.study.seed,
                       "subjects": self.study.plan()}, f, indent=1)
        with replacing(os.path.join(self.dir, "study.toml"), encoding="utf-8") as f:
            f.write(self.study.text.decode())

    def _write_conditions(self):
        for c in self.study.conditions:
            self.study.write_condition(c, os.path.join(self.dir, "conditions", c["name"]))

    def _same_study(self, update):
        """A study file changed after its first trial would make its trials
        incomparable: refused, unless only subjects were added at the end
        (their orders follow on; no earlier subject's changes)."""
        with open(os.path.join(self.dir, "study.toml"), "rb") as f:
            first = f.read()
        if first == self.study.text:
            return
        a, b = tomllib.loads(first.decode()), tomllib.loads(self.study.text.decode())
        old_subjects = a["study"].pop("subjects", [])
        new_subjects = b["study"].pop("subjects", [])
        a["study"].pop("description", None)
        b["study"].pop("description", None)
        if a != b or new_subjects[:len(old_subjects)] != old_subjects:
            raise LabError(f"{self.study.path} is not the study file its folder {self.dir} was begun with "
                           f"(study.toml there): its trials were flown under that one. Only subjects may be "
                           f"added, at the end of study.subjects. Restore the file, or begin a new study "
                           f"(another study.name, or --dir)")
        added = new_subjects[len(old_subjects):]
        if not added:
            # Comments or the description only: the folder keeps the file
            # its trials began with (and its SHA-256 in their manifests).
            if update and not getattr(self, "_said_same", False):
                self._said_same = True
                say(f"note: {self.study.path} differs from the study's own copy ({self.dir}/study.toml) only in "
                    f"comments or its description: the copy is kept")
            return
        if not update:
            return
        # Subjects added: the plan and the folder's copy follow the file.
        self._write_plan_and_copy()
        say(f"study file: subjects added ({', '.join(added)}); the folder follows it")

    # ---- the journal ----
    def events(self):
        if not os.path.exists(self.journal):
            return []
        out = []
        with open(self.journal) as f:
            for n, line in enumerate(f, 1):
                try:
                    e = json.loads(line)
                    if isinstance(e, dict):
                        out.append(e)
                except ValueError:
                    say(f"{self.journal}: line {n} is not JSON: left out (a line cut short by a crash or a full "
                        f"disk)")
        return out

    def append(self, event):
        event = dict(event, utc=time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime()))
        with open(self.journal, "a") as f:
            f.write(json.dumps(event) + "\n")
            f.flush()
            os.fsync(f.fileno())

    def runs(self, subject):
        """{trial: [run, ...]}, each run {run, session, status (started, done,
        lost, stopped), why, outcome, ...} from the journal."""
        out = {}
        for e in self.events():
            if e.get("subject") != subject or not isinstance(e.get("trial"), int):
                continue
            runs = out.setdefault(e["trial"], [])
            if e.get("event") == "start":
                runs.append({"run": e.get("run"), "session": e.get("session"), "status": "started"})
            elif e.get("event") == "end":
                for r in runs:
                    if r["run"] == e.get("run"):
                        r.update({k: v for k, v in e.items() if k not in ("event", "utc")})
        return out


# ---- check ----
def check(argv):
    p = argparse.ArgumentParser(prog="scripts/lab study check", description="The study file checked (every "
                                "condition's design and bindings as the processes check them) and every "
                                "subject's order printed.")
    p.add_argument("study")
    p.add_argument("--json", action="store_true", help="the plan as JSON on standard output")
    p.add_argument("--no-build", action="store_true")
    a = p.parse_args(argv)
    s = StudyFile(a.study)
    build(a.no_build)
    s.check_designs()
    plan = s.plan()
    if a.json:
        print(json.dumps({"study": s.name, "order": s.order, "seed": s.seed, "subjects": plan}, indent=1))
        return 0
    say(f"study '{s.name}': {plural(len(s.conditions), 'condition')}, {plural(len(s.subjects), 'subject')}, "
        f"{s.practice} practice "
        f"and {s.measured} measured trials a condition, at most {s.limit_s:g} s each; order {s.order}"
        + (f", seed {s.seed}" if s.seed is not None else ""))
    for c in s.conditions:
        say(f"  condition {c['name']}: {describe(c)}")
    for subject, trials in plan.items():
        say(f"  {subject}: " + ", ".join(dict.fromkeys(t["condition"] for t in trials)))
    if s.balance_note():
        say("note: " + s.balance_note())
    return 0


def plural(n, word):
    return f"{n} {word}" if n == 1 else f"{n} {word}s"


def describe(c):
    sets = "; ".join(f"{k} = {v}" for k, v in c["set"].items()) or "the study's configuration"
    cams = " ".join(str(x) for x in c["cameras"])
    lesson = f"; lesson {os.path.basename(c['lesson'])}" if c.get("lesson") else ""
    return f"{sets}; cameras {cams}; {c['control'].replace('_', ' ')}{lesson}"


def build(no_build):
    if not no_build:
        install_and_build()
    require_built("tools/rms_session", "operator_station/operator_station")


# ---- status ----
def progress(folder, subject, trials):
    """Each planned trial with its runs, and the next to fly (None: all done).
    A run started and not ended is lost -- unless a study run holds the
    subject now: then it is the trial under way."""
    runs = folder.runs(subject)
    if folder.in_flight(subject):
        for rs in runs.values():
            for r in rs:
                if r["status"] == "started":
                    r["status"] = "under way"
    rows, nxt = [], None
    for t in trials:
        rs = runs.get(t["trial"], [])
        done = next((r for r in rs if r["status"] == "done"), None)
        rows.append(dict(t, runs=rs, done=done is not None, outcome=(done or {}).get("outcome"),
                         lost=sum(r["status"] in ("lost", "started") for r in rs)))
        if done is None and nxt is None:
            nxt = t
    return rows, nxt


def status(argv):
    p = argparse.ArgumentParser(prog="scripts/lab study status", description="What each subject has flown "
                                "and what is left.")
    p.add_argument("study")
    p.add_argument("--dir", help="the study's folder (default sessions/studies/NAME)")
    p.add_argument("--json", action="store_true")
    a = p.parse_args(argv)
    s = StudyFile(a.study)
    folder = StudyFolder(s, a.dir)
    if folder.exists():
        folder._same_study(update=False)
    elif not a.json:
        say(f"no trial of study '{s.name}' has been run in {folder.dir} (no study.toml there)")
    plan = s.plan()
    out = {"study": s.name, "folder": folder.dir, "subjects": {}}
    for subject, trials in plan.items():
        rows, nxt = progress(folder, subject, trials)
        out["subjects"][subject] = {
            "planned": len(rows), "done": sum(r["done"] for r in rows),
            "measured_done": sum(r["done"] and r["kind"] == "measured" for r in rows),
            "lost_runs": sum(r["lost"] for r in rows),
            "next": None if nxt is None else {k: nxt[k] for k in ("trial", "condition", "kind", "index")},
            "trials": [{k: r[k] for k in ("trial", "condition", "kind", "index", "done", "outcome", "lost")}
                       | {"sessions": [x.get("session") for x in r["runs"]]} for r in rows]}
    if a.json:
        print(json.dumps(out, indent=1))
        return 0
    say(f"study '{s.name}' ({folder.dir}):")
    total = sum(v["planned"] for v in out["subjects"].values())
    done = sum(v["done"] for v in out["subjects"].values())
    for subject, v in out["subjects"].items():
        nxt = v["next"]
        left = "done" if nxt is None else \
            f"next: trial {nxt['trial']}, {nxt['condition']} ({nxt['kind']} {nxt['index']})"
        lost = f", {v['lost_runs']} lost run(s) flown again" if v["lost_runs"] else ""
        say(f"  {subject}: {v['done']} of {v['planned']} trials ({v['measured_done']} measured){lost}; {left}")
    say(f"{done} of {total} trials done, {total - done} left")
    return 0


# ---- run ----
def parse_run_args(argv):
    p = argparse.ArgumentParser(prog="scripts/lab study run", description="Runs a subject's next trials, one "
                                "after another, each a session with its condition's configuration, tagged "
                                "with the study, condition, subject and trial.")
    p.add_argument("study")
    p.add_argument("--subject", required=True)
    p.add_argument("--pilot", default="by-hand", choices=PILOTS,
                   help="by-hand: the subject flies (default); autopilot: a virtual subject, for a dry run")
    p.add_argument("--trials", type=int, help="at most this many trials now (default: until the subject's last)")
    p.add_argument("--dir", help="the study's folder (default sessions/studies/NAME)")
    p.add_argument("--no-build", action="store_true")
    p.add_argument("--instructor", nargs="?", const="8080", metavar="PORT")
    for f in PASSED_FLAGS:
        p.add_argument(f, action="store_true")
    for f in PASSED_VALUES:
        p.add_argument(f)
    a = p.parse_args(argv)
    if a.trials is not None and a.trials < 1:
        raise LabError(f"--trials {a.trials}: 1 or more")
    return a


def demo_args(a):
    out = []
    for f in PASSED_FLAGS:
        if getattr(a, f[2:].replace("-", "_")):
            out.append(f)
    for f in PASSED_VALUES:
        v = getattr(a, f[2:].replace("-", "_"))
        if v is not None:
            out += [f, v]
    if a.instructor is not None:
        out += ["--instructor", a.instructor]
    return out


class Subject:
    """One subject's trials in one study run: the lock, the next trial, a
    trial run and judged."""

    def __init__(self, folder, a):
        self.folder, self.a, self.study = folder, a, folder.study
        self.name = a.subject
        self.trials = self.study.plan()[self.name]
        os.makedirs(folder.subject_dir(self.name), exist_ok=True)
        self.lock = open(os.path.join(folder.subject_dir(self.name), ".lock"), "a+")
        try:
            fcntl.flock(self.lock, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            raise LabError(f"subject '{self.name}' of study '{self.study.name}' is being run by another "
                           f"'scripts/lab study run' now; one at a time", 1)

    def settle_unended(self):
        """A run the journal started and never ended: the study was stopped
        during it (killed, the machine down). Its session, still stopping,
        is waited for (its launcher holds the trial lock until it exits);
        then it is marked lost, to be flown again."""
        unended = [(trial, r) for trial, runs in self.folder.runs(self.name).items() for r in runs
                   if r["status"] == "started"]
        if unended:
            wait_for_trial_lock(self.trial_lock_path())
        for trial, r in unended:
            self.folder.append({"event": "end", "subject": self.name, "trial": trial, "run": r["run"],
                                "session": r.get("session") or "", "status": "lost",
                                "why": "the study run stopped during it (no end recorded)"})
            say(f"trial {trial} (run {r['run']}) was under way when the study run stopped: marked lost, "
                f"to be flown again")

    def trial_lock_path(self):
        return os.path.join(self.folder.subject_dir(self.name), ".trial.lock")

    def next_trial(self):
        return progress(self.folder, self.name, self.trials)[1]

    def fly(self, t):
        """Runs trial t once: its session, judged. Returns the end event."""
        runs = self.folder.runs(self.name).get(t["trial"], [])
        run_no = 1 + max([r.get("run") or 0 for r in runs] or [0])
        base = f"{t['trial']:02d}-{t['condition']}-{t['kind']}-{t['index']}"
        session = os.path.join(self.folder.subject_dir(self.name), base + ("" if run_no == 1 else f".run{run_no}"))
        if os.path.lexists(session):
            raise LabError(f"{session} exists, and the study's journal has no such run: left as it is; move it "
                           f"away to go on")
        cond = os.path.join(self.folder.dir, "conditions", t["condition"])
        cmd = [os.path.join(ROOT, "scripts", "lab"), "demo", "--no-build", "--out", session,
               "--config", os.path.join(cond, "config.toml"), "--limit-s", repr(float(self.study.limit_s)),
               "--subject", self.name, "--note", f"study {self.study.name}: trial {t['trial']} of "
               f"{len(self.trials)}, {t['condition']}, {t['kind']} {t['index']} of {t['of']}",
               "--study", self.study.name, "--study-sha256", self.folder.sha256, "--condition", t["condition"],
               "--trial", str(t["trial"]), "--trial-kind", t["kind"], "--trial-run", str(run_no)]
        if os.path.exists(os.path.join(cond, "lesson.toml")):
            cmd += ["--lesson", os.path.join(cond, "lesson.toml")]
        if self.a.pilot == "by-hand":
            cmd += ["--by-hand", "--bindings", os.path.join(cond, "bindings.toml"),
                    "--end-when-docked", repr(DOCKED_S)]
        cmd += demo_args(self.a)
        self.folder.append({"event": "start", "subject": self.name, "trial": t["trial"], "run": run_no,
                            "session": os.path.relpath(session, self.folder.dir), "condition": t["condition"],
                            "kind": t["kind"], "pilot": self.a.pilot})
        rc = run_child(cmd, self.trial_lock_path())
        end = judge(session, rc, self.study.limit_s)
        end.update({"event": "end", "subject": self.name, "trial": t["trial"], "run": run_no,
                    "session": os.path.relpath(session, self.folder.dir)})
        self.folder.append(end)
        return end


def run_child(cmd, trial_lock):
    """The trial's session in the foreground: a Ctrl-C, a closed terminal or
    a kill of this run reaches it (it stops as a session stops, its record
    whole), and this run waits for it. The session's launcher inherits the
    trial lock and holds it until it exits, even if this run is killed: a
    resumed run waits on it (wait_for_trial_lock) before it flies again on
    the same address."""
    parent = os.getpid()

    def child_setup():
        import ctypes
        ctypes.CDLL("libc.so.6", use_errno=True).prctl(1, signal.SIGTERM)  # PR_SET_PDEATHSIG
        if os.getppid() != parent:  # this run died before prctl took
            os.kill(os.getpid(), signal.SIGTERM)
    lock_fd = os.open(trial_lock, os.O_RDWR | os.O_CREAT | os.O_CLOEXEC, 0o600)
    try:
        fcntl.flock(lock_fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except OSError:
        os.close(lock_fd)
        raise LabError(f"the session of an earlier trial still holds {trial_lock}: wait for it to stop, "
                       f"then run the same command again", 1)
    try:
        return wait_child(lambda: subprocess.Popen(cmd, preexec_fn=child_setup, pass_fds=(lock_fd,)))
    finally:
        os.close(lock_fd)


def wait_child(start):
    """Starts the child (start()) and waits for it, passing on the signals
    this run is sent."""
    stopped, signalled = [], []
    old = {s: signal.signal(s, lambda n, f: stopped.append(n)) for s in (signal.SIGINT, signal.SIGTERM, signal.SIGHUP)}
    try:
        proc = start()
        while True:
            try:
                rc = proc.wait(timeout=0.2)
                break
            except subprocess.TimeoutExpired:
                while stopped:  # a terminal's Ctrl-C reaches it too: a second one is harmless
                    proc.send_signal(stopped.pop())
                    signalled.append(True)
        return 130 if signalled and rc == 0 else rc
    finally:
        for s, h in old.items():
            signal.signal(s, h)


def judge(session, rc, limit_s):
    """A trial's run: done (its outcome counted) or lost (a technical
    reason: flown again) or stopped (by the experimenter: flown again)."""
    summary = read_folder_json(os.path.join(session, "summary.json"))
    if not os.path.isdir(session):
        return {"status": "refused", "why": f"the session did not start (exit code {rc}; its reason is said above)",
                "exit_code": rc}
    if rc == 130:
        return {"status": "stopped", "why": "stopped by the experimenter (Ctrl-C or a signal)", "exit_code": rc}
    if not summary:
        return {"status": "lost", "why": f"the session wrote no summary (exit code {rc})", "exit_code": rc}
    restarts = summary.get("restarts") or []
    if restarts:
        names = ", ".join(sorted({str(r.get("process")) for r in restarts}))
        return {"status": "lost", "why": f"a process crashed and was restarted ({names}): the subject's trial was "
                                         f"disturbed", "exit_code": rc}
    verdict = (summary.get("resimulation") or {}).get("verdict")
    if rc == 4 or not (summary.get("resimulation") or {}).get("exact"):
        return {"status": "lost", "why": f"the session does not re-simulate ({verdict or 'no verdict'})",
                "exit_code": rc}
    if rc not in (0, 3):
        return {"status": "lost", "why": f"the session ended with exit code {rc}", "exit_code": rc}
    attempts = summary.get("attempts") or []
    res = summary.get("result_attempt")
    result = next((x for x in attempts if x.get("index") == res), attempts[-1] if attempts else {})
    duration = summary.get("duration_s")
    docked = bool(summary.get("docked"))
    ended_by = "docked" if docked else "time limit" if isinstance(duration, (int, float)) and \
        duration >= limit_s - 0.1 else "the pilot (quit or gave up)"
    return {"status": "done", "exit_code": rc, "outcome": result.get("outcome"), "ended_by": ended_by,
            "docked": docked, "attempts": len(attempts),
            "task_time_s": (result.get("scorecard") or {}).get("task_time_s"),
            "duration_s": summary.get("duration_s")}


def wait_for_trial_lock(path, limit_s=120):
    """Waits until no launcher of an earlier run holds the trial lock (it
    stops when the run that started it dies: PR_SET_PDEATHSIG)."""
    fd = os.open(path, os.O_RDWR | os.O_CREAT | os.O_CLOEXEC, 0o600)
    try:
        end = time.time() + limit_s
        said = False
        while True:
            try:
                fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
                return
            except OSError:
                if time.time() >= end:
                    raise LabError(f"the session of the run that was under way has not stopped in {limit_s} s "
                                   f"(it holds {path}): stop it, then run the same command again", 1)
            if not said:
                say("waiting for the session of the run that was under way to stop")
                said = True
            time.sleep(0.2)
    finally:
        os.close(fd)


def dir_arg(a):
    return f" --dir {a.dir}" if a.dir else ""


def banner(study, subject, t, n, folder):
    cond = next(c for c in study.conditions if c["name"] == t["condition"])
    say(f"study '{study.name}', subject {subject}: trial {t['trial']} of {n} -- condition '{t['condition']}', "
        f"{t['kind']} trial {t['index']} of {t['of']}")
    say(f"  {cond['description'] or describe(cond)}; at most {study.limit_s:g} s")


def ask(prompt):
    """Enter goes on; q (or end of input) stops. Without a terminal: goes on."""
    if not sys.stdin.isatty():
        return True
    try:
        print(f"lab: {prompt} [Enter: go on, q: stop here] ", end="", file=sys.stderr, flush=True)
        line = sys.stdin.readline()
        if not line:  # end of input (Ctrl-D): stop, as q does
            print(file=sys.stderr)
            return False
        return line.strip().lower() not in ("q", "quit")
    except (OSError, KeyboardInterrupt):
        return False


def run_trials(argv):
    a = parse_run_args(argv)
    study = StudyFile(a.study)
    if a.subject not in study.subjects:
        raise LabError(f"subject '{a.subject}' is not one of the study's subjects (key 'study.subjects' of "
                       f"{study.file}: {', '.join(study.subjects)}); add them there, at the end")
    build(a.no_build)
    folder = StudyFolder(study, a.dir)
    folder.open(create=True)
    subj = Subject(folder, a)
    subj.settle_unended()
    flown, lost_in_a_row = 0, 0
    while True:
        t = subj.next_trial()
        if t is None:
            say(f"subject {subj.name} has flown every trial of study '{study.name}' "
                f"({len(subj.trials)} of {len(subj.trials)}); scripts/lab study status {a.study}{dir_arg(a)}")
            return 0
        if a.trials is not None and flown >= a.trials:
            say(f"{flown} trial(s) done; next for {subj.name}: trial {t['trial']} "
                f"(scripts/lab study run {a.study} --subject {subj.name}{dir_arg(a)} goes on)")
            return 0
        banner(study, subj.name, t, len(subj.trials), folder)
        if not ask("the subject is ready?"):
            say(f"stopped before trial {t['trial']}; the same command goes on from there")
            return 0
        end = subj.fly(t)
        if end["status"] == "done":
            flown += 1
            time_s = end.get("task_time_s")
            say(f"trial {t['trial']} of {len(subj.trials)} done: {end.get('outcome')}"
                + (f" in {time_s:.1f} s" if isinstance(time_s, (int, float)) else f", ended by {end['ended_by']}"))
        elif end["status"] == "stopped":
            say(f"trial {t['trial']} stopped part way: not counted; the same command flies it again")
            return 130
        elif end["status"] == "refused":
            say(f"trial {t['trial']}: the session did not start (why: above): nothing was flown or counted; "
                f"put it right and run the same command again")
            return end["exit_code"] or 1
        else:
            lost_in_a_row += 1
            say(f"trial {t['trial']} LOST: {end['why']}: not counted; it is flown again next")
            if lost_in_a_row >= MAX_LOST_IN_A_ROW:
                say(f"{lost_in_a_row} runs lost in a row: stopping here (see {folder.dir}/{end['session']}/logs); "
                    f"the same command goes on")
                return 1
            continue
        lost_in_a_row = 0
