"""A session folder and what is done to it before and after its processes
run: the folder, the id, the manifest, the checks (files, network, disk),
the record's parts, the summary (docs/sessions.md)."""
import errno
import json
import os
import stat
import tempfile
import secrets
import shutil
import subprocess
import time

from . import disk
from .common import LabError, binary, say

CHANNELS = ["RMS_OPERATOR_INPUT", "RMS_OPERATOR_STATE", "RMS_WINDOW_KEYS", "RMS_DCP_FRAME", "RMS_DCP_TELEMETRY",
            "RMS_DCP_STATE", "RMS_ESG_FRAME", "RMS_STATUS", "RMS_CONTROL", "RMS_CONTROL_ANSWER"]


def new_session_id():
    """A random 63-bit id, never 0 (0 is "no session"), as the manifest writes it."""
    return f"0x{secrets.randbits(63) | 1:016x}"


def run_then_stop(owner, body):
    """demo and replay alike: body() runs the session; a LabError in it is the
    session's fatal reason; the session is stopped whatever happened; then
    owner.finish() says how it went and gives the exit code."""
    try:
        body()
    except LabError as e:
        if not hasattr(owner, "sup"):
            raise
        owner.sup.fatal = (str(e), e.code)
    finally:
        if hasattr(owner, "sup"):
            owner.stop()
    return owner.finish()


def make_folder(out, default_parent):
    """A new session folder, made by the one writer of them (rms_session
    folder: docs/sessions.md "The session folder"); its absolute path."""
    if not out:
        out = os.path.join(default_parent, time.strftime("%Y%m%dT%H%M%SZ", time.gmtime()))
    r = subprocess.run([binary("tools/rms_session"), "folder", out], capture_output=True, text=True)
    if r.returncode != 0:
        msg = r.stderr.strip().removeprefix("rms_session: ")
        raise LabError(f"--out {msg}" if "already holds" not in msg else msg)
    return r.stdout.strip()


SESSION_KEY = "session.key"  # in the session's run/ (docs/security.md "Authenticated messages")
MESSAGE_AUTH = "blake2b-128"


def write_session_key(run_dir, key_hex=None):
    """The session's secret key (32 random bytes, as 64 hex digits), written
    as run/session.key readable by its owner only, never over a file or
    through a link; its path. key_hex: a key already made (a replay's, its
    recorded session's)."""
    path = os.path.join(run_dir, SESSION_KEY)
    fd = os.open(path, os.O_WRONLY | os.O_CREAT | os.O_EXCL | os.O_NOFOLLOW | os.O_CLOEXEC, 0o600)
    with os.fdopen(fd, "w") as f:
        f.write((key_hex or secrets.token_hex(32)) + "\n")
    return path


def read_session_key(session_dir):
    """A session's key (64 hex digits) when its manifest says its messages
    carry tags, else None; a key that cannot be read is a LabError."""
    path = os.path.join(session_dir, "run", SESSION_KEY)
    try:
        fd = os.open(path, os.O_RDONLY | os.O_NOFOLLOW | os.O_CLOEXEC | os.O_NONBLOCK)
    except FileNotFoundError:
        return None
    except OSError as e:
        raise LabError(f"session key {path}: cannot be read ({e.strerror}"
                       f"{': a link is not followed' if e.errno == errno.ELOOP else ''})")
    with os.fdopen(fd) as f:
        st = os.fstat(f.fileno())
        if not stat.S_ISREG(st.st_mode):
            raise LabError(f"session key {path}: not a regular file")
        if st.st_uid != os.geteuid() and os.geteuid() != 0:
            raise LabError(f"session key {path}: owned by uid {st.st_uid}, not by this user")
        if st.st_mode & 0o077:
            raise LabError(f"session key {path}: readable or writable by others (chmod 600 it)")
        text = f.read(66).strip()
    if len(text) != 64 or any(c not in "0123456789abcdefABCDEF" for c in text):
        raise LabError(f"{path}: not 64 hex digits")
    return text


