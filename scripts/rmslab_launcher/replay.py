"""scripts/lab replay SESSION: scene_proc and esg_renderer driven from a
recorded session's log -- lcm-logplayer plays its RMS_DCP_FRAME messages at
their recorded pace (times --speed) -- make its ESG frames, PNG frames and
video again into a new session folder (default SESSION/replay-<UTC time>),
then compares the replayed ESG frames with the recorded ones word for word:
exit 0 only if all are identical."""
import argparse
import json
import os
import signal
import subprocess
import time

from . import disk, session
from .common import (DEFAULT_REPLAY_URL, MAX_CONFIG_BYTES, LabError, binary, check_lcm_url, check_speed,
                     ensure_multicast_route, install_and_build, read_folder_file, read_folder_json, require_built,
                     require_session_file, say)
from .hosts import Host
from .supervisor import Spec, Supervisor


def manifest(path):
    """The recorded session's manifest, read as untrusted (read_folder_json)."""
    return read_folder_json(os.path.join(path, "manifest.json"))


class Replay:
    def __init__(self, a):
        self.a = a
        self.interrupted = None
        self.src = os.path.abspath(a.session)
        m = manifest(self.src)
        self.suffix = m.get("lcm", {}).get("channel_suffix", "")
        # The replayed frames carry the recorded session's id: the replay's
        # processes take them as their own session's.
        self.session_id = m.get("session_id", "")
        self.message_auth = m.get("message_auth")
        # The replayed frames carry the recorded session's tags: its key
        # checks them, and tags what the replay's processes send. Read (and
        # refused) before any folder is made.
        self.key = session.read_session_key(self.src) if self.message_auth else None
        if self.message_auth and not self.key:
            raise LabError(f"{self.src}/run/{session.SESSION_KEY} is missing: the session's messages carry tags "
                           f"(manifest.json message_auth), and without its key they cannot be replayed")

    def make(self):
        a = self.a
        out = a.out or os.path.join(self.src, "replay-" + time.strftime("%Y%m%dT%H%M%SZ", time.gmtime()))
        self.out = session.make_folder(out, self.src)
        os.makedirs(os.path.join(self.out, "journal"), exist_ok=True)
        # Its configuration, read as untrusted: a link, a FIFO or /dev/zero
        # there is refused, not copied without end (docs/security.md).
        config = read_folder_file(os.path.join(self.src, "config.toml"), MAX_CONFIG_BYTES,
                                  "the session's configuration")
        with open(os.path.join(self.out, "config.toml"), "wb") as f:
            f.write(config)
        with open(os.path.join(self.out, "run", "pilot"), "w") as f:
            f.write("replay\n")
        fields = [("--pilot", "replay"), ("--lcm-url", a.lcm_url), ("--command", f"scripts/lab replay {self.src}"),
                  ("--kind", "replay"), ("--parent", os.path.abspath(self.src))]
        if self.suffix:
            fields.append(("--channel-suffix", self.suffix))
        if self.session_id:
            fields.append(("--session-id", self.session_id))
        key = self.key
        self.key_file = session.write_session_key(os.path.join(self.out, "run"), key) if key else None
        if key:
            fields.append(("--message-auth", session.MESSAGE_AUTH))
        session.write_manifest(self.out, fields)
        summary = read_folder_json(os.path.join(self.src, "summary.json"))
        # The log plays at its recorded pace: its wall time, not its session
        # time (a session flown at --speed 2 has half as much).
        self.duration = float(summary.get("wall_duration_s", 0) or summary.get("duration_s", 0) or 0)
        rate = 30.0 * self.speed
        self.bytes_per_s = disk.session_bytes_per_s(rate, a.width, a.height, a.png_every, not a.no_video)
        disk.check_room(self.out, self.bytes_per_s, (self.duration or 120) / self.speed, "the replay")
        say(f"replaying {self.src} into {self.out}")

    def spec(self, name, extra):
        ready = os.path.join(self.out, "run", f"{name}.ready")
        argv = [binary(f"{name}/{name}"), "--config", os.path.join(self.out, "config.toml"), "--lcm-url",
                self.a.lcm_url, "--stats", os.path.join(self.out, "stats", f"{name}.json"), "--ready-file", ready,
                "--journal-dir", os.path.join(self.out, "journal")]
        if self.suffix:
            argv += ["--channel-suffix", self.suffix]
        return Spec(name, Host("localhost"), argv + extra, os.path.join(self.out, "logs", f"{name}.log"),
                    ready=lambda c: os.path.exists(ready))

    def run(self):
        a = self.a
        env = {"RMSLAB_SESSION_ID": self.session_id} if self.session_id else {}
        if self.key_file:
            env["RMSLAB_SESSION_KEY_FILE"] = self.key_file
        self.sup = Supervisor(os.path.join(self.out, "run"), env)
        self.sup.start_reaper(self.out, [binary("tools/rms_session"), "summary", self.out])
        for sig in (signal.SIGINT, signal.SIGTERM, signal.SIGHUP):
            signal.signal(sig, lambda s, f: setattr(self, "interrupted", s))
        chans = f"RMS_(DCP_FRAME|ESG_FRAME|STATUS){self.suffix}"
        log = os.path.join(self.out, session.WIRE_LOG)
        self.sup.add(Spec("lcm-logger", Host("localhost"),
                          ["lcm-logger", f"--lcm-url={a.lcm_url}", "--force", "--quiet", f"--channel={chans}", log],
                          os.path.join(self.out, "logs", "lcm-logger.log"), ready=lambda c: os.path.exists(log),
                          lifeline=False, restart=False))
        esg = ["--width", str(a.width), "--height", str(a.height), "--png-dir", os.path.join(self.out, "frames"),
               "--png-every", str(a.png_every)]
        if not a.no_video:
            esg += ["--video", os.path.join(self.out, "session.mp4")]
        self.sup.add(self.spec("esg_renderer", esg))
        # Nothing in a replay is real time: a stall slows it, no frame is dropped as late.
        self.sup.add(self.spec("scene_proc", ["--every-frame"]))
        err = self.sup.wait_ready(["lcm-logger", "esg_renderer", "scene_proc"])
        if err:
            raise LabError(err, 1)
        time.sleep(0.2)
        player = ["lcm-logplayer", "-s", str(self.speed), "-e", f"^RMS_DCP_FRAME{self.suffix}$", "-l", a.lcm_url,
                  os.path.join(self.src, "lcmlog")]
        self.sup.add(Spec("lcm-logplayer", Host("localhost"), player,
                          os.path.join(self.out, "logs", "lcm-logplayer.log"), pilot=True, lifeline=False))
        start = time.time()
        next_say = start + 2
        while not self.sup.pilot_done and self.interrupted is None and self.sup.fatal is None:
            self.sup.poll()
            if time.time() >= next_say and self.duration:
                next_say += 2
                done = min(100.0, 100 * (time.time() - start) * self.speed / self.duration)
                say(f"replay {done:3.0f}% ({(time.time() - start) * self.speed:.0f} of {self.duration:.0f} s)")
            time.sleep(0.05)
        if self.sup.pilot_done:
            time.sleep(1.0)  # the last frames through the scene and the renderer

    def stop(self):
        self.sup.begin_stop()
        self.sup.stop(["lcm-logplayer", "esg_renderer", "scene_proc"])
        time.sleep(0.3)
        self.sup.stop(["lcm-logger"])
        self.sup.record_exit_codes()
        self.sup.finish_reaper()
        for n in session.close_record(self.out):
            say("note: " + n)

    def finish(self):
        lines, summary_path = session.summarize(self.out, os.path.basename(self.out))
        for line in lines:
            if line.startswith(("video:", "renderer:", "the record lost")):
                say(line)
        if self.sup.fatal:
            say(self.sup.fatal[0])
            return self.sup.fatal[1]
        if self.interrupted is not None:
            say("interrupted")
            return 130
        player = self.sup.children["lcm-logplayer"]
        if player.exit_code not in (0, None):
            say(f"lcm-logplayer failed: {open(player.spec.log_path, errors='replace').read().strip()}")
            return 1
        bad = [n for n in ("esg_renderer", "scene_proc", "lcm-logger")
               if self.sup.children[n].exit_code not in (0, None)]
        for n in bad:
            say(f"{n} exited with {self.sup.children[n].exit_code} (see {self.sup.children[n].spec.log_path})")
        if bad:
            return 1
        say(f"replay done: {self.out} (lcmlog, frames/{'' if self.a.no_video else ', session.mp4'})")
        r = subprocess.run([binary("tools/rms_session"), "compare-esg", self.src, self.out],
                           capture_output=True, text=True)
        if r.returncode != 0 and r.stderr.strip():
            say("compare-esg: " + r.stderr.strip())
        with open(os.path.join(self.out, "replay_comparison.json"), "w") as f:
            f.write(r.stdout)
        if r.returncode == 0:
            c = json.loads(r.stdout)
            say(f"every ESG frame identical to the recording, word for word (identical: {c['identical']})")
            return 0
        try:
            c = json.loads(r.stdout)
        except ValueError:
            c = None
        lost, missed, late = reported_losses(self.out, summary_path)
        if c and c["identical"] + c["missing"] == c["recorded"] and c["missing"] <= lost + missed + late:
            # No frame differs, and every one missing is one a reported loss
            # accounts for (a loaded machine at --speed above 1).
            say(f"every ESG frame replayed identical to the recording, word for word (identical: {c['identical']}); "
                f"{c['missing']} not in the replay's log, each a reported loss (the record lost {lost} ESG frames, "
                f"scene_proc missed {missed} DCP frames and dropped {late} that came too late)")
            return 0
        say("the replay differs from the recording: " + " ".join(r.stdout.split()))
        return 1


