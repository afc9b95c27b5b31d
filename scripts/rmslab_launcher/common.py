"""What every launcher command shares: paths, messages, the build, the
multicast route, reading configuration (TOML, with Python's tomllib).

docs/sessions.md "The launcher" describes what scripts/lab does; this
package is that launcher.
"""
import contextlib
import errno
import hashlib
import json
import os
import re
import shutil
import stat
import subprocess
import sys
import tempfile
import tomllib

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
BUILD = os.environ.get("RMSLAB_BUILD", os.path.join(ROOT, "build"))
# transport/include/rms/transport/lcm_interface.h kDefaultLcmUrl (held to it
# by tests/python/test_cpp_constants.py), and its multicast group.
DEFAULT_URL = "udpm://239.255.76.67:7667?ttl=0"
DEFAULT_GROUP = DEFAULT_URL[len("udpm://"):].split(":")[0]
DEFAULT_REPLAY_URL = f"udpm://{DEFAULT_GROUP}:7669?ttl=0"
MAX_SPEED = 100.0  # transport/include/rms/transport/process.h kMaxSessionSpeed: the frame checks allow no faster


class LabError(Exception):
    """Bad input or a refusal: the message says what and why; exit code 2."""

    def __init__(self, message, code=2):
        super().__init__(message)
        self.code = code


_CONTROL = re.compile("[\x00-\x08\x0b-\x1f\x7f\x80-\x9f]")


def terminal_text(text):
    """Text safe to print on a terminal (as rms::TerminalText): every control
    character but LF and TAB as \\xNN, so a name from a message or a folder
    cannot clear the screen or set the window's title."""
    return _CONTROL.sub(lambda m: f"\\x{ord(m.group()):02x}", text)


# Limits for each kind of a session folder's files (as rms/base/folder_file.h).
MAX_CONFIG_BYTES = 1 << 20
MAX_JSON_BYTES = 64 << 20


_UMASK = os.umask(0)
os.umask(_UMASK)


@contextlib.contextmanager
def replacing(path, **kw):
    """A file written under a unique temporary name beside path (O_EXCL, no
    link followed), then renamed over it: a failure leaves no part, two
    writers do not trip each other, and a link planted at path is replaced,
    never written through (docs/security.md). Made as an ordinary file is
    (0666 less the umask)."""
    fd, tmp = tempfile.mkstemp(dir=os.path.dirname(os.path.abspath(path)), prefix="." + os.path.basename(path) + ".")
    try:
        os.fchmod(fd, 0o666 & ~_UMASK)
        with os.fdopen(fd, "w", **kw) as f:
            yield f
        os.replace(tmp, path)
    except BaseException:
        with contextlib.suppress(OSError):
            os.remove(tmp)
        raise


def read_folder_file(path, limit, what=None):
    """The bytes of a session folder's file, read as untrusted input
    (docs/security.md "Session folders are untrusted"): no link followed, a
    regular file only (a FIFO or a device is refused, not waited on or read
    without end), at most `limit` bytes. LabError naming the file otherwise."""
    what = what or os.path.basename(path)
    try:
        fd = os.open(path, os.O_RDONLY | os.O_NOFOLLOW | os.O_NONBLOCK | os.O_CLOEXEC)
    except OSError as e:
        why = "a link, not followed" if e.errno == errno.ELOOP else e.strerror
        raise LabError(f"cannot read {what} '{path}': {why}", 2)
    try:
        st = os.fstat(fd)
        if not stat.S_ISREG(st.st_mode):
            raise LabError(f"cannot read {what} '{path}': not a regular file (a FIFO, a device or a folder)", 2)
        if st.st_size > limit:
            raise LabError(f"cannot read {what} '{path}': {st.st_size} bytes, more than {limit}", 2)
        data = os.read(fd, limit + 1)
        while len(data) <= limit:
            more = os.read(fd, limit + 1 - len(data))
            if not more:
                break
            data += more
        if len(data) > limit:
            raise LabError(f"cannot read {what} '{path}': more than {limit} bytes", 2)
        return data
    finally:
        os.close(fd)


def require_session_file(session, name="lcmlog", code=2):
    """LabError unless SESSION/NAME is a regular file (no link), saying which
    of missing or not a regular file (a link, a FIFO, a device) it is."""
    path = os.path.join(session, name)
    try:
        st = os.lstat(path)
    except OSError:
        raise LabError(f"{session}: not a session folder (no {name})", code)
    if not stat.S_ISREG(st.st_mode):
        raise LabError(f"{session}: its {name} is not a regular file (a link, a FIFO or a device): refused "
                       f"(docs/security.md \"Session folders are untrusted\")", code)


