"""scripts/lab resim | export | report | monitor | control: the tools over a
session (docs/sessions.md), each a thin call of its executable."""
import argparse
import json
import os
import subprocess
import time

from . import replay
from .common import DEFAULT_URL, ROOT, LabError, binary, file_sha256, install_and_build, require_session_file, say


def ensure(rel, no_build=False):
    if not os.access(binary(rel), os.X_OK):
        if no_build:
            raise LabError(f"{binary(rel)} is not built (drop --no-build, or run scripts/test)")
        install_and_build()


def resim(argv):
    """scripts/lab resim SESSION [--config FILE] [--set KEY=VALUE]... [--out DIR] [--threads N] [--video]:
    the DCP again on the recorded inputs. Without --config or --set, exit 0
    only if every output is identical; with them (another design), a new
    session (default SESSION-resim) with comparison.md; --video replays it
    to make its video."""
    p = argparse.ArgumentParser(prog="scripts/lab resim", description=resim.__doc__)
    p.add_argument("session")
    p.add_argument("--config")
    p.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                   help="a configuration key set over the session's (or --config's), e.g. dcp.tpob_ft=0.4")
    p.add_argument("--out")
    p.add_argument("--threads", choices=["auto", "1", "2"],
                   help="the session's own design on two cores at once (auto, the default), one thread, or always two")
    p.add_argument("--video", action="store_true")
    p.add_argument("--no-build", action="store_true")
    a = p.parse_args(argv)
    if not a.no_build:
        install_and_build()
    cmd = [binary("tools/rms_resim"), a.session]
    if a.threads:
        cmd += ["--threads", a.threads]
    if a.config:
        cmd += ["--config", a.config]
    for kv in a.set:
        cmd += ["--set", kv]
    if a.out:
        cmd += ["--out", a.out]
    rc = subprocess.run(cmd).returncode
    if rc == 0 and not a.config and not a.set and not branch_parent_unchanged(a.session):
        rc = 1
    if rc == 0 and a.video:
        out = a.out or a.session.rstrip("/") + "-resim"
        if not os.path.isdir(out):
            raise LabError("resim --video needs the new session (--config or --set)")
        replay.run([out, "--out", os.path.join(out, "replay"), "--no-build", "--speed", "4"])
        video = os.path.join(out, "replay", "session.mp4")
        if os.path.exists(video):
            os.replace(video, os.path.join(out, "session.mp4"))
            say(f"video: {os.path.join(out, 'session.mp4')}")
    return rc


def branch_parent_unchanged(session):
    """A branch (docs/sessions.md "Branching"): its parent's log is the one
    the branch was made from (the manifest's SHA-256). False, said, if not."""
    try:
        with open(os.path.join(session, "manifest.json")) as f:
            b = json.load(f).get("branch")
    except (OSError, ValueError, AttributeError, RecursionError):
        return True  # no manifest to speak of: no branch
    if b is None:
        return True
    try:
        want, parent = b["parent_log_sha256"], b["parent"]
        if not isinstance(want, str) or not isinstance(parent, str):
            raise TypeError
    except (KeyError, TypeError):
        say("the branch's manifest names no parent's log hash ('branch.parent_log_sha256'): "
            "its parent cannot be checked")
        return False
    try:
        now = file_sha256(os.path.join(parent, "lcmlog"))
    except OSError as e:
        say(f"the branch's parent log {parent}/lcmlog cannot be read ({e.strerror})")
        return False
    if now != want:
        say(f"the branch's parent {parent} is not the session it was made from: its lcmlog's SHA-256 is "
            f"{now[:16]}..., the branch's manifest says {str(want)[:16]}...")
        return False
    return True


