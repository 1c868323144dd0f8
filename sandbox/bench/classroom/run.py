"""A classroom run of one scene: start a server, run the main phase, the connect-and-drop
phase and the Origin probe, stop the server, and judge the results by the targets.
"""

from __future__ import annotations

import asyncio
import os
import threading
import time
from collections.abc import Callable, Coroutine
from typing import Any, TypeVar

from sandbox.bench.classroom.busy import BusyCore
from sandbox.bench.classroom.phases import (
    FOREIGN_ORIGIN,
    Side,
    drop_phase,
    main_phase,
    origin_probe,
)
from sandbox.bench.classroom.processes import load_average, require_psutil
from sandbox.bench.classroom.report import STALL
from sandbox.bench.classroom.server import Server
from sandbox.bench.classroom.targets import targets
from sandbox.cores import DEFAULT_WORKERS_CAP, default_workers
from sandbox.scenes import SCENES

T = TypeVar("T")


PROBE_PARAMS = {
    "rotor": "mass1_g",
    "compressor": "counterweight_mass",
    "engine": "L",
}
"""Parameter slider toggled by the slider-delay probe (other scenes: their first). Each
changes what is drawn (the delay is seen as a 3D node made or removed) and hardly what a
step costs: the engine's first slider, its speed, would take half the class to 7250 rpm,
where the timestep is 3.5 times shorter (a class there costs what it costs: the benchmark
measures the scenes at their defaults); a longer rod keeps its timestep."""


SERVE_WORKERS_CAP = DEFAULT_WORKERS_CAP
"""Worker processes ``sandbox serve`` starts at most by default (:mod:`sandbox.cores`)."""

_cores = default_workers
"""Worker processes ``sandbox serve`` starts by default (one count for both)."""


def probe_param(scene: str) -> str | None:
    """Slider toggled by the delay probe: :data:`PROBE_PARAMS`, else the scene's first."""
    if scene in PROBE_PARAMS:
        return PROBE_PARAMS[scene]
    params = SCENES[scene].params if scene in SCENES else ()
    return params[0].name if params else None


def run_async(coro: Coroutine[Any, Any, T]) -> T:
    """``asyncio.run(coro)`` in a thread of its own: the caller's thread may already run
    an event loop (Playwright's sync API does, in the test suite)."""
    values: list[T] = []
    errors: list[BaseException] = []

    def body() -> None:
        try:
            values.append(asyncio.run(coro))
        except BaseException as exc:  # re-raised in the caller's thread
            errors.append(exc)

    worker = threading.Thread(target=body, name="classroom-bench")
    worker.start()
    worker.join()
    if errors:
        raise errors[0]
    return values[0]


def run_classroom(
    scene: str,
    clients: int,
    *,
    seconds: float = 15.0,
    warmup: float = 3.0,
    follow: bool = False,
    workers: int | None = None,
    drop_clients: int = 20,
    idle_seconds: float = 10.0,
    panel: str | None = None,
    progress: Callable[[str], None] | None = None,
    side: Side | None = None,
    busy_core: bool = False,
) -> dict[str, Any]:
    """Start a server, run the main phase, the connect-and-drop phase and the Origin probe.

    Args:
        scene: Scene (or lesson, or MJCF path) served.
        clients: Headless browsers in the main phase.
        seconds: Measurement window [s].
        warmup: Wait after every client's first frame [s].
        follow: Serve with ``--follow``: ``clients`` followers plus one teacher client
            (the link the server prints) that toggles the slider of the shared simulation.
        workers: Pass ``--workers`` to the server when not None.
        drop_clients: Connect-and-drop clients (0 skips that phase).
        idle_seconds: CPU sampling after the drop [s].
        panel: Readout folder every client picks in
            :data:`~sandbox.bench.classroom.client.PANEL_PICKER` (e.g. ``"Tous les panneaux"``,
            ``"Précision et coût"``); None keeps the default.
        progress: Called with one line per phase.
        side: A task beside the clients (:func:`main_phase`).
        busy_core: Another program keeps one core busy from before the server starts
            to after it stops (a laptop driving a projector and a video call).

    Returns:
        JSON-able results (see :func:`~sandbox.bench.classroom.report.report`).
    """
    say = progress or (lambda _line: None)
    require_psutil()  # missing: say how to install it before a server starts
    load = load_average()
    param = probe_param(scene)
    with BusyCore(busy_core), Server(scene, follow=follow, workers=workers) as server:
        link = server.teacher_path()
        teacher = link if follow else None
        if follow and teacher is None:
            say("no teacher link in the server's output: no slider probe")

        async def all_phases() -> dict[str, Any]:
            who = " following a teacher" if teacher else ""
            say(f"{clients} clients{who} on {scene} (port {server.port}) ...")
            main = await main_phase(
                server,
                clients,
                seconds=seconds,
                warmup=warmup,
                param=param if (teacher or not follow) else None,
                teacher=teacher,
                panel=panel,
                side=side,
                board=None if follow else link,
            )
            out: dict[str, Any] = {"main": main}
            if main["longest_frame_gap_s"]["max"] >= STALL:  # what the server said then
                out["server_output"] = server.output()
            if drop_clients > 0:
                say(f"{drop_clients} connect-and-drop clients, then {idle_seconds:g} s idle ...")
                out["drop"] = await drop_phase(server, clients=drop_clients, seconds=idle_seconds)
            refused, detail = await origin_probe(server.port)
            out["origin"] = {"origin": FOREIGN_ORIGIN, "refused": refused, "detail": detail}
            return out

        results = run_async(all_phases())
    results.update(
        scene=scene,
        follow=follow,
        busy_core=busy_core,
        workers=workers,
        worker_count=1 if follow else (workers if workers is not None else _cores()),
        date=time.strftime("%Y-%m-%d %H:%M:%S %Z"),
        cpus=os.cpu_count(),
        load_average_before=load,
        load_average_after=load_average(),
    )
    results["targets"] = targets(results)
    return results
