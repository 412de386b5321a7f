"""A Ray cluster of one or more nodes on this machine, bound to 127.0.0.1, started with ``ray
start`` and stopped by pid: for the tests and the benchmark, and to try a cluster out.

``ray start`` leaves its processes running after it returns (its GCS server, raylets, agents
and workers, re-parented away from the caller), and ``ray stop`` would stop every Ray process of
the user, other people's clusters included. So each cluster gets a temporary folder of its own
(``--temp-dir``), which every one of its GCS servers and raylets names on its command line; stopping
the cluster kills exactly those processes and their descendants (the agents and workers, which
rename themselves ``ray::...``), found in ``/proc``. Linux only.

Ray 2.60 turns token authentication on: every node that joins, and every driver that connects,
needs ``RAY_AUTH_MODE=token`` and the head's token (by default in ``~/.ray/auth_token``, made by
the head if missing); :class:`LocalRayCluster` sets the mode for the nodes it starts and
:data:`ENVIRONMENT` holds what a driver needs.
"""

from __future__ import annotations

import os
import shutil
import signal
import socket
import subprocess
import sys
import tempfile
import time
from collections.abc import Sequence
from pathlib import Path

__all__ = ["ENVIRONMENT", "LocalRayCluster", "descendants"]

#: What a process that joins or connects to the cluster needs in its environment.
ENVIRONMENT = {"RAY_AUTH_MODE": "token"}


def _processes() -> dict[int, tuple[int, str]]:
    """Every process this user can see: pid -> (parent pid, command line)."""
    found = {}
    for entry in Path("/proc").iterdir():
        if not entry.name.isdigit():
            continue
        try:
            stat = (entry / "stat").read_text()
            cmdline = (entry / "cmdline").read_bytes().replace(b"\0", b" ").decode(errors="replace")
        except OSError:
            continue
        parent = int(stat[stat.rindex(")") + 2:].split()[1])  # the name may hold spaces and brackets
        found[int(entry.name)] = (parent, cmdline)
    return found


def descendants(roots: Sequence[int]) -> set[int]:
    """``roots`` and every process below them."""
    table = _processes()
    found, frontier = set(roots), list(roots)
    while frontier:
        pid = frontier.pop()
        children = [p for p, (parent, _) in table.items() if parent == pid and p not in found]
        found.update(children)
        frontier += children
    return found


#: The ``ray`` command beside this Python (a virtual environment's), else the first on the PATH.
_RAY = shutil.which("ray", path=os.path.dirname(sys.executable)) or "ray"


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


class LocalRayCluster:
    """A head node of ``cpus[0]`` CPUs and a node of each further ``cpus[k]``, all on 127.0.0.1;
    :attr:`address` is the head's. Use it as a context manager: leaving stops every process of it."""

    def __init__(self, cpus: Sequence[int] = (2,)):
        self.cpus = list(cpus)
        self.folder = Path(tempfile.mkdtemp(prefix="rt-", dir="/tmp"))  # short: Ray's socket paths must fit
        self.address = f"127.0.0.1:{_free_port()}"
        self.environment = os.environ | ENVIRONMENT

    def __enter__(self) -> LocalRayCluster:
        try:
            # The head authenticates nodes and drivers with the token in ~/.ray/auth_token: made if missing.
            subprocess.run([_RAY, "get-auth-token", "--generate"], env=self.environment, check=True,
                           capture_output=True, timeout=60)
            for k, cpus in enumerate(self.cpus):
                where = ["--head", "--port", self.address.rsplit(":", 1)[1], "--include-dashboard", "false"] if k == 0 \
                    else ["--address", self.address]
                subprocess.run([_RAY, "start", *where, "--num-cpus", str(cpus), "--node-ip-address", "127.0.0.1",
                                "--temp-dir", str(self.folder), "--disable-usage-stats"],
                               env=self.environment, check=True, capture_output=True, timeout=120)
        except BaseException:
            self.stop()
            raise
        return self

    def __exit__(self, *exc) -> None:
        self.stop()

    def pids(self) -> set[int]:
        """The processes of this cluster now."""
        roots = [pid for pid, (_, cmdline) in _processes().items() if str(self.folder) in cmdline]
        return descendants(roots)

    def stop(self) -> None:
        """Kill every process of this cluster (SIGKILL: nothing of it is kept), wait for them, and
        remove its folder."""
        pids = self.pids()
        for pid in pids:
            try:
                os.kill(pid, signal.SIGKILL)
            except ProcessLookupError:
                pass
        deadline = time.monotonic() + 10
        while time.monotonic() < deadline and self.pids():
            time.sleep(0.05)
        shutil.rmtree(self.folder, ignore_errors=True)