def export(argv):
    """scripts/lab export SESSION [--out DIR] | --mcap [--out FILE]: every
    channel of the session's LCM log to CSV, one file each (default
    SESSION/csv/), in engineering units, each row with its session time; or,
    with --mcap, the whole log as one MCAP file (default SESSION/session.mcap)
    that Foxglove Studio and PlotJuggler open: JSON messages, a JSON Schema
    for every channel made from the LCM types."""
    p = argparse.ArgumentParser(prog="scripts/lab export", description=export.__doc__)
    p.add_argument("session")
    p.add_argument("--out")
    p.add_argument("--mcap", action="store_true", help="one MCAP file instead of CSV")
    p.add_argument("--no-build", action="store_true")
    a = p.parse_args(argv)
    require_session_file(a.session)
    if a.mcap:
        refuse_record_file(a.out)
    ensure("tools/rms_session", a.no_build)
    if not a.mcap:
        cmd = [binary("tools/rms_session"), "export", a.session] + (["--out", a.out] if a.out else [])
        return subprocess.run(cmd).returncode
    return export_mcap(a.session, a.out or os.path.join(a.session, "session.mcap"))


def inside(path, folder):
    """Whether path lies inside folder, links and trailing slashes resolved
    (as rms::LinksForOutput)."""
    p = os.path.realpath(os.path.dirname(os.path.abspath(path)))
    f = os.path.realpath(folder)
    return os.path.commonpath([p, f]) == f


def export_mcap(session, out):
    """The log as JSON lines (rms_session export --jsonl) into the MCAP
    writer (tools/mcap/write_mcap.mjs, @mcap/core from npm)."""
    mcap = os.path.join(ROOT, "tools", "mcap")
    folder = os.path.dirname(os.path.abspath(out))
    if not os.path.isdir(folder) or not os.access(folder, os.W_OK):
        raise LabError(f"--out {out}: cannot write there (its folder {folder} is missing or not writable)", 2)
    schemas = binary("lcmtypes/schemas")
    if not os.path.isdir(os.path.join(mcap, "node_modules", "@mcap", "core")):
        raise LabError("the MCAP writer's packages are not installed: run scripts/install-deps", 1)
    if not os.path.isdir(schemas):
        raise LabError(f"no JSON schemas in {schemas}: build first (drop --no-build)", 1)
    reader = subprocess.Popen([binary("tools/rms_session"), "export", session, "--jsonl"], stdout=subprocess.PIPE)
    # A link at an --out the user named outside the session is theirs to
    # follow (/dev/stdout); inside the folder it is replaced (docs/security.md).
    follow = [] if inside(out, session) else ["--follow-links"]
    writer = subprocess.run(["node", os.path.join(mcap, "write_mcap.mjs"), "--schemas", schemas, "--out", out] +
                            follow, stdin=reader.stdout)
    reader.stdout.close()
    rc = reader.wait()
    if rc != 0 or writer.returncode != 0:
        if writer.returncode == 0 and os.path.isfile(out) and not os.path.islink(out) and \
                not os.path.abspath(out).startswith(("/dev/", "/proc/")):
            os.remove(out)  # a partial log: not left as if whole (a stream or a link is not removed)
        why = ("the MCAP writer failed (said above)" if writer.returncode != 0 else
               f"reading the session's log failed (rms_session exit {rc})")
        raise LabError(f"the MCAP export failed: {why}; no file written", 1)
    say(f"MCAP: {out} (opens in Foxglove Studio and PlotJuggler)")
    return 0


# A session's record and what is made from it at its end (docs/sessions.md
# "The session folder"): an --out never writes over one of them.
RECORD_FILES = ("lcmlog", "wire.lcmlog", "record.json", "resimulation.json", "summary.json",
                "manifest.json", "config.toml", "timeline.tl", "bindings.toml", "session.mp4")


def refuse_record_file(out):
    """A LabError when OUT names a file of a session's record (a folder
    holding an lcmlog): writing there would lose it."""
    if not out:
        return
    folder = os.path.dirname(os.path.abspath(out))
    if os.path.basename(out) in RECORD_FILES and os.path.exists(os.path.join(folder, "lcmlog")):
        raise LabError(f"--out {out}: that is the session's own {os.path.basename(out)} "
                       f"(docs/sessions.md \"The session folder\"): give another file", 2)


