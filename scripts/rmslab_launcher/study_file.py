"""A study file (docs/studies.md "The study file"): read, checked key by key,
and each subject's order of trials planned from it.

Every error names the file and the key, as the lab's configuration does
(docs/config.md): `boom.toml: key 'conditions[1].cameras': ...`.
"""
import json
import os
import random
import re
import subprocess
import tempfile
import tomllib

from .common import ROOT, LabError, binary

NAME = re.compile(r"[A-Za-z0-9][A-Za-z0-9_.-]{0,63}", re.ASCII)  # a subject's, a condition's, a study's
ORDERS = ("balanced-latin-square", "random")
CONTROL_MODES = ("manual_augmented", "single_joint")
NUM_CAMERA_STATIONS = 8  # base/include/rms/base/config.h kNumCameraStations
MAX_TRIALS = 100         # per condition and kind: far above any study, far below a runaway
MAX_SUBJECTS = 1000
MAX_CONDITIONS = 26

STUDY_KEYS = {"name", "description", "order", "seed", "practice_trials", "measured_trials", "trial_limit_s",
              "subjects", "config", "bindings"}
CONDITION_KEYS = {"name", "description", "set", "cameras", "control", "lesson"}


class StudyFile:
    """The study, checked: `name`, `order`, `seed`, `practice`, `measured`,
    `limit_s`, `subjects`, `config` and `bindings` (absolute paths),
    `conditions` (each a dict: name, description, set {KEY: TOML text},
    cameras, control), `path` and `text` (the file's bytes)."""

    def __init__(self, path):
        self.path = os.path.abspath(path)
        self.file = os.path.basename(path)
        try:
            with open(path, "rb") as f:
                self.text = f.read(1 << 20 + 1)
        except FileNotFoundError:
            raise LabError(f"no such study file: {path}")
        except OSError as e:
            raise LabError(f"cannot read the study file {path} ({e.strerror})")
        if len(self.text) > 1 << 20:
            raise LabError(f"{path}: larger than 1 MiB: not a study file")
        try:
            doc = tomllib.loads(self.text.decode())
        except (tomllib.TOMLDecodeError, UnicodeDecodeError) as e:
            raise LabError(f"{path}: not TOML ({e}) -- a study file (docs/studies.md)")
        self._read(doc)

    def fail(self, key, why):
        raise LabError(f"{self.file}: key '{key}': {why} (docs/studies.md)")

    def _table(self, doc, key, known):
        t = doc.get(key) if isinstance(doc, dict) else None
        if not isinstance(t, dict):
            self.fail(key, "missing, or not a table")
        for k in t:
            if k not in known:
                near = [n for n in known if _close(n, k)]
                self.fail(f"{key}.{k}", "unknown key" + (f" (misspelt? the key is '{key}.{near[0]}')" if near else ""))
        return t

    def _int(self, t, where, key, lo, hi, default=None):
        v = t.get(key, default)
        if v is None:
            self.fail(f"{where}.{key}", "missing (a whole number)")
        if isinstance(v, bool) or not isinstance(v, int) or not lo <= v <= hi:
            self.fail(f"{where}.{key}", f"must be a whole number {lo}..{hi}, got {v!r}")
        return v

    def _name(self, v, key, what):
        if not isinstance(v, str) or not NAME.fullmatch(v):
            self.fail(key, f"{what} must be 1 to 64 letters, digits, '_', '.' or '-', starting with a letter or "
                           f"digit (it names a folder), got {v!r}")
        return v

    def _path(self, t, where, key, default):
        v = t.get(key)
        if v is None:
            return default
        if not isinstance(v, str) or not v:
            self.fail(f"{where}.{key}", "must be a file's path (relative to the study file)")
        p = os.path.normpath(os.path.join(os.path.dirname(self.path), v))
        if not os.path.exists(p):
            self.fail(f"{where}.{key}", f"no such file: {p}")
        if not os.path.isfile(p):
            self.fail(f"{where}.{key}", f"{p} is not a regular file (a folder, a device or a pipe)")
        return p

    def _read(self, doc):
        for k in doc:
            if k not in ("study", "conditions"):
                self.fail(k, "unknown table (a study file has [study] and [[conditions]])")
        s = self._table(doc, "study", STUDY_KEYS)
        self.name = self._name(s.get("name"), "study.name", "a study's name")
        self.description = s.get("description", "")
        if not isinstance(self.description, str):
            self.fail("study.description", "must be text")
        self.order = s.get("order")
        if self.order not in ORDERS:
            self.fail("study.order", f"must be \"{ORDERS[0]}\" or \"{ORDERS[1]}\", got {self.order!r}")
        if self.order == "random":
            self.seed = self._int(s, "study", "seed", 0, 2**63 - 1)
        else:
            if "seed" in s:
                self.fail("study.seed", "is for order = \"random\" only (a balanced Latin square has no seed)")
            self.seed = None
        self.practice = self._int(s, "study", "practice_trials", 0, MAX_TRIALS, default=0)
        self.measured = self._int(s, "study", "measured_trials", 1, MAX_TRIALS)
        self.limit_s = s.get("trial_limit_s")
        if isinstance(self.limit_s, bool) or not isinstance(self.limit_s, (int, float)) or \
                not 1 <= self.limit_s <= 86400:
            self.fail("study.trial_limit_s", f"must be a number of seconds of session time, 1..86400 (a trial "
                                             f"ends there, docked or not), got {self.limit_s!r}")
        subjects = s.get("subjects")
        if not isinstance(subjects, list) or not 1 <= len(subjects) <= MAX_SUBJECTS:
            self.fail("study.subjects", f"must be a list of 1 to {MAX_SUBJECTS} subjects' names")
        for i, n in enumerate(subjects):
            self._name(n, f"study.subjects[{i}]", "a subject's name")
            if n in subjects[:i]:
                self.fail(f"study.subjects[{i}]", f"'{n}' is listed twice")
        self.subjects = subjects
        self.config = self._path(s, "study", "config", os.path.join(ROOT, "config", "rmslab.toml"))
        self.bindings = self._path(s, "study", "bindings", os.path.join(ROOT, "config", "bindings.toml"))
        conds = doc.get("conditions")
        if not isinstance(conds, list) or not 1 <= len(conds) <= MAX_CONDITIONS:
            self.fail("conditions", f"must be 1 to {MAX_CONDITIONS} [[conditions]] tables")
        self.conditions = [self._condition(c, i) for i, c in enumerate(conds)]
        names = [c["name"] for c in self.conditions]
        for i, n in enumerate(names):
            if n in names[:i]:
                self.fail(f"conditions[{i}].name", f"'{n}' is the name of another condition")

    def _condition(self, c, i):
        where = f"conditions[{i}]"
        if not isinstance(c, dict):
            self.fail(where, "must be a table")
        for k in c:
            if k not in CONDITION_KEYS:
                self.fail(f"{where}.{k}", "unknown key (a condition has name, description, set, cameras, control, "
                                          "lesson)")
        name = self._name(c.get("name"), f"{where}.name", "a condition's name")
        desc = c.get("description", "")
        if not isinstance(desc, str):
            self.fail(f"{where}.description", "must be text")
        sets = c.get("set", {})
        if not isinstance(sets, dict):
            self.fail(f"{where}.set", "must be a table of configuration keys (docs/config.md), e.g. "
                                      "set = { \"arm.upper_boom_ft\" = 20.9 }")
        flat = {}
        _flatten(sets, "", flat)
        settings = {}
        for key, value in flat.items():
            try:
                settings[key] = toml_text(value)
            except ValueError as e:
                self.fail(f"{where}.set.{key}", str(e))
        cams = c.get("cameras", list(range(1, NUM_CAMERA_STATIONS + 1)))
        if not isinstance(cams, list) or not cams or any(
                isinstance(x, bool) or not isinstance(x, int) or not 1 <= x <= NUM_CAMERA_STATIONS for x in cams) \
                or len(set(cams)) != len(cams):
            self.fail(f"{where}.cameras", f"must be distinct camera stations 1..{NUM_CAMERA_STATIONS}, at least "
                                          f"one (the subject selects only these), got {cams!r}")
        control = c.get("control", "manual_augmented")
        if control not in CONTROL_MODES:
            self.fail(f"{where}.control", f"must be \"manual_augmented\" or \"single_joint\" (the control mode the "
                                          f"trial starts in), got {control!r}")
        lesson = self._path(c, where, "lesson", None)
        return {"name": name, "description": desc, "set": settings, "cameras": cams, "control": control,
                "lesson": lesson}

    # ---- the designs, checked by the processes' own checks ----
    def write_condition(self, cond, folder):
        """FOLDER/config.toml (the configuration with the condition's keys set
        over it: rms_session design) and FOLDER/bindings.toml (its camera
        set and control mode over the study's bindings), each checked as the
        processes check them; LabError naming the condition's key if not."""
        i = self.conditions.index(cond)
        os.makedirs(folder, exist_ok=True)
        cfg, bnd = os.path.join(folder, "config.toml"), os.path.join(folder, "bindings.toml")
        cmd = [binary("tools/rms_session"), "design", "--config", self.config, "--out", cfg]
        for k, v in cond["set"].items():
            cmd += ["--set", f"{k}={v}"]
        r = subprocess.run(cmd, capture_output=True, text=True)
        if r.returncode != 0:
            why = _tool_error(r)
            m = re.match(r"--set ([^:=]+)(=.*)?: (.*)", why) or re.match(r".*: key '([^']+)': (.*)", why)
            if m and m.group(1) in cond["set"]:
                self.fail(f"conditions[{i}].set.{m.group(1)}", m.group(m.lastindex))
            self.fail(f"conditions[{i}].set", "the design it makes is refused: " + why.replace(cfg, "config.toml"))
        with open(bnd, "w") as f:
            f.write(condition_bindings(_read_text(self.bindings), cond))
        r = subprocess.run([binary("operator_station/operator_station"), "--check", "--manual", "--config", cfg,
                            "--bindings", bnd, "--log-level", "warn"], capture_output=True, text=True)
        if r.returncode != 0:
            self.fail(f"conditions[{i}]", f"its bindings (the study's, with its cameras and control): "
                                          f"{_tool_error(r)}")
        if cond["lesson"]:
            les = os.path.join(folder, "lesson.toml")
            with open(les, "w") as f:
                f.write(_read_text(cond["lesson"]))
            r = subprocess.run([binary("operator_station/operator_station"), "--check", "--autopilot", "--config",
                                cfg, "--lesson", les, "--log-level", "warn"], capture_output=True, text=True)
            if r.returncode != 0:
                self.fail(f"conditions[{i}].lesson", _tool_error(r).replace(les, cond["lesson"]))

    def check_designs(self):
        with tempfile.TemporaryDirectory(prefix="rmslab-study-") as tmp:
            for c in self.conditions:
                self.write_condition(c, os.path.join(tmp, c["name"]))

    # ---- the order ----
    def orders(self):
        """Each subject's order of the conditions (indices): the balanced
        Latin square's rows in turn, or shuffled from the seed."""
        n = len(self.conditions)
        if self.order == "random":
            out = {}
            for s in self.subjects:
                rng = random.Random(f"{self.seed}:{s}")  # a str seed: the same on every Python 3
                out[s] = rng.sample(range(n), n)
            return out
        rows = balanced_latin_square(n)
        return {s: rows[i % len(rows)] for i, s in enumerate(self.subjects)}

    def plan(self):
        """{subject: [trial, ...]}, each trial {trial (from 1), condition,
        kind (practice / measured), index (its number within the condition
        and kind, from 1), of (how many of that kind)}: each condition in the
        subject's order, its practice trials first."""
        out = {}
        for s, order in self.orders().items():
            trials = []
            for ci in order:
                for kind, count in (("practice", self.practice), ("measured", self.measured)):
                    for k in range(1, count + 1):
                        trials.append({"trial": len(trials) + 1, "condition": self.conditions[ci]["name"],
                                       "kind": kind, "index": k, "of": count})
            out[s] = trials
        return out

    def balance_note(self):
        """A balanced Latin square balances order and carry-over only over a
        whole number of its rows' subjects: what to say when it does not."""
        if self.order != "balanced-latin-square":
            return None
        rows = len(balanced_latin_square(len(self.conditions)))
        if len(self.subjects) % rows == 0:
            return None
        return (f"{len(self.subjects)} subjects over a balanced Latin square of {rows} orders: each order "
                f"is flown by a whole number of subjects only with a multiple of {rows}")


