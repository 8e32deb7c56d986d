"""A Ray cluster of several nodes on one machine, the nodes sharing no disk (tests and benchmarks).

A head node (``ray start --head``, token authentication: ``RAY_AUTH_MODE=token`` and a token file) and worker
nodes started with ``ray start --address=...`` each inside its own mount namespace (``unshare --mount``) whose
``/tmp`` is a private tmpfs holding the node's copy of the token (``RAY_AUTH_TOKEN_PATH``): a worker node sees
neither the driver's folders under ``/tmp`` nor the head's files, as on separate machines. Needs root.

Every process started here runs in a new session; ``Cluster.stop`` ends them by process group (SIGTERM, then
SIGKILL), never with ``ray stop``, which would stop every Ray instance on the machine.
"""

from __future__ import annotations

import contextlib
import json
import os
import secrets
import shutil
import signal
import socket
import subprocess
import sys
from pathlib import Path

import psutil

SRC = Path(__file__).resolve().parents[1] / "src"
RAY = Path(sys.executable).with_name("ray")
REPOSITORY = Path(__file__).resolve().parents[1]


def _kept_under_tmp() -> list[str]:
    """The folders under /tmp that a worker node must still see: the repository and its Python, when a clone lives
    under /tmp (as CI's may) — the private tmpfs over /tmp would hide them otherwise."""
    needed = sorted({str(p) for p in (REPOSITORY, Path(sys.prefix).resolve()) if p.is_relative_to("/tmp")})
    return [p for p in needed if not any(p != q and p.startswith(q + "/") for q in needed)]
OBJECT_STORE = "200000000"  # bytes per node: the machine is shared
# the head declares a node dead after 3 missed health checks 1 s apart (Ray's default waits longer)
HEAD_CONFIG = json.dumps({"health_check_period_ms": 1000, "health_check_failure_threshold": 3})


def skip_reason() -> str | None:
    if not hasattr(os, "geteuid") or os.geteuid() != 0:
        return "needs root: worker nodes run in their own mount namespace (unshare --mount, mount -t tmpfs)"
    if shutil.which("unshare") is None:
        return "needs unshare (util-linux)"
    if not RAY.exists():
        return f"needs the ray command beside {sys.executable}"
    probe = subprocess.run(["unshare", "--mount", "--propagation", "private", "sh", "-c",
                            "mount -t tmpfs tmpfs /mnt"], capture_output=True)  # fmt: skip
    if probe.returncode:
        return f"cannot make a private tmpfs in a mount namespace: {probe.stderr.decode(errors='replace').strip()}"
    return None


def free_port() -> int:
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return probe.getsockname()[1]


def group_processes(groups: list[int]) -> list:
    """Every live process in the given process groups, and their descendants."""
    found = {}
    for process in psutil.process_iter():
        try:
            if os.getpgid(process.pid) in groups and process.status() != psutil.STATUS_ZOMBIE:
                found[process.pid] = process
                for child in process.children(recursive=True):
                    found[child.pid] = child
        except (ProcessLookupError, psutil.Error):
            continue
    return list(found.values())


def stop_groups(groups: list[int]) -> None:
    """SIGTERM, then SIGKILL, every process of these groups (ours: each was started in a new session)."""
    for sig, grace in ((signal.SIGTERM, 5.0), (signal.SIGKILL, 5.0)):
        processes = group_processes(groups)
        for process in processes:
            with contextlib.suppress(psutil.Error):
                process.send_signal(sig)
        psutil.wait_procs(processes, timeout=grace)


