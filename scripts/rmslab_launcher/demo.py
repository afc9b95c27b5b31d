"""scripts/lab demo: one session of the four processes and the recorder
(docs/sessions.md). See `scripts/lab demo --help`."""
import argparse
import json
import os
import secrets
import socket
import shutil
import signal
import subprocess
import sys
import time

from . import disk, session
from .branch import Branch
from .common import (BUILD, DEFAULT_URL, ROOT, LabError, binary, check_cpu_wake_latency, check_speed, check_suffix,
                     ensure_multicast_route, file_sha256, frame_rate_hz, check_lcm_url, install_and_build,
                     require_built, say, timeline_length_s)
from .hosts import Host, check_hosts
from .supervisor import Spec, Supervisor

PROCESSES = ["operator_station", "dynamics_proc", "scene_proc", "esg_renderer"]
AUTOPILOT_S = 120.0   # the autopilot's mission, with a margin (docs/operator.md)
BY_HAND_S = 600.0     # what the disk check allows a person, at least (the watch covers longer)


def add_arguments(p):
    p.add_argument("--out", help="the session folder (default sessions/<UTC time>)")
    g = p.add_mutually_exclusive_group()
    g.add_argument("--timeline", help="fly this timeline (docs/timeline.md)")
    g.add_argument("--by-hand", action="store_true", help="fly it yourself: this terminal's keys and status screen")
    p.add_argument("--bindings", help="by hand: other keys, rates and devices (docs/operator.md)")
    p.add_argument("--autopilot-straight", action="store_true", help="the autopilot flies straight lines")
    p.add_argument("--subject", default="", help="who flies it, for the manifest and scripts/lab compare")
    p.add_argument("--note", default="", help="the experimenter's note, for the manifest")
    p.add_argument("--restore", help="start from this checkpoint")
    p.add_argument("--from", dest="from_", metavar="SESSION@TIME",
                   help="branch from a recorded session: its inputs re-simulated up to TIME (s of session "
                        "time; or @fFRAME, a DCP frame), word for word, then flown live from there")
    p.add_argument("--lab", help="a lab file: which process runs on which host (docs/sessions.md)")
    p.add_argument("--config", help="the configuration (default config/rmslab.toml; with --from, the "
                                    "recorded session's)")
    p.add_argument("--speed", default="1", help="the same frames, that many times faster (0.01 .. 100)")
    p.add_argument("--png-every", type=int, default=30, help="a PNG frame every N frames (0: none)")
    p.add_argument("--width", type=int, default=1024)
    p.add_argument("--height", type=int, default=768)
    p.add_argument("--no-video", action="store_true")
    p.add_argument("--window", action="store_true", help="the ESG's live window (by hand: its keys too)")
    p.add_argument("--gl", default="osmesa", choices=["osmesa", "egl"])
    p.add_argument("--visibility", default="priority", choices=["priority", "depth"])
    p.add_argument("--lcm-url", help=f"the session's LCM address (default {DEFAULT_URL})")
    p.add_argument("--channel-suffix", default="", help="appended to every channel: stations sharing a network")
    p.add_argument("--share-network", action="store_true",
                   help="start even when another session is on this address and channels")
    p.add_argument("--instructor", nargs="?", const=8080, type=int, metavar="PORT",
                   help="the instructor's station: a web page of live views, status, events and controls, "
                        "served on PORT (default 8080; 0: any free port) of 127.0.0.1, or where the lab file "
                        "says (docs/instructor.md)")
    p.add_argument("--cpu-wake-latency-us", default="0", metavar="US|off",
                   help="while the session runs, hold this machine's CPUs' wake-up latency at most this many "
                        "microseconds (default 0: idle CPUs poll instead of halting, and the frames reach the "
                        "pixels sooner; Linux PM QoS through /dev/cpu_dma_latency, which needs root: without "
                        "it the session runs and says so); off: leave it to the system "
                        "(docs/performance.md \"Wake latency\")")
    p.add_argument("--lesson", help="scripted events: malfunctions, repairs, freezes at a session time, on entering "
                                    "a mode or on a condition (docs/lessons.md)")
    p.add_argument("--instructor-lesson", metavar="FILE",
                   help="a lesson the instructor's station fires (with --instructor; its page can load one "
                        "too: docs/lessons.md \"From the instructor's station\")")
    p.add_argument("--limit-s", type=float, metavar="S",
                   help="end the session after S seconds of session time (a study's trial limit)")
    p.add_argument("--end-when-docked", type=float, metavar="S",
                   help="by hand: end the session S seconds of session time after the payload docks (a "
                        "study's trial; the autopilot and a timeline end there already)")
    g = p.add_argument_group("a study's trial (set by scripts/lab study run; docs/studies.md)")
    g.add_argument("--study", default="", help="the study's name, for the manifest")
    g.add_argument("--study-sha256", default="", help="SHA-256 of the study file")
    g.add_argument("--condition", default="", help="the trial's condition")
    g.add_argument("--trial", type=int, default=0, help="the trial's place in the subject's order, from 1")
    g.add_argument("--trial-kind", default="", choices=["", "practice", "measured"])
    g.add_argument("--trial-run", type=int, default=1, help="1, or more when a lost run is flown again")
    p.add_argument("--no-build", action="store_true")