def precheck(checks):
    """Runs each process with --check before anything starts: a bad file or
    option is refused here, its message shown (exit 2). checks: [(name, argv)]."""
    for name, argv in checks:
        r = subprocess.run(argv + ["--check", "--log-level", "warn"], capture_output=True, text=True)
        if r.returncode != 0:
            lines = []
            for line in (r.stderr + r.stdout).splitlines():
                # "[time] [process] [level] message" -> "message"
                parts = line.split("] ", 3)
                lines.append(parts[-1] if len(parts) == 4 and line.startswith("[") else line)
            raise LabError(f"{name} refuses to start:\n" + "\n".join("  " + line for line in lines if line.strip()))


def probe_network(host, url, suffix, share):
    """Another session already on this address and channels? Refused unless
    share (--share-network); one on other channels is only noted."""
    r = host.run([binary("tools/rms_session"), "probe", "--lcm-url", url, "--seconds", "1.2"], capture_output=True,
                 text=True)
    if r.returncode != 0:
        # The processes could not open it either.
        raise LabError(f"cannot listen on {url}: {r.stderr.strip()}")
    ours = {c + suffix for c in CHANNELS}
    for s in json.loads(r.stdout).get("sessions", []):
        chans = set(s["channels"])
        who = ", ".join(s["senders"][:4])
        if chans & ours:
            msg = (f"another session is running on {url} on this session's channels: session {s['session_id']} "
                   f"({who}; {', '.join(sorted(chans & ours)[:3])}). Sessions on one address and channels see each "
                   f"other's traffic (each drops the other's, but they share the link); give this one "
                   f"--channel-suffix NAME or another --lcm-url, or --share-network to run beside it anyway.")
            if not share:
                raise LabError(msg, 1)
            say("--share-network: " + msg.split(". ")[0])
        else:
            say(f"note: another station is on {url}, on other channels (session {s['session_id']}, "
                f"{', '.join(sorted(chans)[:2])}): not affected")


_address_lock = None  # held for the launcher's life


def private_dir():
    """This user's own folder for locks and temporary files
    (docs/security.md "Locks and temporary files"): $XDG_RUNTIME_DIR/rmslab,
    else /tmp/rmslab-UID, made 0700; refused, with what is wrong, when it is
    a link, not a folder, another user's, or open to others."""
    base = os.environ.get("XDG_RUNTIME_DIR")
    path = os.path.join(base, "rmslab") if base and os.path.isabs(base) else \
        os.path.join(tempfile.gettempdir(), f"rmslab-{os.getuid()}")
    try:
        os.mkdir(path, 0o700)
    except FileExistsError:
        pass
    except OSError as e:
        raise LabError(f"cannot make {path} for this user's locks: {e.strerror}", 2)
    st = os.lstat(path)
    if not stat.S_ISDIR(st.st_mode):
        raise LabError(f"{path} should be this user's folder for locks but is a "
                       f"{'link' if stat.S_ISLNK(st.st_mode) else 'file'}: remove it (or set XDG_RUNTIME_DIR)", 2)
    if st.st_uid != os.getuid():
        raise LabError(f"{path} belongs to {_user_name(st.st_uid)}, not to you: another user made it to take "
                       f"this user's locks. Remove it (or set XDG_RUNTIME_DIR)", 2)
    if st.st_mode & 0o077:
        os.chmod(path, 0o700)
    return path


def _user_name(uid):
    try:
        import pwd
        return f"user {pwd.getpwuid(uid).pw_name} (uid {uid})"
    except (KeyError, ImportError):
        return f"uid {uid}"


