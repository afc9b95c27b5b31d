"""Disk space for a session's record (docs/sessions.md "Disk space"): an
estimate before it starts, a watch while it runs, and somewhere else to
write the summary when the session's own disk is full."""
import os
import shutil
import tempfile

from .common import LabError

MB = 1 << 20
# Measured on this project's sessions (the autopilot's, 1024x768; docs/sessions.md
# "Disk space"): the LCM log at 1.73 KB a frame (every channel) with the
# status reports; a PNG frame at 1/110 of its raw RGBA size; the video at
# 0.0026 bytes a pixel a frame (libx264 ultrafast). Taken at about twice
# that, for busier scenes; the margin covers logs and stats.
LOG_BYTES_PER_FRAME = 1800
# The log is written three times over (docs/sessions.md "The record"): the
# processes' journals, what the network delivered (wire.lcmlog), and the
# record made from them at the end (the journals removed once it is made).
LOG_COPIES = 3
STATUS_BYTES_PER_S = 8000
PNG_FRACTION = 1 / 50
VIDEO_BYTES_PER_PIXEL_FRAME = 0.005
SAFETY = 1.5
FLOOR_BYTES = 20 * MB
STOP_BELOW_BYTES = 4 * MB


def session_bytes_per_s(rate_hz, width, height, png_every, video):
    b = (LOG_BYTES_PER_FRAME * rate_hz + STATUS_BYTES_PER_S) * LOG_COPIES
    if png_every > 0:
        b += width * height * 4 * PNG_FRACTION * rate_hz / png_every
    if video:
        b += width * height * VIDEO_BYTES_PER_PIXEL_FRAME * rate_hz
    return b


def free_bytes(path):
    while path and not os.path.exists(path):
        path = os.path.dirname(path)
    return shutil.disk_usage(path or ".").free


def check_room(path, bytes_per_s, duration_s, what):
    """Refuses to start a session its disk cannot hold."""
    need = max(FLOOR_BYTES, bytes_per_s * duration_s * SAFETY)
    free = free_bytes(path)
    if free < need:
        raise LabError(
            f"not enough free space for this session at {path}: {free / MB:.1f} MB free, it needs about "
            f"{need / MB:.0f} MB ({bytes_per_s / 1024:.0f} KB/s for {duration_s:.0f} s, {what}, and a margin). Free "
            f"some, give --out on another disk, or record less (--no-video, --png-every 0, smaller --width/--height).",
            1)
    return need, free


def stop_threshold(bytes_per_s, journal_dir=None):
    """Below this much free space a running session stops, while its record
    and summary still fit: 10 s of writing, at least 4 MB, and at least what
    the record still to be made from the journals needs (their size so far,
    and a tenth more)."""
    return max(STOP_BELOW_BYTES, 10 * bytes_per_s, 1.1 * journal_bytes(journal_dir))


def journal_bytes(journal_dir):
    """The journals' size so far (0 without the folder)."""
    if not journal_dir:
        return 0
    total = 0
    try:
        with os.scandir(journal_dir) as it:
            for e in it:
                try:
                    total += e.stat().st_size
                except OSError:
                    pass
    except OSError:
        return 0
    return total


def fallback_dirs():
    """Where a summary goes when the session's own disk is full."""
    out = []
    for d in (os.environ.get("XDG_RUNTIME_DIR"), "/dev/shm", tempfile.gettempdir(), os.path.expanduser("~"),
              os.getcwd()):
        if d and os.path.isdir(d) and d not in out:
            out.append(d)
    return out
