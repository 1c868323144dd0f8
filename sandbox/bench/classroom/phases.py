"""The phases of a classroom run on a started server: the main phase (N browsers in one
asyncio loop warm up, then a measured window: frames, simulated time, slider delays,
server CPU, threads and RSS), the connect-and-drop phase (the server's idle CPU after
it) and the Origin probe (a foreign page gets no session).
"""

from __future__ import annotations

import asyncio
import collections
import math
import time
from collections.abc import Callable, Coroutine
from typing import Any

import websockets
import websockets.exceptions

from sandbox.bench.classroom.browser import camera_message, connect_as_browser
from sandbox.bench.classroom.client import ClientStats, Window, run_client
from sandbox.bench.classroom.processes import (
    browsers_by_process,
    process_tree,
    thread_cpu,
    tree_cpu,
    tree_rss,
)
from sandbox.bench.classroom.server import Server
from sandbox.bench.classroom.speed import SpeedProbe
from sandbox.bench.classroom.stats import summary
from sandbox.bench.classroom.teacher import TeacherPage
from sandbox.bench.classroom.wire import is_update_frame, unpack
from sandbox.bench.classroom.workers import by_worker

Side = Callable[[str, str, "Window", list["ClientStats"]], Coroutine[Any, Any, dict[str, Any]]]
"""A task beside the clients of :func:`main_phase`: (url, origin, window, clients)."""


FOREIGN_ORIGIN = "http://evil.example"


async def _wait_first_frames(
    stats: list[ClientStats], tasks: list[asyncio.Task[None]], limit: float
) -> None:
    deadline = time.perf_counter() + limit
    while time.perf_counter() < deadline:
        if all(s.first_frame is not None or t.done() for s, t in zip(stats, tasks, strict=True)):
            return
        await asyncio.sleep(0.1)


async def main_phase(
    server: Server,
    clients: int,
    *,
    seconds: float,
    warmup: float,
    param: str | None,
    teacher: str | None = None,
    panel: str | None = None,
    side: Side | None = None,
    board: str | None = None,
) -> dict[str, Any]:
    """N clients in this loop: warm up, then measure frames, sim rate, delays, CPU, RSS.

    Args:
        server: The running server.
        clients: Browsers measured.
        seconds: Measurement window [s].
        warmup: Wait after every client's first frame [s].
        param: Slider each client toggles (its own session), or None.
        teacher: With ``--follow``, the teacher's path (``/prof/<token>``): one more
            client opens it and toggles ``param`` on the shared simulation, and the
            delay is measured on every follower; the teacher is not in the statistics.
        panel: Readout folder every client picks (None: the default one).
        side: A task run beside the clients once they all draw (a hostile student:
            :mod:`sandbox.bench.classroom.flood`), given the URL, the Origin, the window and
            the clients; what it returns is kept as ``main["side"]``.
        board: The teacher's path (``/prof/<token>``) of a class whose teacher's page
            reads « La classe » (the capacity estimate the teacher sees, kept as
            ``main["teacher"]``); the teacher is not in the statistics.
    """
    url, origin = f"ws://127.0.0.1:{server.port}", f"http://127.0.0.1:{server.port}"
    window = Window()
    stats = [ClientStats(i) for i in range(clients)]
    tasks = []
    connect_start = time.perf_counter()
    for s in stats:
        probe = None if teacher else param
        tasks.append(
            asyncio.create_task(
                run_client(url, s, window, origin=origin, param=probe, seed=s.index, panel=panel)
            )
        )
    page = TeacherPage() if board is not None else None
    if page is not None:
        tasks.append(asyncio.create_task(page.read(url + str(board), origin)))
    if teacher is not None:
        lead = ClientStats(-1)
        tasks.append(
            asyncio.create_task(
                run_client(url + teacher, lead, window, origin=origin, param=param, watchers=stats)
            )
        )
    try:
        await _wait_first_frames(stats, tasks[:clients], 30.0 + 0.5 * clients)
        ready = time.perf_counter() - connect_start
        beside = None
        if side is not None:
            beside = asyncio.create_task(side(url, origin, window, stats))
        await asyncio.sleep(warmup)
        speed = SpeedProbe()
        speed.start()
        own0, cpu0, threads0 = time.process_time(), tree_cpu(server.pid), thread_cpu(server.pid)
        window.start = time.perf_counter()
        window.end = window.start + seconds
        rss: list[int] = []
        while time.perf_counter() < window.end:
            rss.append(tree_rss(server.pid))
            await asyncio.sleep(min(1.0, max(0.0, window.end - time.perf_counter())))
        cpu1, threads1, own1 = tree_cpu(server.pid), thread_cpu(server.pid), time.process_time()
        machine_ms = speed.stop()
        rss.append(tree_rss(server.pid))
        processes = len(process_tree(server.pid))
        owner = browsers_by_process(server.pid, server.port)
        # the students' websockets (the teacher's page, one more, is not in the figures)
        mine = [owner[s.port] for s in stats if s.port in owner]
        held = collections.Counter(mine if mine else owner.values())
        spread = sorted(held.values(), reverse=True)
        side_result = None
        if beside is not None:
            side_result = await asyncio.wait_for(beside, timeout=30.0)
    finally:
        for t in tasks:
            t.cancel()
        await asyncio.wait(tasks, timeout=5.0)
    fps = [s.fps(window) for s in stats]
    rates = [r for r in (s.sim_rate() for s in stats) if math.isfinite(r)]
    delays = [d for s in stats for d in s.delays]
    used = {k: (threads1[k] - threads0.get(k, 0.0)) / seconds for k in threads1}
    threads = sorted(used.values(), reverse=True)
    frames = sum(s.frames for s in stats)
    ws_msgs = sum(s.ws_messages for s in stats)
    wire = sum(s.wire_bytes for s in stats)
    return {
        "clients": clients,
        "panel": panel,
        "panel_picked": sum(s.picker is not None for s in stats),
        "played": sum(bool(s.played) for s in stats),
        "connected": sum(s.first_frame is not None for s in stats),
        "errors": sorted({s.error for s in stats if s.error}),
        "ready_s": ready,
        "seconds": seconds,
        "warmup_s": warmup,
        "fps": summary(fps),
        "fps_per_client": fps,
        "messages_per_client": [s.ws_messages for s in stats],
        "sim_rate": summary(rates),
        "sim_rate_per_client": [s.sim_rate() for s in stats],
        "sim_rate_samples": len(rates),
        "slider_param": param,
        "slider_delay_s": summary(delays),
        "slider_samples": len(delays),
        "slider_not_shown": sum(s.not_shown for s in stats),
        "server_cpu_cores": (cpu1 - cpu0) / seconds,
        "server_cpu_ms_per_frame": (cpu1 - cpu0) * 1000.0 / frames if frames else math.nan,
        "server_processes": processes,
        "clients_per_process": spread,
        "server_threads": len(threads1),
        "server_top_thread_cores": threads[:6],
        "workers": by_worker(fps, [s.port for s in stats], owner, used),
        "server_rss_bytes": max(rss),
        "bench_cpu_cores": (own1 - own0) / seconds,
        "machine_probe_ms": machine_ms,
        "per_client_ws_messages_per_s": ws_msgs / seconds / clients,
        "per_client_kbytes_per_s": wire / seconds / clients / 1000.0,
        "bytes_per_ws_message": wire / ws_msgs if ws_msgs else math.nan,
        "viser_messages_per_ws_message": (
            sum(s.viser_messages for s in stats) / ws_msgs if ws_msgs else math.nan
        ),
        "update_frames_share": frames / ws_msgs if ws_msgs else math.nan,
        "longest_frame_gap_s": summary([s.longest_gap(window) for s in stats]),
        "big_messages_per_client_per_s": sum(s.big for s in stats) / seconds / clients,
        "largest_message_bytes": max((s.max_bytes for s in stats), default=0),
        "side": side_result,
        "teacher": page.results() if page is not None else None,
    }