def reported_losses(out, summary_path):
    """The losses the replay reported: ESG frames its record lost (its
    summary), DCP frames that never reached scene_proc (its counter
    dcp.missing) and those it dropped as too late to act on (dropped.late:
    a stalled, loaded machine; docs/protocol.md "Frame numbers and times"). Each is 0
    when its file is not there."""
    lost = missed = late = 0
    try:
        with open(summary_path or os.path.join(out, "summary.json")) as f:
            lost = int(json.load(f)["record"]["by_channel"]["RMS_ESG_FRAME"]["lost"])
    except (OSError, ValueError, KeyError, TypeError):
        pass
    try:
        with open(os.path.join(out, "stats", "scene_proc.json")) as f:
            counters = json.load(f)["counters"]
        missed, late = int(counters.get("dcp.missing", 0)), int(counters.get("dropped.late", 0))
    except (OSError, ValueError, KeyError, TypeError, AttributeError):
        missed = late = 0
    return lost, missed, late


def run(argv):
    p = argparse.ArgumentParser(prog="scripts/lab replay", description=__doc__)
    p.add_argument("session")
    p.add_argument("--out")
    p.add_argument("--speed", default="1")
    p.add_argument("--width", type=int, default=1024)
    p.add_argument("--height", type=int, default=768)
    p.add_argument("--png-every", type=int, default=30)
    p.add_argument("--no-video", action="store_true")
    p.add_argument("--lcm-url", default=DEFAULT_REPLAY_URL)
    p.add_argument("--no-build", action="store_true")
    a = p.parse_args(argv)
    require_session_file(a.session)
    r = Replay(a)
    r.speed = check_speed(a.speed)
    check_lcm_url(a.lcm_url)
    if not a.no_build:
        install_and_build()
    require_built("scene_proc/scene_proc", "esg_renderer/esg_renderer", "tools/rms_session")
    ensure_multicast_route()
    r.make()
    return session.run_then_stop(r, r.run)
