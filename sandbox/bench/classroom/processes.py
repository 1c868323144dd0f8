"""Per-process accounting of the server under test: its process tree, the tree's CPU time
and resident memory, each thread's CPU, the process holding each browser's connection,
the machine's load average, and stopping a tree where there are no process groups.

These are read with psutil, the same way on Linux, macOS and Windows (the ``bench``
extra: ``pip install "sandbox[bench]"``).
"""

from __future__ import annotations

import collections
import contextlib
import os
from types import ModuleType
from typing import TYPE_CHECKING

from sandbox.errors import BadOption

if TYPE_CHECKING:
    import psutil


PSUTIL_MISSING = (
    "the classroom benchmark measures the server's processes with psutil, which is not "
    'installed: pip install "sandbox[bench]" (or: pip install psutil)'
)


def require_psutil() -> ModuleType:
    """psutil, imported on first use (the ``bench`` extra).

    Raises:
        BadOption: psutil is not installed; the message gives the install command.
    """
    try:
        import psutil  # optional: the ``bench`` extra, named when missing
    except ImportError:
        raise BadOption(PSUTIL_MISSING) from None
    return psutil


def _tree(pid: int) -> list[psutil.Process]:
    """``pid``'s process and its live descendants (empty when ``pid`` is gone)."""
    ps = require_psutil()
    try:
        root = ps.Process(pid)
        return [root, *root.children(recursive=True)]
    except ps.Error:
        return []


def process_tree(pid: int) -> list[int]:
    """``pid`` and all its live descendants (empty when ``pid`` is gone)."""
    return [p.pid for p in _tree(pid)]


def tree_cpu(pid: int) -> float:
    """CPU time [s] of ``pid`` and its descendants: user + system, reaped children too
    (the reaped children's part is known on Linux only; elsewhere psutil gives 0)."""
    ps, total = require_psutil(), 0.0
    for p in _tree(pid):
        with contextlib.suppress(ps.Error):
            t = p.cpu_times()
            total += t.user + t.system + t.children_user + t.children_system
    return total


def tree_rss(pid: int) -> int:
    """Resident set size [bytes] summed over ``pid`` and its descendants."""
    ps, total = require_psutil(), 0
    for p in _tree(pid):
        with contextlib.suppress(ps.Error):
            total += int(p.memory_info().rss)
    return total


def thread_cpu(pid: int) -> dict[tuple[int, int], float]:
    """CPU time [s] of every thread of ``pid``'s tree, keyed by (pid, tid).

    A process whose threads cannot be read (psutil's AccessDenied, e.g. another user's
    process on macOS) is left out: the figures then cover the threads that could be.
    """
    ps, out = require_psutil(), {}
    for p in _tree(pid):
        with contextlib.suppress(ps.Error, NotImplementedError):
            for t in p.threads():
                out[(p.pid, t.id)] = t.user_time + t.system_time
    return out


def browsers_by_process(pid: int, port: int) -> dict[int, int]:
    """The process of ``pid``'s tree holding each established TCP connection on local
    ``port``: the connection's remote port (a browser's own) -> the process's pid."""
    ps, owner = require_psutil(), {}
    for p in _tree(pid):
        with contextlib.suppress(ps.Error):
            # net_connections since psutil 6.0, connections before
            listed = getattr(p, "net_connections", None) or p.connections
            for c in listed(kind="tcp"):
                here = c.laddr and c.laddr.port == port
                if c.status == ps.CONN_ESTABLISHED and here and c.raddr:
                    owner[int(c.raddr.port)] = p.pid
    return owner


def connections_per_process(pid: int, port: int) -> dict[int, int]:
    """Established TCP connections on local ``port`` held by each process of the tree.

    Shows how the kernel spread the browsers over the server's worker processes.
    """
    return dict(collections.Counter(browsers_by_process(pid, port).values()))


def load_average() -> tuple[float, float, float] | None:
    """The system's 1, 5 and 15 min load averages; None where the OS has none (Windows)."""
    getloadavg = getattr(os, "getloadavg", None)
    if getloadavg is None:
        return None
    try:
        one, five, fifteen = getloadavg()
    except OSError:  # "load average was unobtainable"
        return None
    return (one, five, fifteen)


def stop_tree(pid: int, *, wait: float = 8.0) -> None:
    """Terminate ``pid`` and its descendants, then kill those alive after ``wait`` [s]."""
    ps = require_psutil()
    tree = _tree(pid)  # listed while the root lives: its children are found through it
    for p in tree:
        with contextlib.suppress(ps.Error):
            p.terminate()
    _, alive = ps.wait_procs(tree, timeout=wait)
    for p in alive:
        with contextlib.suppress(ps.Error):
            p.kill()
    ps.wait_procs(alive, timeout=3.0)