async def drop_phase(
    server: Server, *, clients: int = 20, settle: float = 3.0, seconds: float = 10.0
) -> dict[str, Any]:
    """Clients that connect, send the camera and drop; then the server's CPU each second.

    Returns:
        ``cores_per_s`` (one value per second after the drop) and ``idle_cores`` (mean
        of the last 2 s).
    """
    url, origin = f"ws://127.0.0.1:{server.port}", f"http://127.0.0.1:{server.port}"
    await asyncio.sleep(settle)
    camera = camera_message()

    async def one() -> bool:
        try:
            async with connect_as_browser(url, origin, open_timeout=10) as ws:
                await ws.send(camera)
            return True
        except Exception:
            return False

    ok = await asyncio.wait_for(asyncio.gather(*(one() for _ in range(clients))), 30.0)
    cores, last = [], (time.perf_counter(), tree_cpu(server.pid))
    for _ in range(int(seconds)):
        await asyncio.sleep(1.0)
        now = (time.perf_counter(), tree_cpu(server.pid))
        cores.append((now[1] - last[1]) / (now[0] - last[0]))
        last = now
    tail = cores[-2:] if cores else [math.nan]
    return {
        "clients": clients,
        "connected": sum(ok),
        "cores_per_s": cores,
        "idle_cores": sum(tail) / len(tail),
    }


async def origin_probe(
    port: int, *, origin: str = FOREIGN_ORIGIN, wait: float = 3.0
) -> tuple[bool, str]:
    """Whether a page from ``origin`` is refused a session, and how.

    Returns:
        (refused, detail): refused is True when no update frame arrived.
    """
    try:
        async with connect_as_browser(f"ws://127.0.0.1:{port}", origin, open_timeout=10) as ws:
            await ws.send(camera_message())
            deadline = time.perf_counter() + wait
            while (left := deadline - time.perf_counter()) > 0:
                try:
                    raw = await asyncio.wait_for(ws.recv(), left)
                except TimeoutError:
                    break
                if isinstance(raw, bytes) and is_update_frame(unpack(raw)):
                    return False, "accepted: the session sent update frames"
            return True, f"handshake accepted but no update frame within {wait:g} s"
    except websockets.exceptions.InvalidStatus as exc:
        return True, f"handshake refused (HTTP {exc.response.status_code})"
    except websockets.exceptions.ConnectionClosed as exc:
        code = exc.rcvd.code if exc.rcvd is not None else None
        return True, f"connection closed by the server (code {code})"
    except (websockets.exceptions.InvalidHandshake, OSError, TimeoutError) as exc:
        return True, f"handshake failed ({type(exc).__name__}: {exc})"
