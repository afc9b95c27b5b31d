"""A sweep's cache of cell results (docs/sessions.md "Sweeps"): one JSON
file a cell, named by its key (the SHA-256 of the session's log, of its
effective configuration and of the software). Written atomically under a
unique temporary name, so sweeps sharing a cache cannot trip each other; an
entry that cannot be read or is not a cell's result counts as missing (the
cell runs again and the entry is written anew)."""
import json
import os
import tempfile

from .common import LabError

# What a cell's result (rms_resim --result-json) holds, with the kinds the table reads.
REQUIRED = {"outcome": dict, "recorded_outcome": dict, "changes": list, "frames_identical": int,
            "frames_compared": int}
OUTCOME = {"acquired": bool, "docked": bool, "reached_s": dict}


def valid_result(res):
    """None when res is a cell's result, else why not."""
    if not isinstance(res, dict):
        return "not a JSON object"
    if "error" in res:
        return f"a failure ({res['error']})"
    for key, kind in REQUIRED.items():
        if not isinstance(res.get(key), kind):
            return f"no '{key}'"
    for part in ("outcome", "recorded_outcome"):
        for key, kind in OUTCOME.items():
            if not isinstance(res[part].get(key), kind):
                return f"no '{part}.{key}'"
    if "first_divergence" not in res:
        return "no 'first_divergence'"
    return None


class Cache:
    def __init__(self, folder):
        self.folder = os.path.abspath(folder)
        try:
            os.makedirs(self.folder, exist_ok=True)
            fd, probe = tempfile.mkstemp(dir=self.folder, prefix=".probe-")
            os.close(fd)
            os.remove(probe)
        except OSError as e:
            raise LabError(f"--cache {folder}: cannot write there ({e.strerror})")
        self.unreadable = []  # (path, why) of entries found but not usable

    def path(self, key):
        return os.path.join(self.folder, key + ".json")

    def load(self, key):
        """The cell's cached result, or None (missing, or unusable: noted)."""
        p = self.path(key)
        try:
            with open(p) as f:
                res = json.load(f)
        except FileNotFoundError:
            return None
        except (OSError, ValueError) as e:
            self.unreadable.append((p, f"cannot be read ({e})"))
            return None
        why = valid_result(res)
        if why:
            self.unreadable.append((p, why))
            return None
        return res

    def store(self, key, res):
        fd, tmp = tempfile.mkstemp(dir=self.folder, prefix=f".{key}.", suffix=".tmp")
        try:
            with os.fdopen(fd, "w") as f:
                json.dump(res, f)
            os.replace(tmp, self.path(key))
        except OSError as e:
            try:
                os.remove(tmp)
            except OSError:
                pass
            raise LabError(f"cannot write the cache {self.folder} ({e.strerror})", 1)
