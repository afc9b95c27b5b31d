"""Where a session's process runs: "localhost", "netns:NAME" (a network
namespace on this machine) or "ssh:[USER@]HOST" (docs/sessions.md "Several
hosts"). A Host turns a command into the command that runs it there."""
import os
import shlex
import subprocess

from .common import DEFAULT_GROUP, LabError, say, sudo_prefix

SSH = ["ssh", "-o", "BatchMode=yes", "-o", "ConnectTimeout=5"]


class Host:
    def __init__(self, spec):
        self.spec = spec or "localhost"
        kind, _, rest = self.spec.partition(":")
        if self.spec == "localhost":
            self.kind, self.name = "localhost", ""
        elif kind in ("netns", "ssh") and rest:
            self.kind, self.name = kind, rest
        else:
            raise LabError(f"host '{spec}': must be localhost, netns:NAME or ssh:[USER@]HOST")

    @property
    def remote(self):
        return self.kind == "ssh"

    @property
    def via_sudo(self):
        """True when the command runs under sudo (a namespace, not root): its
        pid is sudo's, its processes root's."""
        return self.kind == "netns" and bool(sudo_prefix())

    def wrap(self, argv, env, remote_run=None, pid_name=None):
        """The command that runs argv with env here, on this host."""
        env_args = [f"{k}={v}" for k, v in sorted(env.items())]
        if self.kind == "localhost":
            return list(argv)
        if self.kind == "netns":
            return (sudo_prefix() + ["nsenter", f"--net=/var/run/netns/{self.name}", "--", "env"] + env_args +
                    list(argv))
        # ssh: the remote shell writes the process's pid (for signals), then
        # becomes it; its standard input is the launcher's lifeline.
        pre = f"umask 077 && mkdir -p {shlex.quote(remote_run)}/journal && " if remote_run else ""
        if remote_run and pid_name:
            pre += f"echo $$ >{shlex.quote(remote_run)}/{shlex.quote(pid_name)}.pid && "
        cmd = pre + "exec env " + " ".join(shlex.quote(a) for a in env_args + list(argv))
        return SSH + [self.name, cmd]

    def run(self, argv, env=None, **kw):
        """Runs argv here to its end (for checks and probes)."""
        return subprocess.run(self.wrap(argv, env or {}), **kw)

    def signal(self, pid, sig, remote_run=None, pid_name=None):
        """Sends sig to a process (its group, when it leads one) on this host."""
        if self.remote:
            if remote_run and pid_name:
                subprocess.run(SSH + [self.name, f"kill -{int(sig)} $(cat {shlex.quote(remote_run)}/"
                                                 f"{shlex.quote(pid_name)}.pid) 2>/dev/null"],
                               stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
            return
        if self.via_sudo:
            subprocess.run(sudo_prefix() + ["kill", f"-{int(sig)}", "--", f"-{pid}"], stdout=subprocess.DEVNULL,
                           stderr=subprocess.DEVNULL)
            return
        try:
            os.killpg(pid, sig)
        except (ProcessLookupError, PermissionError):
            try:
                os.kill(pid, sig)
            except (ProcessLookupError, PermissionError):
                pass

    def copy_to(self, local_path, remote_path):
        if not self.remote:
            return
        subprocess.run(SSH + [self.name, f"umask 077 && mkdir -p {shlex.quote(os.path.dirname(remote_path))}"],
                       check=False,
                       stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        if subprocess.run(["scp", "-q", "-o", "BatchMode=yes", local_path, f"{self.name}:{remote_path}"]).returncode:
            raise LabError(f"host {self.spec}: cannot copy {local_path} there", 1)

    def copy_from(self, remote_path, local_path):
        if self.remote:
            subprocess.run(["scp", "-q", "-o", "BatchMode=yes", f"{self.name}:{remote_path}", local_path],
                           stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)

    def __str__(self):
        return self.spec


def check_hosts(url, remote_build, hosts):
    """Before a session on several hosts: each reachable, rmslab built there,
    multicast routed. Raises LabError saying which and why."""
    problems = []
    seen = []
    for h in hosts:
        if h.spec in seen:
            continue
        seen.append(h.spec)
        if h.kind == "netns":
            names = subprocess.run(["ip", "netns", "list"], capture_output=True, text=True).stdout.split()
            if h.name not in names:
                problems.append(f"host {h}: no such network namespace (ip netns list)")
                continue
            if h.run(["ip", "route", "get", DEFAULT_GROUP], stdout=subprocess.DEVNULL,
                     stderr=subprocess.DEVNULL).returncode:
                problems.append(f"host {h}: no route for multicast in the namespace "
                                "(ip route add 224.0.0.0/4 dev IFACE)")
        elif h.kind == "ssh":
            if subprocess.run(SSH + [h.name, "true"], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL).returncode:
                problems.append(f"host {h}: cannot reach it by ssh without a password")
                continue
            if subprocess.run(SSH + [h.name, f"test -x {shlex.quote(remote_build)}/dynamics_proc/dynamics_proc"],
                              stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL).returncode:
                problems.append(f"host {h}: rmslab is not built at {remote_build} (the lab file's [remote] build)")
            if subprocess.run(SSH + [h.name, "ip route get " + DEFAULT_GROUP], stdout=subprocess.DEVNULL,
                              stderr=subprocess.DEVNULL).returncode:
                problems.append(f"host {h}: no route for multicast")
    if problems:
        raise LabError("\n".join(problems), 1)
    say(f"hosts checked: {' '.join(seen)} (LCM {url})")