def read_folder_json(path, limit=MAX_JSON_BYTES):
    """A session folder's JSON file (read_folder_file), or {} when it is
    missing or not JSON; LabError when it is there but not a regular file."""
    if not os.path.lexists(path):
        return {}
    try:
        return json.loads(read_folder_file(path, limit))
    except ValueError:
        return {}


def say(*parts):
    """A line for the person at the terminal (stderr, prefixed "lab:"); a
    terminal that has gone (closed) is no reason to stop. Control characters
    from what it quotes are shown, not obeyed (terminal_text)."""
    try:
        print(terminal_text("lab: " + " ".join(str(p) for p in parts)), file=sys.stderr, flush=True)
    except OSError:
        pass


_unwritable = set()


def write_run_file(path, text, append=True):
    """One of the session's small bookkeeping files (run/): a full disk is
    said once a file and is no reason for the launcher to stop stopping
    the session. Returns False when it could not be written."""
    try:
        with open(path, "a" if append else "w") as f:
            f.write(text)
        return True
    except OSError as e:
        if path not in _unwritable:
            _unwritable.add(path)
            say(f"could not write {path} ({e.strerror})")
        return False


def file_sha256(path):
    """The SHA-256 of a session folder's file, hex (as sha256sum prints it):
    a regular file only, no link followed (a FIFO or a device is refused, not
    waited on or hashed without end: LabError naming it)."""
    try:
        fd = os.open(path, os.O_RDONLY | os.O_NOFOLLOW | os.O_NONBLOCK | os.O_CLOEXEC)
    except OSError as e:
        raise LabError(f"cannot read '{path}': {'a link, not followed' if e.errno == errno.ELOOP else e.strerror}",
                       2)
    with os.fdopen(fd, "rb") as f:
        if not stat.S_ISREG(os.fstat(fd).st_mode):
            raise LabError(f"cannot read '{path}': not a regular file (a FIFO, a device or a folder)", 2)
        h = hashlib.sha256()
        for block in iter(lambda: f.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()


def run_statistics(module, *args):
    """python3 -m rmslab_launcher.MODULE ARGS... with Debian's python3, where
    apt puts python3-pandas, -scipy and -statsmodels (another python3 first
    on PATH, a pyenv's, has not them): its CompletedProcess, output kept."""
    py = "/usr/bin/python3" if os.path.exists("/usr/bin/python3") else sys.executable
    env = dict(os.environ, PYTHONPATH=os.path.join(ROOT, "scripts"))
    return subprocess.run([py, "-m", f"rmslab_launcher.{module}", *args], capture_output=True, text=True, env=env)


def binary(rel):
    return os.path.join(BUILD, rel)


def is_root():
    return os.geteuid() == 0


def sudo_prefix():
    """[] as root, ["sudo", "-n"] otherwise (when sudo exists)."""
    if is_root():
        return []
    return ["sudo", "-n"] if shutil.which("sudo") else []


def install_and_build():
    """scripts/install-deps, then configure (once) and build, Release."""
    subprocess.run([os.path.join(ROOT, "scripts", "install-deps")], check=True)
    if not (os.path.exists(os.path.join(BUILD, "build.ninja")) or os.path.exists(os.path.join(BUILD, "Makefile"))):
        werror = os.environ.get("RMSLAB_WERROR")  # as scripts/lib.sh's rmslab_configure
        subprocess.run(["cmake", "-S", ROOT, "-B", BUILD, "-G", "Ninja", "-DCMAKE_BUILD_TYPE=Release"] +
                       ([f"-DRMSLAB_WERROR={werror}"] if werror else []), check=True, stdout=subprocess.DEVNULL)
    subprocess.run(["cmake", "--build", BUILD, "--parallel", str(os.cpu_count() or 2)], check=True,
                   stdout=subprocess.DEVNULL)


def require_built(*rels):
    for rel in rels:
        if not os.access(binary(rel), os.X_OK):
            raise LabError(f"{binary(rel)} is not built (drop --no-build, or run scripts/test)")


def ensure_multicast_route():
    """LCM's UDP multicast needs a route to 224.0.0.0/4: added on loopback when missing."""
    if subprocess.run(["ip", "route", "get", DEFAULT_GROUP], stdout=subprocess.DEVNULL,
                      stderr=subprocess.DEVNULL).returncode == 0:
        return
    say("this machine has no route for multicast (224.0.0.0/4); adding one on loopback:")
    say("  ip route add 224.0.0.0/4 dev lo")
    if subprocess.run(sudo_prefix() + ["ip", "route", "add", "224.0.0.0/4", "dev", "lo"]).returncode != 0:
        raise LabError("could not add the route (needs root or sudo). Add it by hand, then run again.", 1)


def read_toml(path, what, folder_file=False):
    """A TOML file, parsed. folder_file: a session folder's (read_folder_file:
    no link, a regular file of at most 1 MiB); else one the user named."""
    try:
        if folder_file:
            if not os.path.lexists(path):
                raise FileNotFoundError(path)
            return tomllib.loads(read_folder_file(path, MAX_CONFIG_BYTES, what).decode())
        with open(path, "rb") as f:
            return tomllib.load(f)
    except FileNotFoundError:
        raise LabError(f"no such file: {path}")
    except (tomllib.TOMLDecodeError, UnicodeDecodeError) as e:
        raise LabError(f"{path}: not TOML ({e}) -- {what}")
    except OSError as e:
        raise LabError(f"cannot read {path} ({e.strerror}) -- {what}")


def check_lcm_url(url):
    """An LCM URL the processes can open: udpm://GROUP:PORT[?options], GROUP
    an IPv4 multicast address (224.0.0.0 to 239.255.255.255), PORT 1..65535."""
    m = re.fullmatch(r"udpm://(\d{1,3})\.(\d{1,3})\.(\d{1,3})\.(\d{1,3}):(\d{1,5})(\?[A-Za-z0-9_=&.]*)?", url,
                     re.ASCII)
    if not m:
        raise LabError(f"--lcm-url '{url}': not udpm://GROUP:PORT[?ttl=N] (e.g. {DEFAULT_URL})")
    octets = [int(m.group(i)) for i in range(1, 5)]
    if any(o > 255 for o in octets) or not 224 <= octets[0] <= 239:
        raise LabError(f"--lcm-url '{url}': {'.'.join(map(str, octets))} is not an IPv4 multicast group "
                       f"(224.0.0.0 to 239.255.255.255; a lab uses 239.x.y.z)")
    if not 1 <= int(m.group(5)) <= 65535:
        raise LabError(f"--lcm-url '{url}': port {m.group(5)} is not 1..65535")


def frame_rate_hz(config_path):
    """session.frame_rate_hz of a configuration (an integer or a float)."""
    cfg = read_toml(config_path, "the configuration (docs/config.md)")
    try:
        rate = float(cfg["session"]["frame_rate_hz"])
    except (KeyError, TypeError, ValueError):
        raise LabError(f"{config_path}: key 'session.frame_rate_hz': missing or not a number")
    if not rate > 0:
        raise LabError(f"{config_path}: key 'session.frame_rate_hz': must be > 0")
    return rate


def timeline_length_s(path):
    """The last time in a timeline (docs/timeline.md): its length in seconds."""
    last = 0.0
    with open(path, encoding="utf-8", errors="replace") as f:
        for line in f:
            line = line.split("#", 1)[0].strip()
            if not line:
                continue
            try:
                last = max(last, float(line.split()[0]))
            except ValueError:
                pass
    return last


def check_suffix(suffix):
    if suffix and not all(c.isalnum() and c.isascii() or c == "_" for c in suffix):
        raise LabError(f"--channel-suffix '{suffix}': letters, digits and '_' only")


def check_speed(speed):
    try:
        s = float(speed)
    except ValueError:
        raise LabError(f"--speed '{speed}': not a number")
    if not (0.01 <= s <= MAX_SPEED):
        raise LabError(f"--speed {speed}: must be within 0.01 .. {MAX_SPEED:g}")
    return s


MAX_CPU_WAKE_LATENCY_US = 1000000  # rms/base/cpu_wake_latency.h kMaxCpuWakeLatencyUs


def check_cpu_wake_latency(value):
    """--cpu-wake-latency-us: "off", or whole microseconds 0 .. 1,000,000
    (docs/performance.md "Wake latency"); returned as the processes'
    RMSLAB_CPU_WAKE_LATENCY_US."""
    if value == "off":
        return value
    if not re.fullmatch(r"[0-9]{1,7}", value, re.ASCII) or int(value) > MAX_CPU_WAKE_LATENCY_US:
        shown = value if len(value) <= 40 and value.isprintable() else \
            repr(value[:40])[1:-1] + ("..." if len(value) > 40 else "")
        raise LabError(f"--cpu-wake-latency-us '{shown}': \"off\" or whole microseconds, at most 7 digits, "
                       f"0 .. {MAX_CPU_WAKE_LATENCY_US}")
    return str(int(value))
