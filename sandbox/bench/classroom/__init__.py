"""Classroom benchmark: one server, N headless browsers, what each of them gets.

Usage::

    sandbox bench --classroom 30 rotor [--seconds 15] [--follow] [--out r.json]

starts ``python -m sandbox.cli serve SCENE --port P`` on a free loopback port, opens N
websocket clients that speak viser's protocol exactly as the browser does (subprotocol
``viser-v<version>``, ``Origin: http://127.0.0.1:P``, a first ``ViewerCameraMessage``
that starts the per-browser session), waits for every client's first frame, warms up,
then measures for ``--seconds`` (all clients run in one asyncio loop and decode only
what they need). Afterwards it runs a connect-and-drop phase and an Origin probe, stops
the server and prints each target of issue 12 next to its value (PASS/FAIL words, never
asserted).

Definitions:

- **Update frame**: one websocket message from the server that carries at least one
  scene pose update (``SetPositionMessage``, ``SetOrientationMessage``, or new
  ``batched_positions`` / ``batched_wxyzs`` of batched nodes). Frames/s of
  a client = its update frames received in the measurement window / the window [s].
- **Simulated-time rate**: what the browser shows. The control panel's status line
  ``t = 12,35 s · vitesse ×1 …`` (``sandbox.web.panels.controls.ControlPanel``, refreshed at
  10 Hz) is read from the wire; the rate of a client = (last t - first t) / (wall time
  between the two messages) inside the window [sim s per wall s].
- **Slider delay**: during the window each client toggles a parameter slider every
  :data:`~sandbox.bench.classroom.client.PROBE_PERIOD` s between its initial value and
  that value plus a quarter of its range, as a ``GuiUpdateMessage`` (the browser's own
  message). It "shows" in the first server message received after the send that creates
  or removes a 3D node under ``/model``: the renderer rebuilt the geom the parameter
  changed (the rotor's correction mass ``mass1_g`` and the compressor's
  ``counterweight_mass`` appear or disappear). With ``--follow``, one extra client opens
  the teacher link the server prints (``/prof/<token>``) and toggles the shared
  simulation's slider; every one of the N followers waits for the change under
  ``/prof/model`` (N samples per change). Delay = receive time - send time [s]; a change
  not shown before the next toggle counts as *not shown*. Other scenes probe their first
  parameter, which may never show this way.
- **Server CPU**: user + system time (+ reaped children, on Linux) of the server
  process and all its descendants, over the window [cores]. **RSS**: sum of the
  resident sizes over that tree (shared pages count once per process) [bytes]. These,
  the threads' CPU and the browsers per worker process are read with psutil, the same
  way on Linux, macOS and Windows (the ``bench`` extra: ``pip install "sandbox[bench]"``).
- **Idle CPU**: after the main clients left and 3 s passed, 20 clients connect, send
  the camera message and close at once; the server tree's CPU is sampled each second
  for 10 s; idle = the mean over the last 2 s [cores].
- **Origin probe**: a handshake with ``Origin: http://evil.example``; *refused* means
  no session: the handshake fails, the connection closes, or no update frame arrives
  within 3 s.

``--out FILE.json`` also writes the results (other ``--out`` values are ignored here).

Modules, by role: :mod:`~sandbox.bench.classroom.command` (the command's entry),
:mod:`~sandbox.bench.classroom.run` (one scene's run), :mod:`~sandbox.bench.classroom.phases`
(main phase, connect-and-drop, Origin probe), :mod:`~sandbox.bench.classroom.server` (the
server under test), :mod:`~sandbox.bench.classroom.client` and
:mod:`~sandbox.bench.classroom.browser` (the headless browsers),
:mod:`~sandbox.bench.classroom.wire` (decoding what the server sends),
:mod:`~sandbox.bench.classroom.processes` (per-process accounting),
:mod:`~sandbox.bench.classroom.stats`, :mod:`~sandbox.bench.classroom.targets` and
:mod:`~sandbox.bench.classroom.report` (what a run gives), and beside them
:mod:`~sandbox.bench.classroom.suite` (several scenes, saved runs),
:mod:`~sandbox.bench.classroom.speed` (the machine's speed),
:mod:`~sandbox.bench.classroom.workers` (worker by worker),
:mod:`~sandbox.bench.classroom.flood` and :mod:`~sandbox.bench.classroom.studies` (students
beside the class).
"""

from __future__ import annotations

from sandbox.bench.classroom.browser import camera_message, connect_as_browser, gui_message
from sandbox.bench.classroom.client import ClientStats, Window, run_client
from sandbox.bench.classroom.command import cli_classroom
from sandbox.bench.classroom.processes import connections_per_process, process_tree
from sandbox.bench.classroom.wire import find_gui, messages, unpack

__all__ = [
    "ClientStats",
    "Window",
    "camera_message",
    "cli_classroom",
    "connect_as_browser",
    "connections_per_process",
    "find_gui",
    "gui_message",
    "messages",
    "process_tree",
    "run_client",
    "unpack",
]