def report(argv):
    """scripts/lab report SESSION [--out FILE]: one self-contained HTML report
    (default SESSION/report.html): the session, its tolerances, every
    attempt and the operator's scorecard, the end effector's path, joints,
    inputs, an event timeline, frames and the video's link, losses and
    timing; plots drawn by Chart.js, embedded."""
    p = argparse.ArgumentParser(prog="scripts/lab report", description=report.__doc__)
    p.add_argument("session")
    p.add_argument("--out")
    p.add_argument("--no-build", action="store_true")
    a = p.parse_args(argv)
    require_session_file(a.session)
    if a.out and not os.path.isdir(os.path.dirname(os.path.abspath(a.out))):
        raise LabError(f"--out {a.out}: its folder does not exist", 2)
    refuse_record_file(a.out)
    ensure("tools/rms_report", a.no_build)
    return subprocess.run([binary("tools/rms_report"), a.session] + (["--out", a.out] if a.out else [])).returncode


def debrief(argv):
    """scripts/lab debrief SESSION [--port N] [--bind ADDRESS] [--for SECONDS]:
    the instructor's page over a recorded session (docs/instructor.md
    "Debrief"): scrub through it -- any station's view at any session time,
    drawn from the log's DCP frames, the plots and events under the cursor
    -- and place marks and notes on its timeline, kept in
    SESSION/instructor_marks.jsonl and shown in the report. Nothing is sent
    to any session. Runs until Ctrl-C (or --for SECONDS)."""
    p = argparse.ArgumentParser(prog="scripts/lab debrief", description=debrief.__doc__)
    p.add_argument("session")
    p.add_argument("--port", type=int, default=8080, help="the page's port (0: any free one)")
    p.add_argument("--bind", default="127.0.0.1", help="the address to serve on (beyond loopback the token "
                   "crosses the network in clear: docs/security.md)")
    p.add_argument("--for", dest="for_s", type=float, help="stop after this many seconds")
    p.add_argument("--no-build", action="store_true")
    a = p.parse_args(argv)
    require_session_file(a.session)
    require_session_file(a.session, "config.toml")
    if not 0 <= a.port <= 65535:
        raise LabError(f"--port {a.port}: 0..65535 (0: any free one)", 2)
    if a.for_s is not None and not 0 < a.for_s <= 86400:
        raise LabError(f"--for {a.for_s}: 0..86400 s", 2)
    ensure("instructor_station/instructor_station", a.no_build)
    import secrets
    import signal
    import tempfile
    token = secrets.token_hex(16)
    with tempfile.TemporaryDirectory(prefix="rmslab-debrief-") as tmp:
        url_file = os.path.join(tmp, "debrief.url")
        argv = [binary("instructor_station/instructor_station"), "--debrief", "--session-dir", a.session,
                "--config", os.path.join(a.session, "config.toml"), "--lcm-url", "memq://",
                "--bind", a.bind, "--port", str(a.port), "--url-file", url_file,
                "--marks-file", os.path.join(a.session, "instructor_marks.jsonl"),
                "--checkpoint-dir", os.path.join(a.session, "checkpoints")]
        lesson_state = os.path.join(a.session, "run", "instructor_lesson.json")
        if os.path.isfile(lesson_state):  # the lesson the session ran, each event's outcome (read only)
            argv += ["--lesson-state", lesson_state]
        # Its lifeline (standard input, closed when this launcher dies, even
        # by SIGKILL): the station never outlives the debrief's launcher.
        proc = subprocess.Popen(argv, stdin=subprocess.PIPE,
                                env=dict(os.environ, RMSLAB_INSTRUCTOR_TOKEN=token, RMSLAB_LIFELINE="stdin"))

        def stop_on(signum, _frame):
            raise KeyboardInterrupt  # SIGTERM, SIGHUP: stopped as by Ctrl-C, the station with it

        for sig in (signal.SIGTERM, signal.SIGHUP):
            signal.signal(sig, stop_on)
        try:
            end = time.monotonic() + 60
            while not os.path.exists(url_file):
                if proc.poll() is not None:
                    raise LabError(f"the debrief's station stopped (exit {proc.returncode}): see above", 1)
                if time.monotonic() > end:
                    raise LabError("the debrief's station did not start within 60 s", 1)
                time.sleep(0.1)
            say(f"debrief of {a.session}: {open(url_file).read().strip()}")
            say("Ctrl-C stops it" if a.for_s is None else f"for {a.for_s:g} s")
            try:
                proc.wait(timeout=a.for_s)
            except subprocess.TimeoutExpired:
                pass
        except KeyboardInterrupt:
            pass
        finally:
            if proc.poll() is None:
                proc.send_signal(signal.SIGINT)
                try:
                    proc.wait(timeout=10)
                except subprocess.TimeoutExpired:
                    proc.kill()
                    proc.wait()
    return 0 if proc.returncode in (0, -signal.SIGINT, 130) else proc.returncode


