"""A sweep's cache of cell results (docs/sessions.md "Sweeps"): one JSON
file a cell, named by its key (the SHA-256 of the session's log, of its
effective configuration and of the software). Written atomically under a
unique temporary name, so sweeps sharing a cache cannot trip each other; an
entry that cannot be read or is not a cell's result counts as missing (the
cell runs again and the entry is written anew).

An entry is untrusted (docs/security.md "Session folders are untrusted"):
it is read only as a regular file of at most 16 MiB (a link, a FIFO or a
device is refused, not followed, waited on or read without end), and it
carries its key and the SHA-256 of its result: an entry whose key is not
its name's or whose result does not match its checksum (edited by hand,
or damaged) is refused, said, and made again."""
import hashlib
import json
import os
import tempfile

from .common import LabError, read_folder_file

MAX_ENTRY_BYTES = 16 << 20
ENTRY_FORMAT = "rmslab-sweep-cell-1"


def _checksum(res):
    """The SHA-256 of a result's canonical JSON."""
    return hashlib.sha256(json.dumps(res, sort_keys=True, separators=(",", ":")).encode()).hexdigest()


class CannotWrite(LabError):
    """An entry could not be written (a full disk, a folder taken away)."""


# The process's umask (read once, at the start): an entry is made as an
# ordinary file is (mkstemp makes its file 0600), so a cache shared by a
# lab's users is readable by them.
_UMASK = os.umask(0)
os.umask(_UMASK)


def _number(x):
    return (isinstance(x, (int, float)) and not isinstance(x, bool)) or x is None


def _integer(x):
    return type(x) is int or x is None  # noqa: E721 (a bool is no integer here)


def _outcome_why(o, name):
    if not isinstance(o, dict):
        return f"'{name}' is not an object"
    checks = [("acquired", lambda x: type(x) is bool), ("docked", lambda x: type(x) is bool),  # noqa: E721
              ("final_mode", _integer), ("collisions", _integer), ("held_frames", _integer),
              ("reached_s", lambda x: isinstance(x, dict) and all(_number(v) for v in x.values())),
              ("phase_durations_s",
               lambda x: x is None or (isinstance(x, dict) and all(_number(v) for v in x.values()))),
              ("docking", lambda x: x is None or (isinstance(x, dict) and all(_number(v) for v in x.values())))]
    for key, ok in checks:
        if key not in o or not ok(o[key]):
            return f"'{name}.{key}' is missing or of the wrong kind"
    return None


# A closed-loop sweep's flight (rms_fly's line): each field the table reads, and its kind.
FLIGHT_FIELDS = {"subject": lambda x: x in ("autopilot", "scripted"), "run": lambda x: type(x) is int,  # noqa: E721
                 "docked": lambda x: type(x) is bool, "failure": lambda x: isinstance(x, str),  # noqa: E721
                 "time_s": _number, "acquired_s": _number, "cleared_s": _number, "docked_s": _number,
                 "collision_events": _integer, "held_frames": _integer, "key_actions": _integer}


def _flights_why(flights):
    if not isinstance(flights, list) or not flights:
        return "'flights' is missing or empty"
    for f in flights:
        if not isinstance(f, dict):
            return "a flight is not an object"
        for key, ok in FLIGHT_FIELDS.items():
            if key not in f or not ok(f[key]):
                return f"a flight's '{key}' is missing or of the wrong kind"
    return None


def valid_result(res):
    """None when res is a cell's result (rms_resim --result-json, or a
    closed-loop cell's {"flights": [...]} from rms_fly --cells; every field
    the table reads, of its kind), else why not."""
    if not isinstance(res, dict):
        return "not a JSON object"
    if "error" in res:
        return f"a failure ({res['error']})"
    if "flights" in res:
        return _flights_why(res["flights"])
    for name in ("outcome", "recorded_outcome"):
        why = _outcome_why(res.get(name), name)
        if why:
            return why
    for name in ("frames_identical", "frames_compared"):
        if type(res.get(name)) is not int:  # noqa: E721
            return f"'{name}' is missing or not an integer"
    changes = res.get("changes")
    if not isinstance(changes, list) or not all(isinstance(c, dict) and isinstance(c.get("field"), str)
                                                for c in changes):
        return "'changes' is missing or not a list of changes"
    for name in ("first_divergence", "first_difference"):
        d = res.get(name)
        if d is not None and not (isinstance(d, dict) and _integer(d.get("frame")) and _number(d.get("time_s"))):
            return f"'{name}' is of the wrong kind"
    if "first_divergence" not in res:
        return "'first_divergence' is missing"
    if not isinstance(res.get("note", ""), str):
        return "'note' is not text"
    return None


class Cache:
    def __init__(self, folder, must_exist=False):
        self.folder = os.path.abspath(folder)
        if must_exist and not os.path.isdir(self.folder):
            raise LabError(f"--cache {folder}: no such folder (--cached-only reads an existing cache)")
        try:
            os.makedirs(self.folder, exist_ok=True)
            fd, probe = tempfile.mkstemp(dir=self.folder, prefix=".probe-")
            os.close(fd)
            os.remove(probe)
        except OSError as e:
            raise LabError(f"--cache {folder}: cannot write there ({e.strerror})")
        self.unreadable = []  # (path, why) of entries found but not usable

    def path(self, key):
        if not (isinstance(key, str) and len(key) == 64 and all(c in "0123456789abcdef" for c in key)):
            raise LabError(f"a cache key must be a SHA-256 (64 hex digits), not {key!r}")
        return os.path.join(self.folder, key + ".json")

    def load(self, key):
        """The cell's cached result, or None (missing, or unusable: noted)."""
        p = self.path(key)
        if not os.path.lexists(p):
            return None
        try:
            entry = json.loads(read_folder_file(p, MAX_ENTRY_BYTES, "a cache entry"))
        except LabError as e:
            self.unreadable.append((p, str(e)))
            return None
        except (ValueError, RecursionError) as e:
            self.unreadable.append((p, f"cannot be read ({type(e).__name__}: {str(e)[:80]})"))
            return None
        if not isinstance(entry, dict) or entry.get("format") != ENTRY_FORMAT:
            self.unreadable.append((p, "not a checksummed entry (edited, or written by an older rmslab)"))
            return None
        res = entry.get("result")
        if entry.get("key") != key:
            self.unreadable.append((p, "its key is not its name's (another cell's entry, renamed)"))
            return None
        if entry.get("sha256") != _checksum(res):
            self.unreadable.append((p, "its result does not match its checksum (edited by hand, or damaged)"))
            return None
        why = valid_result(res)
        if why:
            self.unreadable.append((p, why))
            return None
        return res

    def store(self, key, res):
        fd, tmp = tempfile.mkstemp(dir=self.folder, prefix=f".{key}.", suffix=".tmp")
        try:
            os.fchmod(fd, 0o666 & ~_UMASK)
            with os.fdopen(fd, "w") as f:
                entry = {"format": ENTRY_FORMAT, "key": key, "sha256": _checksum(res), "result": res}
                f.write(json.dumps(entry))  # (json.dump's text, by the C encoder: it does not use it)
            os.replace(tmp, self.path(key))
        except OSError as e:
            try:
                os.remove(tmp)
            except OSError:
                pass
            raise CannotWrite(f"cannot write the cache {self.folder} ({e.strerror})", 1)