class Cluster:
    """A head node and worker nodes on this machine, the workers in private mount namespaces."""

    def __init__(self, root: Path, environment: dict[str, str], object_store: str = OBJECT_STORE,
                 token: str | None = None) -> None:  # fmt: skip
        self.root, self.object_store = root, object_store
        self.port = free_port()
        self.token = root / "auth_token"
        self.token.write_text(token or secrets.token_hex(32))  # a driver process keeps the first token it read
        self.groups: list[int] = []
        self.nodes: dict[str, int] = {}  # name -> process group
        base = {k: v for k, v in os.environ.items() if not k.startswith("RAY_")}
        self.env = {
            **base, **environment,
            "PYTHONPATH": os.pathsep.join([str(SRC), os.environ.get("PYTHONPATH", "")]),
            "RAY_AUTH_MODE": "token",
            "RAY_AUTH_TOKEN_PATH": str(self.token),
            "RAY_ADDRESS": f"127.0.0.1:{self.port}",  # what --address auto finds (other clusters may run here)
            "RAY_USAGE_STATS_ENABLED": "0",
        }  # fmt: skip

    def _start(self, name: str, command: list[str], environment: dict[str, str]) -> int:
        for attempt in range(4):  # a loaded machine can miss the 30 s Ray gives a raylet to register
            log = self.root / f"{name}.{attempt}.log"
            with open(log, "wb") as output:
                process = subprocess.Popen(command, env=environment, stdout=output, stderr=subprocess.STDOUT,
                                           stdin=subprocess.DEVNULL, start_new_session=True)  # fmt: skip
            self.groups.append(process.pid)
            try:
                code = process.wait(timeout=240)
            except subprocess.TimeoutExpired:
                code = -1
            if code == 0:
                self.nodes[name] = process.pid
                return process.pid
            stop_groups([process.pid])
        raise RuntimeError(f"{name} did not start:\n{log.read_text(errors='replace')[-3000:]}")

    def start_head(self, cpus: int = 0) -> None:
        """The head node; with no CPUs (the default) it schedules and holds the driver but renders nothing."""
        self._start("head", [str(RAY), "start", "--head", f"--num-cpus={cpus}", f"--port={self.port}",
                             "--node-ip-address=127.0.0.1", f"--object-store-memory={self.object_store}",
                             "--include-dashboard=false", "--disable-usage-stats", f"--temp-dir={self.root}/head",
                             "--include-log-monitor=false", f"--system-config={HEAD_CONFIG}"], self.env)  # fmt: skip

    def add_worker(self, name: str, cpus: int = 1) -> int:
        """A worker node in its own mount namespace: /tmp a fresh tmpfs holding its copy of the token."""
        kept = _kept_under_tmp()
        # a clone under /tmp (and its venv) stays visible through bind mounts parked on a private tmpfs at /mnt; the
        # driver's output folders (pytest's temporary folders) do not
        park = "".join(f"mkdir -p /mnt/k{i}; mount --bind '{path}' /mnt/k{i}; " for i, path in enumerate(kept))
        park = f"mount -t tmpfs -o size=1m tmpfs /mnt; {park}" if kept else ""
        restore = "".join(f"mkdir -p '{path}'; mount --bind /mnt/k{i} '{path}'; " for i, path in enumerate(kept))
        script = (
            f"set -e; {park}mount -t tmpfs -o size=2g tmpfs /tmp; {restore}mkdir -p /tmp/node; "
            'printf %s "$NODE_TOKEN" > /tmp/node/auth_token; export RAY_AUTH_TOKEN_PATH=/tmp/node/auth_token; '
            f"exec {RAY} start --address=127.0.0.1:{self.port} --num-cpus={cpus} --node-ip-address=127.0.0.1 "
            f"--object-store-memory={self.object_store} --temp-dir=/tmp/node/ray --disable-usage-stats "
            "--include-log-monitor=false"
        )
        environment = {**self.env, "NODE_TOKEN": self.token.read_text()}
        del environment["RAY_AUTH_TOKEN_PATH"]
        return self._start(name, ["unshare", "--mount", "--propagation", "private", "sh", "-c", script], environment)

    def processes(self, name: str) -> list:
        return group_processes([self.nodes[name]])

    def stop(self) -> None:
        stop_groups(self.groups)
