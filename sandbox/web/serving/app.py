"""The web app: a viser server giving every browser its own simulation of one target.

``serve`` blocks until Ctrl-C (``sandbox serve``); ``start`` returns a running
:class:`~sandbox.web.serving.server.App` (tests, notebooks).
"""

from __future__ import annotations

import secrets
import socket
from pathlib import Path
from typing import Any

from sandbox.cores import default_workers
from sandbox.errors import BadOption
from sandbox.physics.limits import machine_bytes
from sandbox.physics.simulation import Simulation
from sandbox.scenes import resolve
from sandbox.web.client import viser_internals
from sandbox.web.panels.board import teacher_path
from sandbox.web.serving.server import bracket, check_port, serve_until_stopped
from sandbox.web.serving.startup import banner, start
from sandbox.web.serving.worker import WorkerSpec
from sandbox.web.serving.workers import serve_pool


def serve(target: str | Path, *, workers: int | None = None, **options: Any) -> None:
    """Serve ``target`` until Ctrl-C or SIGTERM (keyword arguments as for :func:`start`).

    Args:
        target: Scene name or MJCF path.
        workers: Server processes sharing the port (default one per core, at most 4; 1 serves
            from this process).
    """
    if options.get("follow"):
        if workers is not None and workers > 1:
            raise BadOption(
                "--follow serves one shared simulation from one process; drop --workers"
            )
        workers = 1
    count = default_workers() if workers is None else workers
    if count < 1:
        raise BadOption(f"--workers must be 1 or more, got {count!r}")
    viser_internals.warn_at_start()  # an untested viser: one line, then served all the same
    if count == 1:
        serve_until_stopped(lambda: start(target, **options))
        return
    host = str(options.pop("host", "127.0.0.1"))
    port = int(options.pop("port", 8080))
    options.pop("open_message", None)
    options = {k: (dict(v) if k == "values" else v) for k, v in options.items()}
    Simulation(
        resolve(target, max_bytes=machine_bytes(options.get("max_memory"))),
        values=options.get("values") or {},
        integrator=options.get("integrator"),
        timestep=options.get("timestep"),
        motion=options.get("motion"),
    )
    check_port(host, port)
    if port == 0:
        port = _free_port(host)
    options["token"] = options.get("token") or secrets.token_urlsafe(9)  # one for every worker
    spec = WorkerSpec(str(target), host, port, options)
    local = "127.0.0.1" if host in ("0.0.0.0", "", "::") else host
    teacher = f"http://{bracket(local)}:{port}{teacher_path(options['token'])}"
    text = banner(
        target, host, port, workers=count, teacher=teacher, public_url=options.get("public_url")
    )
    serve_pool(spec, count, banner=text)


def _free_port(host: str) -> int:
    family = socket.AF_INET6 if ":" in host else socket.AF_INET
    with socket.socket(family, socket.SOCK_STREAM) as sock:
        sock.bind((host, 0))
        return int(sock.getsockname()[1])