class Demo:
    def __init__(self, a, command_line):
        self.a = a
        self.command_line = command_line
        self.interrupted = None
        self.notes = []

    # ---- before anything starts ----
    def validate(self):
        a = self.a
        self.branch = None
        if a.from_:
            if a.restore:
                raise LabError("--from and --restore: give one (a branch starts from its own checkpoint)")
            self.branch = Branch(a.from_)
            a.config = a.config or os.path.join(self.branch.parent, "config.toml")
        a.config = a.config or os.path.join(ROOT, "config", "rmslab.toml")
        for f in [a.config, a.timeline, a.restore, a.lab, a.bindings, a.lesson, a.instructor_lesson]:
            if f and not os.path.exists(f):
                raise LabError(f"no such file: {f}")
            if f and not os.path.isfile(f):
                raise LabError(f"{f}: not a regular file (a folder, a device or a pipe): give a file")
            if f and not os.access(f, os.R_OK):
                raise LabError(f"{f}: cannot be read (permissions)")
        if a.bindings and not a.by_hand:
            raise LabError("--bindings is for flying by hand (--by-hand)")
        self.tty = sys.stdin.isatty()
        if a.by_hand and not self.tty and not a.window:
            raise LabError("--by-hand needs a terminal on standard input, or --window to fly from the live window")
        if a.window and not os.environ.get("DISPLAY"):
            if a.by_hand and not self.tty:
                raise LabError("--window: no DISPLAY here, and no terminal: nothing to fly from")
            self.notes.append("--window: no DISPLAY here; the ESG rendered headless")
            a.window = False
        self.speed = check_speed(a.speed)
        self.wake_latency = check_cpu_wake_latency(a.cpu_wake_latency_us)
        # The session's own request, for the checks before the start too
        # (its processes' --check reads it): never one left in the shell.
        os.environ["RMSLAB_CPU_WAKE_LATENCY_US"] = self.wake_latency
        self.wake_said = set()  # (state, host) said not held
        check_suffix(a.channel_suffix)
        if a.width < 16 or a.height < 16 or a.width % 2 or a.height % 2:
            raise LabError(f"--width {a.width} --height {a.height}: even sizes, at least 16")
        if a.png_every < 0:
            raise LabError("--png-every: 0 (none) or more")
        self.rate = frame_rate_hz(a.config)
        if a.limit_s is not None and not 1.0 / self.rate <= a.limit_s <= 86400:
            raise LabError(f"--limit-s {a.limit_s}: from one frame to 86400 s of session time")
        if a.instructor_lesson and a.instructor is None:
            raise LabError("--instructor-lesson: the instructor's station fires it: give --instructor too")
        if a.instructor_lesson and (a.from_ or a.restore):
            raise LabError("--instructor-lesson with --from or --restore: a lesson's times and modes are the "
                           "task's from its start (docs/lessons.md); start the session afresh")
        if a.lesson and (a.from_ or a.restore):
            raise LabError("--lesson with --from or --restore: a lesson's times and modes are the task's from its "
                           "start (docs/lessons.md); start the session afresh")
        if a.end_when_docked is not None and not (a.by_hand and 0 <= a.end_when_docked <= 600):
            raise LabError(f"--end-when-docked {a.end_when_docked}: by hand (--by-hand), 0..600 s")
        if a.study and (not a.condition or a.trial < 1 or not a.trial_kind or a.trial_run < 1):
            raise LabError("--study: with --condition, --trial (1 or more), --trial-kind and --trial-run "
                           "(scripts/lab study run gives them)")
        self.pilot = "by-hand" if a.by_hand else "timeline" if a.timeline else "autopilot"
        if a.instructor is not None and not 0 <= a.instructor <= 65535:
            raise LabError(f"--instructor {a.instructor}: a port, 0..65535 (0: any free one)")

    def layout(self):
        a = self.a
        self.hosts = {p: Host("localhost") for p in PROCESSES + ["recorder", "instructor_station"]}
        self.instructor_bind = "127.0.0.1"
        self.remote_bin = BUILD
        self.url = a.lcm_url or DEFAULT_URL
        if a.lab:
            r = subprocess.run([binary("tools/rms_session"), "labfile", a.lab], capture_output=True, text=True)
            if r.returncode:
                raise LabError(r.stderr.strip())
            lab = json.loads(r.stdout)
            for p, h in lab["hosts"].items():
                self.hosts[p] = Host(h)
            if lab.get("instructor_bind"):
                self.instructor_bind = lab["instructor_bind"]
            if self.hosts["recorder"].remote:
                raise LabError("the recorder must run here or in a netns (the session folder is here)")
            if a.by_hand and self.hosts["operator_station"].remote:
                raise LabError("--by-hand needs operator_station here (it takes this terminal)")
            if lab["remote_build"]:
                self.remote_bin = lab["remote_build"]
            elif lab["remote_root"]:
                self.remote_bin = os.path.join(lab["remote_root"], "build")
            if not a.lcm_url:
                ttl = 0 if lab["all_local"] else lab["ttl"]
                self.url = f"udpm://{lab['group']}:{lab['port']}?ttl={ttl}"
            if not lab["all_local"]:
                check_hosts(self.url, self.remote_bin, list(self.hosts.values()))

    def checks(self):
        """Every process with its own files, by --check, before anything starts."""
        a = self.a
        common = ["--config", a.config, "--channel-suffix", a.channel_suffix]
        op = [binary("operator_station/operator_station")] + common
        if self.pilot == "by-hand":
            op += ["--manual", "--bindings", a.bindings or os.path.join(ROOT, "config", "bindings.toml")]
        elif self.pilot == "timeline":
            op += ["--timeline", a.timeline]
        else:
            op += ["--autopilot"]
        if a.restore:
            op += ["--restore", a.restore]
        if a.lesson:
            op += ["--lesson", a.lesson]
        dcp = [binary("dynamics_proc/dynamics_proc")] + common + (["--restore", a.restore] if a.restore else [])
        esg = [binary("esg_renderer/esg_renderer")] + common + [
            "--width", str(a.width), "--height", str(a.height), "--gl", a.gl, "--visibility", a.visibility]
        checks = [("operator_station", op), ("dynamics_proc", dcp),
                  ("scene_proc", [binary("scene_proc/scene_proc")] + common), ("esg_renderer", esg)]
        if a.instructor is not None:
            checks.append(("instructor_station", [binary("instructor_station/instructor_station")] + common +
                           self.instructor_args() + ["--token", "x" * 16] +
                           (["--lesson", a.instructor_lesson] if a.instructor_lesson else [])))
        session.precheck(checks)

    def instructor_args(self):
        """The instructor station's own options (docs/instructor.md). Its
        token goes in the environment (instructor_env), not on the command
        line where every user of the host can read it."""
        if not hasattr(self, "instructor_port"):
            self.instructor_token = secrets.token_hex(16)
            self.instructor_port = self.a.instructor
            if self.instructor_port == 0:
                # Chosen here, once: a restarted station serves where the open pages look.
                family = socket.AF_INET6 if ":" in self.instructor_bind else socket.AF_INET
                with socket.socket(family, socket.SOCK_STREAM) as s:
                    s.bind((self.instructor_bind, 0))
                    self.instructor_port = s.getsockname()[1]
        return ["--bind", self.instructor_bind, "--port", str(self.instructor_port)]

    def instructor_env(self):
        return {"RMSLAB_INSTRUCTOR_TOKEN": self.instructor_token}

    def start_instructor(self):
        url_file = os.path.join(self.out, "run", "instructor.url")
        extra = self.instructor_args() + ["--url-file", url_file,
                                          "--checkpoint-dir", os.path.join(self.out, "checkpoints"),
                                          "--lesson-state", os.path.join(self.out, "run", "instructor_lesson.json")]
        if not self.hosts["instructor_station"].remote:
            # a restarted station reads its history back from the log
            extra += ["--session-dir", self.out,
                      "--marks-file", os.path.join(self.out, "instructor_marks.jsonl")]
        if self.a.instructor_lesson:
            extra += ["--lesson", os.path.join(self.out, "instructor_lesson.toml")]
        self.sup.add(self.spec("instructor_station", extra, env=self.instructor_env()))
        err = self.sup.wait_ready(["instructor_station"])
        if err:
            raise LabError(err, 1)
        url = open(url_file).read().strip()
        where = "" if self.instructor_bind == "127.0.0.1" else \
            f" (served on {self.instructor_bind}: give the token only to whom it is for)"
        say(f"instructor's page: {url}{where}")

    def duration_s(self):
        if self.a.limit_s is not None:
            return self.a.limit_s / self.speed + 10
        if self.pilot == "timeline":
            return timeline_length_s(self.a.timeline) / self.speed + 10
        if self.pilot == "autopilot":
            return AUTOPILOT_S / self.speed
        return BY_HAND_S

    # ---- the session folder ----
    def make_session(self):
        a = self.a
        self.bytes_per_s = disk.session_bytes_per_s(self.rate * self.speed, a.width, a.height, a.png_every,
                                                    not a.no_video and not self.hosts["esg_renderer"].remote)
        # Before the folder is made: a refused session leaves nothing behind.
        disk.check_room(a.out or os.path.join(ROOT, "sessions"), self.bytes_per_s, self.duration_s(),
                        f"{self.pilot}, {a.width}x{a.height}, PNG every {a.png_every}, video "
                        f"{'no' if a.no_video else 'yes'}")
        self.out = session.make_folder(a.out, os.path.join(ROOT, "sessions"))
        os.makedirs(os.path.join(self.out, "journal"), exist_ok=True)
        self.name = os.path.basename(self.out)
        # On an ssh host: a folder in the remote user's home (ssh's working
        # folder), made 0700, its name not guessable -- never a fixed /tmp
        # name another user could make first (it holds the session's key).
        self.remote_run = f".rmslab/run/{self.name}-{secrets.token_hex(6)}"
        run = os.path.join(self.out, "run")
        shutil.copyfile(a.config, os.path.join(self.out, "config.toml"))
        if a.timeline:
            shutil.copyfile(a.timeline, os.path.join(self.out, "timeline.tl"))
        if a.lesson:
            shutil.copyfile(a.lesson, os.path.join(self.out, "lesson.toml"))
        if a.instructor_lesson:
            shutil.copyfile(a.instructor_lesson, os.path.join(self.out, "instructor_lesson.toml"))
        if a.restore:
            shutil.copyfile(a.restore, os.path.join(run, "restore.json"))
        if self.pilot == "by-hand":
            shutil.copyfile(a.bindings or os.path.join(ROOT, "config", "bindings.toml"),
                            os.path.join(self.out, "bindings.toml"))
        with open(os.path.join(run, "pilot"), "w") as f:
            f.write(self.pilot + "\n")
        with open(os.path.join(run, "launcher.pid"), "w") as f:
            f.write(f"{os.getpid()}\n")
        self.session_id = session.new_session_id()
        session.note_address_holder(self.session_id)
        self.key_file = session.write_session_key(os.path.join(self.out, "run"))
        fields = [("--pilot", self.pilot), ("--lcm-url", self.url), ("--session-id", self.session_id),
                  ("--message-auth", session.MESSAGE_AUTH),
                  ("--command", self.command_line),
                  ("--config-sha256", file_sha256(os.path.join(self.out, "config.toml")))]
        for p in PROCESSES:
            fields.append(("--host", f"{p}={self.hosts[p]}"))
        fields.append(("--host", f"lcm-logger={self.hosts['recorder']}"))
        if a.channel_suffix:
            fields.append(("--channel-suffix", a.channel_suffix))
        if a.timeline:
            fields.append(("--timeline", a.timeline))
        if a.restore and not self.branch:
            fields.append(("--restore", a.restore))
        if self.branch:  # its checkpoint is the session's own run/restore.json
            fields.append(("--restore", os.path.join(self.out, "run", "restore.json")))
            fields += self.branch.manifest_fields()
        if a.subject:
            fields.append(("--subject", a.subject))
        if a.note:
            fields.append(("--note", a.note))
        if a.study:
            fields += [("--study", a.study), ("--study-sha256", a.study_sha256), ("--condition", a.condition),
                       ("--trial", str(a.trial)), ("--trial-kind", a.trial_kind), ("--trial-run", str(a.trial_run))]
        session.write_manifest(self.out, fields)
        say(f"session {self.out}")

    # ---- the processes ----
    def proc_paths(self, name):
        """(binary, config, stats, ready file) where `name` runs."""
        h = self.hosts[name]
        if h.remote:
            h.copy_to(os.path.join(self.out, "config.toml"), f"{self.remote_run}/config.toml")
            # scp makes it with the key's own mode (0600): its owner's only.
            h.copy_to(self.key_file, f"{self.remote_run}/{session.SESSION_KEY}")
            return (f"{self.remote_bin}/{name}/{name}", f"{self.remote_run}/config.toml",
                    f"{self.remote_run}/{name}.json", f"{self.remote_run}/{name}.ready")
        return (binary(f"{name}/{name}"), os.path.join(self.out, "config.toml"),
                os.path.join(self.out, "stats", f"{name}.json"), os.path.join(self.out, "run", f"{name}.ready"))

    def spec(self, name, extra, **kw):
        exe, cfg, stats, ready = self.proc_paths(name)
        argv = [exe, "--config", cfg, "--lcm-url", self.url, "--stats", stats, "--ready-file", ready,
                "--journal-dir", self.journal_dir(name)]
        if self.a.channel_suffix:
            argv += ["--channel-suffix", self.a.channel_suffix]
        h = self.hosts[name]
        log = os.path.join(self.out, "logs", f"{name}.log")
        if h.remote:
            # Ready once this run has said so: the log keeps the earlier runs' lines.
            def ready_fn(c):
                with open(log, errors="replace") as f:
                    return f.read().count("] ready: ") > c.n
        else:
            def ready_fn(c):
                return os.path.exists(ready)
            if os.path.exists(ready):
                os.remove(ready)
        if h.remote:  # the key where that host's process reads it
            kw["env"] = dict(kw.get("env") or {}, RMSLAB_SESSION_KEY_FILE=f"{self.remote_run}/{session.SESSION_KEY}")
        return Spec(name, h, argv + extra, log, ready=ready_fn, remote_run=self.remote_run if h.remote else None, **kw)

    def journal_dir(self, name):
        """Where `name` journals what it publishes (docs/sessions.md "The
        record"): the session's journal/ here or in a namespace; on an ssh
        host its run folder's, copied back at the end."""
        if self.hosts[name].remote:
            return f"{self.remote_run}/journal"
        return os.path.join(self.out, "journal")

    def recorder_spec(self):
        chans = f"RMS_({'|'.join(c[4:] for c in session.CHANNELS)}){self.a.channel_suffix}"

        def argv(n):
            return ["lcm-logger", f"--lcm-url={self.url}", "--force", "--quiet", f"--channel={chans}",
                    os.path.join(self.out, session.WIRE_LOG if n == 0 else f"{session.WIRE_LOG}.{n}")]

        def ready(c):
            return os.path.exists(argv(c.n)[-1])

        def may_restart():
            free = disk.free_bytes(self.out)
            if free < disk.stop_threshold(self.bytes_per_s):
                return (f"the recorder stopped: the disk of {self.out} is full ({free / disk.MB:.1f} MB left); "
                        f"stopping the session, its record ends here")
            self.notes.append("the recorder died and was restarted: what the network delivered has a gap there "
                              "(the record holds it from the processes' journals; summary.json 'record')")
            return None
        return Spec("lcm-logger", self.hosts["recorder"], argv(0), os.path.join(self.out, "logs", "lcm-logger.log"),
                    ready=ready, next_argv=argv, lifeline=False, may_restart=may_restart)

    def esg_args(self):
        a = self.a
        args = ["--width", str(a.width), "--height", str(a.height), "--gl", a.gl, "--visibility", a.visibility]
        if self.hosts["esg_renderer"].remote:
            say(f"esg_renderer on {self.hosts['esg_renderer'].name}: frames and video stay there, in {self.remote_run}")
        else:
            args += ["--png-dir", os.path.join(self.out, "frames"), "--png-every", str(a.png_every)]
            if not a.no_video:
                args += ["--video", os.path.join(self.out, "session.mp4")]
        if a.window:
            args.append("--window")
        return args

    def operator_spec(self):
        a = self.a
        remote = self.hosts["operator_station"].remote
        extra = ["--checkpoint-dir", self.remote_run if remote else os.path.join(self.out, "checkpoints")]
        if a.restore:
            extra += ["--restore", os.path.join(self.out, "run", "restore.json")]
        if not remote and not self.hosts["dynamics_proc"].remote:
            # restarted, it sends the DCP's last inputs until it hears the DCP ("Faults")
            extra += ["--dcp-state-file", os.path.join(self.out, "run", "dcp_state.json")]
        tty = False
        if a.lesson:
            if remote:
                self.hosts["operator_station"].copy_to(os.path.join(self.out, "lesson.toml"),
                                                       f"{self.remote_run}/lesson.toml")
            extra += ["--lesson", f"{self.remote_run}/lesson.toml" if remote else
                      os.path.join(self.out, "lesson.toml")]
        if a.limit_s is not None:
            extra += ["--frames", str(max(1, round(a.limit_s * self.rate)))]
        if self.pilot == "timeline":
            extra += ["--timeline", os.path.join(self.out, "timeline.tl"), "--speed", str(self.speed)]
        elif self.pilot == "autopilot":
            extra += ["--autopilot", "--rate", f"{self.rate * self.speed:.3f}"]
            if a.autopilot_straight:
                extra.append("--autopilot-straight")
        else:
            extra += ["--manual", "--bindings", os.path.join(self.out, "bindings.toml")]
            if a.end_when_docked is not None:
                extra += ["--end-when-docked", repr(a.end_when_docked)]
            if a.window:
                extra.append("--window-keys")
            if self.tty:
                extra.append("--status")
            tty = self.tty
        return self.spec("operator_station", extra, pilot=True, tty=tty)

    # ---- running ----
    def on_signal(self, signum, frame):
        self.interrupted = signum
        if hasattr(self, "sup"):
            self.sup.interrupted = True

    def start(self):
        env = {"RMSLAB_SESSION_ID": self.session_id, "RMSLAB_SESSION_EPOCH_US": str(int(time.time() * 1e6)),
               "RMSLAB_SESSION_KEY_FILE": self.key_file,
               "RMSLAB_CPU_WAKE_LATENCY_US": self.wake_latency}
        self.sup = Supervisor(os.path.join(self.out, "run"), env)
        self.sup.start_reaper(self.out, [binary("tools/rms_session"), "summary", self.out])
        for sig in (signal.SIGINT, signal.SIGTERM, signal.SIGHUP):
            signal.signal(sig, self.on_signal)
        self.sup.add(self.recorder_spec())
        err = self.sup.wait_ready(["lcm-logger"])
        if err:
            raise LabError(err, 1)
        if self.interrupted is not None:
            return
        self.sup.add(self.spec("esg_renderer", self.esg_args()))
        self.sup.add(self.spec("scene_proc", []))
        remote = self.hosts["dynamics_proc"].remote
        dcp = ["--checkpoint-dir", self.remote_run if remote else os.path.join(self.out, "checkpoints")]
        if not remote:
            dcp += ["--state-file", os.path.join(self.out, "run", "dcp_state.json")]
        if self.a.restore:
            dcp += ["--restore", os.path.join(self.out, "run", "restore.json")]
        self.sup.add(self.spec("dynamics_proc", dcp))
        err = self.sup.wait_ready(["esg_renderer", "scene_proc", "dynamics_proc"])
        if err:
            raise LabError(err, 2 if "usage or configuration" in err else 1)
        self.say_wake_latency(["esg_renderer", "scene_proc", "dynamics_proc"])
        if self.interrupted is not None:
            return
        if self.a.instructor is not None:
            self.start_instructor()
            self.say_wake_latency(["instructor_station"])
        time.sleep(0.2)
        flying = {"timeline": f"the timeline {os.path.basename(self.a.timeline or '')}",
                  "autopilot": "the autopilot",
                  "by-hand": "you, by hand " + ("(the status screen follows; Q quits)" if self.tty
                                                else "from the live window (Q in the window quits)")}[self.pilot]
        lab_hosts = {str(h) for h in self.hosts.values()} != {"localhost"}
        where = f"the lab's hosts ({os.path.basename(self.a.lab)})" if lab_hosts else "this host"
        suffix = f" (channel suffix {self.a.channel_suffix})" if self.a.channel_suffix else ""
        n = "five" if self.a.instructor is not None else "four"
        say(f"{n} processes up on {where}, {self.url}{suffix}; session {self.session_id}; flying: {flying}")
        self.sup.add(self.operator_spec())

    def say_wake_latency(self, names):
        """Says, once for each host and reason, that the processes there
        could not hold the CPUs' wake latency asked for, and why (from
        their ready files; a remote one's log)."""
        if self.wake_latency == "off":
            return
        for n in names:
            state = self.sup.wake_latency_state(n)
            host = "this host" if str(self.hosts[n]) == "localhost" else str(self.hosts[n])
            if not state or state.startswith("held") or (state, host) in self.wake_said:
                continue
            # Said for the host: its other processes ask as this one did
            # (their ready files and logs say each one's).
            self.wake_said.add((state, host))
            what, _, why = state.partition(": ")
            say(f"the CPUs' wake latency is {what} on {host} ({why or 'no reason given'}): the session's "
                f"processes there run on, and the frames reach the pixels later (docs/performance.md "
                f"\"Wake latency\"); run as root, let this user write /dev/cpu_dma_latency, or say "
                f"--cpu-wake-latency-us off")

    def watch(self):
        """Until the pilot ends, a signal comes, or the session must stop."""
        journals = os.path.join(self.out, "journal")
        next_disk = 0.0
        station_said = self.pilot == "by-hand"  # its screen is the terminal's: nothing said over it
        while not self.sup.pilot_done and self.interrupted is None and self.sup.fatal is None:
            self.sup.poll()
            station = self.sup.children.get("operator_station")
            if not station_said and station is not None and station.ready:
                station_said = True
                self.say_wake_latency(["operator_station"])
            now = time.time()
            if now >= next_disk:
                next_disk = now + 1.0
                free = disk.free_bytes(self.out)
                if free < disk.stop_threshold(self.bytes_per_s, journals):
                    self.sup.fatal = (f"the disk of {self.out} is nearly full ({free / disk.MB:.1f} MB left): stopping "
                                      f"the session now, while its record and summary still fit", 1)
            time.sleep(0.05)

    def stop(self):
        self.sup.begin_stop()
        # The station first (by hand it gives the terminal back), then the
        # pipeline, the recorder last so it records everyone's final report.
        self.sup.stop(["operator_station"])
        if self.interrupted is None and self.sup.fatal is None:
            time.sleep(0.5)  # the last frames through the pipeline
        self.sup.stop(["esg_renderer", "scene_proc", "dynamics_proc"])
        if self.a.instructor is not None:
            # Open pages poll once more and show the session ended, with how
            # (docs/instructor.md "The banner").
            time.sleep(1.0)
            self.sup.stop(["instructor_station"])
        time.sleep(0.3)
        self.sup.stop(["lcm-logger"])
        self.sup.record_exit_codes()
        for p in PROCESSES + (["instructor_station"] if self.a.instructor is not None else []):
            h = self.hosts[p]
            if h.remote:
                h.copy_from(f"{self.remote_run}/{p}.json", os.path.join(self.out, "stats", f"{p}.json"))
                h.copy_from(f"{self.remote_run}/journal/{p}.*.lcmlog", os.path.join(self.out, "journal"))
        self.sup.finish_reaper()
        self.notes += session.close_record(self.out)

    def finish(self):
        """The summary and the exit code."""
        if self.sup.fatal:
            say(self.sup.fatal[0])  # why the session stopped, before anything else
        resimulates = session.resimulate(self.out)
        lines, where = session.summarize(self.out, f"{self.name}-{self.session_id}")
        lines, verdict = session.verdict_of(lines, resimulates)  # said last, below
        op = self.sup.children.get("operator_station")
        op_rc = op.exit_code if op and op.exit_code is not None else None
        if self.sup.fatal:
            say("the session stopped early; what it recorded:")
        elif self.interrupted is not None or op_rc == 130:
            say("interrupted: session stopped")
        else:
            say("done; summary:")
        for line in lines:
            say("  " + line)
        for n in self.notes:
            say("note: " + n)
        own = where == os.path.join(self.out, "summary.json")
        say(f"session folder: {self.out} (manifest.json, lcmlog, logs/, frames/"
            f"{', session.mp4' if not self.a.no_video else ''}{', summary.json' if own else ''})")
        if where is not None and not own:
            say(f"summary: {where}")
        if where is None:
            say("no summary could be written (each place tried said why, above)")
        rc = self.exit_code(op, op_rc)
        # Last: whether the record re-simulates (docs/sessions.md "Does it re-simulate").
        say(verdict)
        if rc == 0 and resimulates is not True:
            return session.EXIT_NOT_RESIMULATED
        return rc

    def exit_code(self, op, op_rc):
        if self.sup.fatal:
            return self.sup.fatal[1]
        if self.interrupted is not None or op_rc == 130:
            return 130
        bad = False
        for n in self.sup.order:
            c = self.sup.children[n]
            if n != "operator_station" and c.exit_code not in (0, None):
                say(f"{n} exited with {c.exit_code} (see {c.spec.log_path})")
                bad = True
        if op_rc not in (0, None):
            say(f"operator_station exited with {op_rc} (see {op.spec.log_path})")
            return op_rc
        return 1 if bad else 0


def run(argv, command_line):
    p = argparse.ArgumentParser(prog="scripts/lab demo", description=__doc__)
    add_arguments(p)
    a = p.parse_args(argv)
    d = Demo(a, command_line)
    d.validate()
    if not a.no_build:
        install_and_build()
    require_built("operator_station/operator_station", "dynamics_proc/dynamics_proc", "scene_proc/scene_proc",
                  "esg_renderer/esg_renderer", "tools/rms_session", "tools/rms_resim",
                  *(["instructor_station/instructor_station"] if a.instructor is not None else []))
    if d.branch:
        require_built("tools/rms_resim")
        a.restore = d.branch.make_checkpoint()
    d.layout()
    check_lcm_url(d.url)
    ensure_multicast_route()
    d.checks()
    session.claim_address(d.url, a.channel_suffix, a.share_network, str(d.hosts["recorder"]))
    session.probe_network(d.hosts["recorder"], d.url, a.channel_suffix, a.share_network)
    d.make_session()
    if d.branch:
        d.branch.cleanup()

    def fly():
        d.start()
        d.watch()
    return session.run_then_stop(d, fly)