def open_private(name, flags=os.O_RDWR | os.O_CREAT):
    """A file in private_dir(), opened without following a link (O_NOFOLLOW,
    O_CLOEXEC, mode 0600) and refused unless it is a regular file of this user."""
    folder = private_dir()
    path = os.path.join(folder, name)
    try:
        fd = os.open(path, flags | os.O_NOFOLLOW | os.O_CLOEXEC, 0o600)
    except OSError as e:
        raise LabError(f"cannot open {path}: {e.strerror}"
                       f"{' (a link: refused)' if e.errno == errno.ELOOP else ''}", 2)
    st = os.fstat(fd)
    if not stat.S_ISREG(st.st_mode) or st.st_uid != os.getuid():
        os.close(fd)
        raise LabError(f"{path} is not a file of yours ({_user_name(st.st_uid)}): refused", 2)
    return path, fd


def claim_address(url, suffix, share, network="localhost"):
    """Two launchers on this host started at once on one address and channels
    would both hear silence in probe_network: a lock file per address, suffix
    and network (this host's, or the namespace host the recorder listens in:
    namespace labs are networks of their own) makes the second refuse. The
    lock is in this user's own folder (private_dir): another user can neither
    hold it nor plant a link in its place; their sessions on the address are
    heard by probe_network instead."""
    global _address_lock
    import fcntl
    import hashlib
    key = hashlib.sha1(f"{url}|{suffix}|{network}".encode()).hexdigest()[:16]
    path, fd = open_private(f"address-{key}.lock")
    try:
        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except OSError:
        holder = os.pread(fd, 200, 0).decode(errors="replace").strip() or "another launcher"
        os.close(fd)
        msg = (f"another session is starting or running on {url}{' suffix ' + suffix if suffix else ''} from this "
               f"host ({holder}). Sessions on one address and channels see each other's traffic; give this one "
               f"--channel-suffix NAME or another --lcm-url, or --share-network to run beside it anyway.")
        if not share:
            raise LabError(msg, 1)
        say("--share-network: " + msg.split(". ")[0])
        return
    import atexit
    atexit.register(_release_address, path, fd)
    os.ftruncate(fd, 0)
    os.pwrite(fd, f"launcher pid {os.getpid()}".encode(), 0)
    _address_lock = fd


def _release_address(path, fd):
    try:
        os.unlink(path)
        os.close(fd)
    except OSError:
        pass


def note_address_holder(session_id):
    """The session's id in the address's lock file, for the next launcher's message."""
    if _address_lock is not None:
        os.ftruncate(_address_lock, 0)
        os.pwrite(_address_lock, f"session {session_id}, launcher pid {os.getpid()}".encode(), 0)


def write_manifest(out, fields):
    argv = [binary("tools/rms_session"), "manifest", out]
    for k, v in fields:
        argv += [k, v]
    r = subprocess.run(argv, capture_output=True, text=True)
    if r.returncode != 0:
        raise LabError(f"cannot write the manifest: {r.stderr.strip()}", 1)


WIRE_LOG = "wire.lcmlog"  # what the network delivered to the session's recorder (docs/sessions.md "The record")


def join_wire_parts(out):
    """The recorder, restarted after it died, wrote wire.lcmlog.1, .2, ...:
    appended to wire.lcmlog (an LCM log is a run of events), in order."""
    parts = []
    n = 1
    while os.path.exists(os.path.join(out, f"{WIRE_LOG}.{n}")):
        parts.append(os.path.join(out, f"{WIRE_LOG}.{n}"))
        n += 1
    if not parts:
        return None
    try:
        with open(os.path.join(out, WIRE_LOG), "ab") as dst:
            for p in parts:
                with open(p, "rb") as src:
                    shutil.copyfileobj(src, dst)
        for p in parts:
            os.remove(p)
        return f"the recorder was restarted {len(parts)} time(s); its parts are joined into {WIRE_LOG}"
    except OSError as e:
        return f"the recorder's parts ({', '.join(os.path.basename(p) for p in parts)}) could not be joined ({e}): " \
               f"{WIRE_LOG} holds only the first"


