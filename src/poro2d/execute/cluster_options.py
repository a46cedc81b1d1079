"""The cluster options of a command, checked before any work: dashboard, scheduler, workers.

A LocalCluster serves its dashboard on this machine unless asked otherwise; a running
scheduler is named by an address the checks here read without connecting (whether it
answers is :func:`poro2d.execute.dask_cluster.check_reachable`'s question).
"""

from __future__ import annotations

import errno
import os
import socket
from urllib.parse import urlsplit

from poro2d.errors import InputError, check_int

#: where a LocalCluster serves its dashboard: this machine only (a port the system picks), so
#: that other users of a shared login node cannot watch the run or read its logs
DEFAULT_DASHBOARD = "127.0.0.1:0"


def check_dashboard(value: str | None, parameter: str = "--dashboard") -> str | None:
    """A dashboard address ``HOST:PORT`` (``:PORT`` for every interface), or None for no dashboard
    (``none``/``off``); the default when ``value`` is None is :data:`DEFAULT_DASHBOARD`.
    """
    if value is None:
        return DEFAULT_DASHBOARD
    text = str(value).strip()
    if text.lower() in ("none", "off"):
        return None
    host, sep, port = text.rpartition(":")
    if not sep or not port.isdigit() or int(port) > 65535 or any(c.isspace() or c == "/" for c in host):
        raise InputError(parameter, value, "HOST:PORT (port 0 to 65535, 0: any free one), :PORT, or none")
    problem = bind_problem(host.strip("[]"), int(port))
    if problem:
        raise InputError(
            parameter, value, "an address of this machine and a free port (0: any free one)", problem
        )
    return text


def bind_problem(host: str, port: int) -> str | None:
    """Why a server could not listen on ``host:port`` here (unknown host, not this machine's,
    port taken), tried now with a socket of our own; None when it can.

    Dask would otherwise find out only once the cluster starts, after the command's first
    stage of work, and answer an unknown host with a failure and a taken port with a
    warning of several lines and another port.
    """
    try:
        infos = socket.getaddrinfo(host or None, port, type=socket.SOCK_STREAM, flags=socket.AI_PASSIVE)
    except (socket.gaierror, UnicodeError) as exc:
        return f"the host {host!r} is not known ({exc})"
    family, kind, proto, _, address = infos[0]
    with socket.socket(family, kind, proto) as probe:
        probe.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)  # as the dashboard's server does
        try:
            probe.bind(address)
        except OSError as exc:
            if exc.errno == errno.EADDRINUSE:
                return f"port {port} is in use on {host or 'this machine'}"
            if exc.errno == errno.EADDRNOTAVAIL:
                return f"{host} is not an address of this machine"
            return f"cannot listen there: {exc.strerror or exc}"
    return None


#: seconds to wait for a running scheduler to answer (distributed's own default is 30)
CONNECT_TIMEOUT_S = 10
#: address schemes of a Dask scheduler that a user can type
SCHEDULER_SCHEMES = ("tcp", "tls", "ws", "wss", "ucx")
SCHEDULER_FORM = "an address such as tcp://host:8786 (scheme tcp, tls, ws, wss or ucx; port 1-65535)"


def max_workers() -> int:
    """The most worker processes a local cluster may start: two per core (more only queue)."""
    return 2 * (os.cpu_count() or 1)


def check_cluster_options(scheduler: str | None, workers: int | None) -> None:
    """``--scheduler`` of the right form and ``--workers`` in range, checked before any work.

    ``--workers`` sizes the local cluster; with ``--scheduler`` the running cluster's own
    workers take the cases, so the two together are refused rather than one ignored.
    """
    if workers is not None:
        check_int("--workers", workers, 1, max_workers())
    if scheduler is None:
        return
    if workers is not None:
        raise InputError("--workers", workers, "nothing with --scheduler (its own workers run the cases)")
    check_scheduler_address(scheduler)


def check_scheduler_address(address: str) -> str:
    """``address`` if it has the form ``[scheme://]host:port``; otherwise InputError."""
    text = address.strip()
    full = text if "://" in text else f"tcp://{text}"
    try:
        parts = urlsplit(full)
        port = parts.port
    except ValueError:
        raise InputError("--scheduler", address, SCHEDULER_FORM) from None
    if parts.scheme not in SCHEDULER_SCHEMES or not parts.hostname or port is None or not 0 < port < 65536:
        raise InputError("--scheduler", address, SCHEDULER_FORM)
    if parts.path not in ("", "/") or parts.query or parts.fragment:
        raise InputError("--scheduler", address, SCHEDULER_FORM)
    return full


__all__ = [
    "CONNECT_TIMEOUT_S",
    "DEFAULT_DASHBOARD",
    "SCHEDULER_FORM",
    "check_cluster_options",
    "check_dashboard",
    "bind_problem",
    "check_scheduler_address",
    "max_workers",
]
