#!/usr/bin/env python3
"""Every program the project's scripts and tests run comes from a Debian
package that scripts/install-deps installs (or from an Essential package,
which every Debian system has), so the README's test command passes on a
fresh bookworm machine (issue 13: nftables was missing).

The programs are the ones named in TOOLS below and every one the launcher's
Python runs (the first element of an argv list, found by scanning
scripts/rmslab_launcher/). A program that is not installed here, or whose
package is not in the list, fails the check with its name and package.
"""
import os
import re
import shutil
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))

# What the bash scripts (scripts/*), the tests (tests/) and the build run.
TOOLS = [
    "cmake", "ninja", "pkg-config", "git", "c++", "clang++",  # build, fuzz
    "lcm-gen", "lcm-logger", "lcm-logplayer",  # LCM
    "ffmpeg", "ffprobe",  # the session's video and its test
    "Xvfb", "xwd", "xauth", "xdotool",  # the window test
    "tmux",  # the terminal tests
    "chromium",  # the report's browser test
    "ssh", "nsenter", "ping", "ip", "tc", "nft", "mount", "umount",  # hosts, namespaces, disks
    "ps", "pkill", "timeout", "jq", "python3", "flock", "parallel",  # parallel: scripts/lab sweep
    "bash", "sudo",  # scripts/lab (python3 installed first where missing), root where the user is not
    "debootstrap", "chroot",  # scripts/fresh-bookworm
    "clang-format", "clang-tidy", "run-clang-tidy", "pycodestyle", "pytest-3",  # scripts/lint
]


def install_deps_packages():
    text = open(os.path.join(ROOT, "scripts", "install-deps")).read()
    body = text[text.index("PACKAGES=(") + len("PACKAGES=("):]
    body = body[:body.index("\n)")]
    words = []
    for line in body.splitlines():
        words += line.split("#", 1)[0].split()
    return set(words)


def launcher_tools():
    found = set()
    pattern = re.compile(r'\[\s*"([A-Za-z][A-Za-z0-9_.+-]*)"\s*,')
    folder = os.path.join(ROOT, "scripts", "rmslab_launcher")
    for name in sorted(os.listdir(folder)):
        if name.endswith(".py"):
            for m in pattern.finditer(open(os.path.join(folder, name)).read()):
                if shutil.which(m.group(1)):
                    found.add(m.group(1))
    return found


def owner(path):
    r = subprocess.run(["dpkg", "-S", path], capture_output=True, text=True)
    if r.returncode != 0:
        return None
    # A diverted file (GNU parallel diverts moreutils' parallel) is listed
    # first as "diversion by ...": its owner is on the line after.
    lines = [ln for ln in r.stdout.splitlines() if not ln.startswith("diversion by")]
    return lines[0].split(":", 1)[0].split(",")[0].strip() if lines else None


def package_of(name):
    """The package that owns the program (/usr-merged paths tried both ways;
    a program shadowed on PATH, e.g. by pyenv, looked for in the system's
    folders). Returns (path, package or None)."""
    first = shutil.which(name)
    candidates = [first] + [os.path.join(d, name) for d in ("/usr/bin", "/usr/sbin", "/bin", "/sbin")]
    for c in candidates:
        if not c or not os.path.exists(c):
            continue
        for path in (c, os.path.realpath(c)):
            for alt in (path, path.replace("/usr/", "/", 1) if path.startswith("/usr/") else "/usr" + path):
                pkg = owner(alt)
                if pkg:
                    return alt, pkg
    return first, None


def installed_closure(roots):
    """Every package the listed ones depend on (Depends, Pre-Depends,
    through virtual packages), as installed here."""
    r = subprocess.run(["dpkg-query", "-W", "-f", "${Package}\t${Depends}, ${Pre-Depends}\t${Provides}\n"],
                       capture_output=True, text=True, check=True)
    deps, providers = {}, {}
    for line in r.stdout.splitlines():
        pkg, dep, prov = (line.split("\t") + ["", ""])[:3]
        names = [re.sub(r"[\s(:].*", "", d.strip()) for d in re.split(r"[,|]", dep)]
        deps[pkg] = [n for n in names if n]
        for v in prov.split(","):
            v = re.sub(r"[\s(:].*", "", v.strip())
            if v:
                providers.setdefault(v, []).append(pkg)
    seen, todo = set(), list(roots)
    while todo:
        p = todo.pop()
        if p in seen:
            continue
        seen.add(p)
        todo += deps.get(p, []) + providers.get(p, [])
    return seen


def essential(pkg):
    r = subprocess.run(["dpkg-query", "-W", "-f", "${Essential}", pkg], capture_output=True, text=True)
    return r.stdout.strip() == "yes"


def main():
    listed = install_deps_packages()
    tools = sorted(set(TOOLS) | launcher_tools())
    bad = []
    closure = installed_closure(listed)
    for t in tools:
        if not shutil.which(t):
            bad.append(f"{t}: used by the project but not installed here (add its package to scripts/install-deps)")
            continue
        path, pkg = package_of(t)
        if pkg is None:
            bad.append(f"{t} ({path}): no Debian package owns it -- installed by hand? scripts/install-deps cannot")
        elif pkg in listed:
            print(f"{t}: {pkg}")
        elif pkg in closure:
            print(f"{t}: {pkg} (a dependency of a listed package)")
        elif essential(pkg):
            print(f"{t}: {pkg} (essential)")
        else:
            bad.append(f"{t} ({path}): package {pkg} is not in scripts/install-deps")
    if bad:
        print("\n".join(bad), file=sys.stderr)
        return 1
    print(f"{len(tools)} programs, each from a package scripts/install-deps installs")
    return 0


if __name__ == "__main__":
    sys.exit(main())