def compare(argv):
    """scripts/lab compare SESSION... [--out DIR]: the scorecard of each
    session side by side, and each subject's learning curve across the
    sessions it flew (scripts/lab demo --subject NAME), as DIR/compare.html
    (self-contained, plots by Chart.js) and DIR/compare.csv (a row an
    attempt); default DIR: sessions/compare-<UTC time>. Re-simulations
    (scripts/lab resim --config) are sessions of their own in it. A session
    whose result began with a restore, a reset or a branch is flagged and
    left off the learning curves (--all-trials puts it on)."""
    p = argparse.ArgumentParser(prog="scripts/lab compare", description=compare.__doc__)
    p.add_argument("sessions", nargs="+")
    p.add_argument("--out")
    p.add_argument("--all-trials", action="store_true",
                   help="learning curves with the sessions whose result began with a restore, a reset or a branch")
    p.add_argument("--no-build", action="store_true")
    a = p.parse_args(argv)
    for s in a.sessions:
        require_session_file(s)
    ensure("tools/rms_compare", a.no_build)
    out = a.out or os.path.join(ROOT, "sessions", "compare-" + time.strftime("%Y%m%dT%H%M%SZ", time.gmtime()))
    return subprocess.run([binary("tools/rms_compare")] + a.sessions + ["--out", out] +
                          (["--all-trials"] if a.all_trials else [])).returncode


def monitor(argv):
    """scripts/lab monitor [--session DIR | --lcm-url URL [--channel-suffix S]] [--for SECONDS]:
    live decoded traffic per channel, and each process's last status report."""
    ensure("tools/rms_monitor")
    if "--lcm-url" not in argv and "--session" not in argv:
        argv = ["--lcm-url", DEFAULT_URL] + argv
    return subprocess.run([binary("tools/rms_monitor")] + argv).returncode


def running_sessions():
    """Session folders under sessions/ whose launcher is still running."""
    out = []
    base = os.path.join(ROOT, "sessions")
    if not os.path.isdir(base):
        return out
    for name in sorted(os.listdir(base)):
        pidf = os.path.join(base, name, "run", "launcher.pid")
        try:
            pid = int(open(pidf).read())
            os.kill(pid, 0)
        except (OSError, ValueError):
            continue
        if not os.path.exists(os.path.join(base, name, "run", "stopping")):
            out.append(os.path.join(base, name))
    return out


def control(argv):
    """scripts/lab control [--session DIR] freeze | run | step [N] | reset | checkpoint NAME | restore NAME|FILE [--run]
                    | malfunction WHAT... | repair WHAT...:
    commands to a running session (docs/sessions.md "Freeze, run, step,
    checkpoint" and "Malfunctions"). WHAT is a malfunction or a repair in
    the grammar that `scripts/lab control malfunction --help` and `scripts/lab
    control repair --help` print (made from the malfunction table in
    wire/include/rms/wire/malfunction.h). Without --session (or --lcm-url and
    --session-id): the one session of this checkout that is running now."""
    if not argv or argv[0] in ("-h", "--help"):
        print(control.__doc__)
        return 0 if argv else 2
    no_build = "--no-build" in argv  # as every other subcommand takes it
    argv = [a for a in argv if a != "--no-build"]
    ensure("tools/rms_control", no_build)
    helping = any(a in argv for a in ("-h", "--help"))
    if not helping and not any(a in argv for a in ("--session", "--lcm-url", "--session-id")):
        live = running_sessions()
        if len(live) != 1:
            raise LabError("no session of this checkout is running: give --session DIR" if not live else
                           "several sessions are running: give --session DIR, one of\n" +
                           "\n".join("  " + s for s in live))
        say(f"the running session: {live[0]}")
        argv = ["--session", live[0]] + argv
    return subprocess.run([binary("tools/rms_control")] + argv).returncode