def balanced_latin_square(n):
    """Williams's design: rows in which each condition comes once in each
    place and, over the rows, each condition follows each other once (n
    even: n rows; n odd: 2n, the rows and their mirror images)."""
    first, lo, hi = [0], 1, n - 1
    while len(first) < n:
        first.append(lo)
        lo += 1
        if len(first) < n:
            first.append(hi)
            hi -= 1
    rows = [[(c + r) % n for c in first] for r in range(n)]
    if n % 2 == 1:
        rows += [list(reversed(r)) for r in rows]
    return rows


def condition_bindings(text, cond):
    """The study's bindings text with the condition's [control] mode and
    camera set: the keys replaced in the [control] table (any other table
    kept as written)."""
    out, in_control, done = [], False, False
    for line in text.splitlines():
        head = re.match(r"\s*\[([^\]]*)\]", line)
        if head:
            in_control = head.group(1).strip() == "control"
            out.append(line)
            if in_control and not done:
                out.append(f"mode = \"{cond['control']}\"")
                out.append("cameras = [" + ", ".join(str(c) for c in cond["cameras"]) + "]")
                done = True
            continue
        if in_control and re.match(r"\s*(mode|cameras)\s*=", line):
            continue
        out.append(line)
    if not done:
        out += ["[control]", f"mode = \"{cond['control']}\"",
                "cameras = [" + ", ".join(str(c) for c in cond["cameras"]) + "]"]
    return "\n".join(out) + "\n"


def toml_text(value):
    """A TOML value's text, as --set takes it."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, int):
        return str(value)
    if isinstance(value, float):
        return repr(value)  # the shortest text that reads back the same double
    if isinstance(value, str):
        return json.dumps(value)
    if isinstance(value, list):
        return "[" + ", ".join(toml_text(v) for v in value) + "]"
    raise ValueError(f"a {type(value).__name__} is no configuration value (numbers, text, arrays)")


def _flatten(node, prefix, out):
    for k, v in node.items():
        key = f"{prefix}.{k}" if prefix else k
        if isinstance(v, dict):
            _flatten(v, key, out)
        else:
            out[key] = v


def _close(a, b):
    return a != b and (a.startswith(b[:3]) or b.startswith(a[:3])) and abs(len(a) - len(b)) <= 2


def _read_text(path):
    with open(path) as f:
        return f.read()


def _tool_error(r):
    lines = [line for line in (r.stderr or r.stdout).strip().splitlines() if line.strip()]
    text = lines[-1] if lines else f"refused (exit code {r.returncode})"
    text = re.sub(r"^\[[^\]]*\] \[[a-z_]+\] \[[a-z]+\] ", "", text)  # a process's log prefix
    return re.sub(r"^(rms_session|operator_station): ", "", text)
