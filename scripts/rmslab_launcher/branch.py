"""scripts/lab demo --from SESSION@TIME: a session branched from a recorded
one (docs/sessions.md "Branching"). The recorded inputs are re-simulated up
to the instant, word for word (rms_resim --until), the DCP's state there
becomes the new session's checkpoint (--restore), and the controls go to
the pilot of the new session: the autopilot, a timeline or a person."""
import atexit
import os
import re
import shutil
import subprocess
import tempfile

from .common import LabError, binary, file_sha256, frame_rate_hz, say

INSTANT = re.compile(r"^(?P<session>.+)@(?:(?P<time>\d+(?:\.\d*)?|\.\d+)s?|f(?:rame)?(?P<frame>\d+))$")


class Branch:
    """The parent session and the instant of --from SESSION@TIME
    (seconds of session time, e.g. @20 or @20.5s) or SESSION@fFRAME (a DCP
    frame, e.g. @f600)."""

    def __init__(self, text):
        m = INSTANT.match(text)
        if not m:
            raise LabError(f"--from '{text}': must be SESSION@TIME (seconds, e.g. sessions/X@20.5) "
                           f"or SESSION@fFRAME (a DCP frame, e.g. sessions/X@f600)")
        self.text = text
        self.parent = os.path.abspath(m.group("session"))
        for f in ("lcmlog", "config.toml", "manifest.json"):
            if not os.path.isfile(os.path.join(self.parent, f)):
                raise LabError(f"--from {text}: {m.group('session')} is not a recorded session (no {f})")
        self.rate = frame_rate_hz(os.path.join(self.parent, "config.toml"))
        if m.group("frame") is not None:
            self.frame = int(m.group("frame"))
        else:
            self.frame = int(round(float(m.group("time")) * self.rate))
        self.time_s = self.frame / self.rate
        self.checkpoint = None

    def make_checkpoint(self):
        """The recorded inputs re-simulated up to the instant; the DCP's
        state there, a checkpoint file. Refused (with rms_resim's reason)
        when the recording does not re-simulate word for word up to it."""
        self.folder = tempfile.mkdtemp(prefix="rmslab-branch-")
        atexit.register(shutil.rmtree, self.folder, True)  # however the launcher ends
        self.checkpoint = os.path.join(self.folder, "branch.json")
        r = subprocess.run([binary("tools/rms_resim"), self.parent, "--until", str(self.frame),
                            "--checkpoint-out", self.checkpoint, "--quiet"], capture_output=True, text=True)
        if r.returncode != 0:
            shutil.rmtree(self.folder, True)
            why = (r.stderr.strip() or r.stdout.strip()).replace("rms_resim: ", "")
            raise LabError(f"--from {self.text} (DCP frame {self.frame}): {why}", 2 if r.returncode == 2 else 1)
        first = r.stdout.splitlines()[0] if r.stdout else ""
        say(f"branch: {self.parent} re-simulated up to DCP frame {self.frame} ({self.time_s:.2f} s): {first}")
        return self.checkpoint

    def cleanup(self):
        """The temporary checkpoint, once the session has its own copy (run/restore.json)."""
        if self.checkpoint:
            shutil.rmtree(os.path.dirname(self.checkpoint), True)

    def manifest_fields(self):
        return [("--branch-of", self.parent), ("--branch-frame", str(self.frame)),
                ("--branch-time", f"{self.time_s:.9g}"),
                ("--branch-parent-log-sha256", file_sha256(os.path.join(self.parent, "lcmlog")))]