def close_record(out):
    """At the session's end: the recorder's parts joined, then the record,
    lcmlog, made from the processes' journals and what the network delivered
    (rms_session record; docs/sessions.md "The record"). Returns the notes
    to say. When the record cannot be made (a full disk), lcmlog is what the
    network delivered (a second name for wire.lcmlog, no space taken) and
    the journals stay, so nothing is lost and the summary still reads it."""
    notes = []
    joined = join_wire_parts(out)
    if joined:
        notes.append(joined)
    if not os.path.isdir(os.path.join(out, "journal")):
        return notes
    r = subprocess.run([binary("tools/rms_session"), "record", out], capture_output=True, text=True)
    if r.returncode == 0:
        try:
            rec = json.loads(r.stdout)
        except ValueError:
            rec = {}
        missed = rec.get("wire", {}).get("missed", {}).get("total", 0)
        if missed:
            by = rec["wire"]["missed"]["by_channel"]
            notes.append(f"the network's recorder missed {missed} message(s) ("
                         + ", ".join(f"{c} {n}" for c, n in sorted(by.items())) +
                         f"): the record holds them from the processes' journals; {WIRE_LOG} is what the "
                         f"network delivered")
        return notes
    why = r.stderr.strip().removeprefix("rms_session: ")
    wire = os.path.join(out, WIRE_LOG)
    lcmlog = os.path.join(out, "lcmlog")
    if os.path.exists(wire) and not os.path.exists(lcmlog):
        try:
            os.link(wire, lcmlog)
        except OSError:
            pass
    notes.append(f"the record could not be made from the journals ({why}): lcmlog is what the network delivered "
                 f"({WIRE_LOG}), and journal/ keeps every process's own record; run "
                 f"build/tools/rms_session record {out} where there is room")
    return notes


RESIM_FILE = "resimulation.json"  # what the session's re-simulation came to (docs/sessions.md "Does it re-simulate")
EXIT_NOT_RESIMULATED = 4  # a session that ran but does not re-simulate (docs/sessions.md "The launcher")


def resimulate(out):
    """The session's own design re-simulated at its end (rms_resim, tens of
    milliseconds), its verdict written to SESSION/resimulation.json, which
    the summary takes in and its brief says ("re-simulates: ..."). Returns
    True when it re-simulates; None when no verdict could be written."""
    path = os.path.join(out, RESIM_FILE)
    r = subprocess.run([binary("tools/rms_resim"), out, "--quiet", "--verdict-json", path], capture_output=True,
                       text=True)
    try:
        with open(path) as f:
            return json.load(f).get("verdict") == "identical"
    except (OSError, ValueError):
        why = (r.stderr.strip().splitlines() or [f"rms_resim exited with {r.returncode}"])[-1]
        say(f"the re-simulation's verdict could not be written ({why})")
        return None


def verdict_of(lines, resimulates):
    """The brief's "re-simulates:" line taken out of `lines` (said last), or
    one saying why there is none."""
    said = [line for line in lines if line.startswith("re-simulates:")]
    rest = [line for line in lines if not line.startswith("re-simulates:")]
    if said:
        return rest, said[-1]
    if resimulates is None:
        return rest, "re-simulates: NOT KNOWN -- its verdict could not be written (above)"
    return rest, "re-simulates: NOT KNOWN -- the summary could not be written (above)"


def summarize(out, fallback_name):
    """summary.json in the session; when its disk cannot take it, elsewhere
    (said). Returns (the brief lines, where it went, or None)."""
    targets = [os.path.join(out, "summary.json")] + [os.path.join(d, f"rmslab-{fallback_name}-summary.json")
                                                     for d in disk.fallback_dirs()]
    for t in targets:
        r = subprocess.run([binary("tools/rms_session"), "summary", out, "--brief", "--out", t], capture_output=True,
                           text=True)
        if r.returncode in (0, 3):  # 3: written, from a log damaged inside (said in the brief)
            if t != targets[0]:
                say(f"the session's folder could not take its summary: written to {t} instead")
            if r.returncode == 3:
                say(f"summary: {r.stderr.strip()}")
            return r.stdout.splitlines(), t
        say(f"summary: {r.stderr.strip()}")
    return [], None
