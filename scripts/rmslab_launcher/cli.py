"""scripts/lab: lab sessions (docs/sessions.md).

  scripts/lab demo [--out DIR] [--timeline FILE | --by-hand [--bindings FILE]] [--autopilot-straight]
                   [--subject NAME] [--note TEXT]
                   [--restore CHECKPOINT | --from SESSION@TIME] [--lab LABFILE] [--config FILE] [--speed X]
                   [--png-every N] [--width W] [--height H] [--no-video] [--window]
                   [--instructor [PORT]] [--gl osmesa|egl] [--visibility priority|depth]
                   [--lcm-url URL] [--channel-suffix S] [--share-network]
                   [--cpu-wake-latency-us US|off] [--no-build]
  scripts/lab replay SESSION [options]       scene and ESG driven from the log: frames, video
  scripts/lab resim SESSION [--config FILE] [--set KEY=VALUE]  the DCP again on the recorded inputs
  scripts/lab sweep SESSION... --vary KEY=V1,V2,... [--hosts LABFILE | --slurm]
                                             the same inputs under every design: one table
  scripts/lab sweep --closed-loop --vary KEY=V1,V2,... [--runs N] [--seed S]
                                             every design flown afresh by virtual subjects
  scripts/lab export SESSION [--mcap]        every channel to CSV, or the log as MCAP
  scripts/lab report SESSION                 one self-contained HTML report
  scripts/lab debrief SESSION [--port N]     the instructor's page over a recorded session: scrub, mark
  scripts/lab compare SESSION...             scorecards side by side, learning curves
  scripts/lab study check|run|status STUDY   a study of subjects, conditions and trials (docs/studies.md)
  scripts/lab monitor [--lcm-url URL]        live decoded traffic per channel
  scripts/lab control [--session DIR] freeze|run|step [N]|reset|checkpoint NAME|restore NAME|FILE [--run]
                      | malfunction WHAT... | repair WHAT...   e.g. malfunction joint 2 stuck

demo: installs what is missing, builds, checks every file the session will
use (refusing, with the reason, what is wrong), looks for another session on
its address, checks the disk, then starts the recorder and the four
processes over LCM UDP multicast (on this host, TTL 0; or on a lab's hosts,
--lab), each in a process group of its own, and lets the autopilot fly the
whole task (acquire, extract, dock) -- or flies a timeline (--timeline), or
lets you fly by hand (--by-hand: this terminal's keys and status screen, and
with --window the live window's keys too; Q ends it; --bindings FILE for
other keys, docs/operator.md). It restarts a process that dies, stops the
session when the disk fills, writes PNG frames, the video (session.mp4) and
summary.json, and stops everything at the end, on Ctrl-C, when the terminal
closes -- and, through its reaper, when it is itself killed. Each other
command explains itself with --help.
"""
import os
import sys

from . import demo, replay, study, sweep, tools
from .common import LabError, say


def main(argv):
    # The launcher's own request to its processes (demo sets it): one left
    # in the shell would reach the processes of a replay, or the checks.
    os.environ.pop("RMSLAB_CPU_WAKE_LATENCY_US", None)
    cmd = argv[0] if argv else "help"
    rest = argv[1:]
    try:
        if cmd == "demo":
            return demo.run(rest, "scripts/lab demo " + " ".join(rest))
        if cmd == "replay":
            return replay.run(rest)
        if cmd == "sweep":
            return sweep.run(rest)
        if cmd == "study":
            return study.run(rest)
        if cmd in ("resim", "export", "report", "compare", "monitor", "control", "debrief"):
            return getattr(tools, cmd)(rest)
        if cmd in ("help", "-h", "--help"):
            print(__doc__.split("\n", 2)[2])
            return 0
        say(f"unknown command '{cmd}'")
        print(__doc__.split("\n", 2)[2], file=sys.stderr)
        return 2
    except LabError as e:
        for line in str(e).splitlines():
            say(line)
        return e.code
    except KeyboardInterrupt:
        say("interrupted before the session started")
        return 130
    except BrokenPipeError:
        return 1
    except (OSError, UnicodeError) as e:
        # Nothing the checks foresaw: said plainly, not as a traceback.
        say(f"error: {e}")
        return 2


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
