"""Shared fixtures: test models (inline MJCF), a served app, headless Chromium."""

from __future__ import annotations

import os
import shutil
import socket
import time
from collections.abc import Callable, Iterator
from pathlib import Path

import pytest

# Tests name scenes at every layer: load the registry, which passes itself down to
# physics for Simulation(get_scene("rotor")).
import sandbox.scenes  # noqa: F401

DIVERGING = """
<mujoco>
  <option timestep="0.05" integrator="Euler"/>
  <worldbody>
    <body>
      <joint type="slide" axis="1 0 0" stiffness="1e6"/>
      <geom type="sphere" size="0.1" mass="0.001"/>
    </body>
  </worldbody>
  <keyframe><key qpos="0.1"/></keyframe>
</mujoco>
"""
"""A stiff spring (ω ≈ 3·10⁴ rad/s) integrated by explicit Euler at dt = 0.05 s: ω dt ≫ 2."""


PENDULUM = """
<mujoco>
  <option timestep="0.001"/>
  <worldbody>
    <body name="arm">
      <joint name="hinge" type="hinge" axis="0 1 0"/>
      <geom type="capsule" fromto="0 0 0 0.3 0 0" size="0.02" mass="1"/>
    </body>
  </worldbody>
  <keyframe><key qpos="0.5"/></keyframe>
</mujoco>
"""
"""A 1 kg arm on a hinge, started at 0.5 rad by its keyframe."""


@pytest.fixture
def pendulum_xml(tmp_path: Path) -> Path:
    path = tmp_path / "pendulum.xml"
    path.write_text(PENDULUM)
    return path


@pytest.fixture
def diverging_xml(tmp_path: Path) -> Path:
    path = tmp_path / "diverging.xml"
    path.write_text(DIVERGING)
    return path


CHROMIUM_ARGS = [
    "--no-sandbox",
    "--disable-gpu",
    "--disable-quic",
    "--no-first-run",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
]


def free_port() -> int:
    with socket.socket() as sock:
        sock.bind(("127.0.0.1", 0))
        return int(sock.getsockname()[1])


def serve_workers(
    cwd: Path, workers: int = 2, scene: str = "rotor", *, interrupts_ignored: bool = False
) -> tuple[object, int]:
    """``sandbox serve SCENE --workers N`` on a free port, in its own process group:
    (the Popen, its port); the caller reads its first line and stops it.
    ``interrupts_ignored``: started as a script's background job or a desktop launcher
    start it, SIGINT ignored (POSIX)."""
    import signal
    import subprocess
    import sys

    def ignore_interrupts() -> None:
        signal.signal(signal.SIGINT, signal.SIG_IGN)

    port = free_port()
    proc = subprocess.Popen(
        [sys.executable, "-m", "sandbox.cli", "serve", scene, "--port", str(port)]
        + ["--workers", str(workers)],
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
        cwd=cwd,
        start_new_session=True,
        preexec_fn=ignore_interrupts if interrupts_ignored else None,
    )
    return proc, port


def chromium_path() -> str:
    """Debian's Chromium; CI (SANDBOX_REQUIRE_BROWSER=1) fails instead of skipping."""
    path = os.environ.get("CHROMIUM") or shutil.which("chromium") or "/usr/bin/chromium"
    if not os.path.exists(path):
        if os.environ.get("SANDBOX_REQUIRE_BROWSER"):
            pytest.fail(f"Chromium not found at {path}; install it with apt-get install chromium")
        pytest.skip("Chromium not installed (apt-get install chromium)")
    return path


@pytest.fixture
def served_rotor() -> Iterator[object]:
    from sandbox.web.serving.app import start

    app = start("rotor", port=free_port(), open_message=False)
    try:
        yield app
    finally:
        app.stop()


@pytest.fixture(scope="session")
def browser() -> Iterator[object]:
    playwright_api = pytest.importorskip("playwright.sync_api")
    with playwright_api.sync_playwright() as pw:
        instance = pw.chromium.launch(executable_path=chromium_path(), args=CHROMIUM_ARGS)
        new_context = instance.new_context

        def patient_context(*args: object, **kwargs: object) -> object:
            context = new_context(*args, **kwargs)
            context.set_default_timeout(ACTION_TIMEOUT_MS)
            context.add_init_script(SLOW_DISPLAY_JS)
            return context

        instance.new_context = patient_context
        try:
            yield instance
        finally:
            instance.close()


DISPLAY_HZ = 10
"""Refresh rate of the test browsers' display (see :data:`SLOW_DISPLAY_JS`)."""

SLOW_DISPLAY_JS = """(() => {
  const period = 1000 / HZ;
  const frame = window.requestAnimationFrame.bind(window);
  let waiting = new Map(), seq = 0, armed = false, last = 0;
  function run(t) {
    armed = false; last = performance.now();
    const due = waiting; waiting = new Map();
    due.forEach((cb) => { try { cb(t); } catch (e) { setTimeout(() => { throw e; }); } });
  }
  function arm() {
    if (armed) return;
    armed = true;
    const wait = last + period - performance.now();
    if (wait < 1) frame(run); else setTimeout(() => frame(run), wait);
  }
  window.requestAnimationFrame = (cb) => {
    const id = ++seq; waiting.set(id, cb); arm(); return id;
  };
  window.cancelAnimationFrame = (id) => { waiting.delete(id); };
})();""".replace("HZ", str(DISPLAY_HZ))
"""Every test page sees a display refreshing :data:`DISPLAY_HZ` times a second: the
chromium of CI draws the 3D without a graphics card, and viser draws at every animation
frame while frames arrive, so at 60 Hz each page playing a scene took a whole core (70 ms
a drawn frame at 1280x720), and two test workers starved each other and their servers.
The tests read the page, not its smoothness; a slow display is a real student's case."""

ACTION_TIMEOUT_MS = 90_000
"""How long a click or a fill may wait for its page (Playwright's default is 30 s): on a
slow 2-core CI machine, three pages drawing in software once took longer than that to
take a click, the product being right. A failure still fails, only later."""

PROJECTOR = {"width": 1280, "height": 720}
"""A projected page's viewport."""


@pytest.fixture
def projector_context(browser) -> Iterator[object]:
    """A fresh browser context at :data:`PROJECTOR`'s size, closed after the test."""
    context = browser.new_context(viewport=PROJECTOR)
    try:
        yield context
    finally:
        context.close()


@pytest.fixture
def open_page(browser) -> Iterator[object]:
    """Factory opening pages in a fresh browser context, all closed after the test."""
    context = browser.new_context(viewport={"width": 1400, "height": 900})

    def open_(url: str):
        page = context.new_page()
        page.goto(url)
        return page

    try:
        yield open_
    finally:
        context.close()


def wait_for(predicate: Callable[[], object], timeout: float = 20.0, poll: float = 0.05) -> bool:
    """Poll ``predicate`` until it is true or ``timeout`` seconds pass; its last value."""
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        if predicate():
            return True
        time.sleep(poll)
    return bool(predicate())


def settled(read: Callable[[], object], polls: int = 3, timeout: float = 15.0) -> bool:
    """Poll ``read`` every 0,1 s until it returns the same value ``polls`` times in a row
    (a page's layout or text has stopped changing), rather than sleeping a fixed time;
    False if it still changes after ``timeout`` seconds."""
    seen: list[object] = []

    def same() -> bool:
        seen.append(read())
        recent = seen[-polls:]
        return len(recent) == polls and recent[0] is not None and recent.count(recent[0]) == polls

    return wait_for(same, timeout=timeout, poll=0.1)


def pause(page) -> None:
    """Pause the page's simulation from its « Pause » button and wait for « Lecture »: a
    check of words and boxes that motion does not change then costs no 3D drawing (a
    playing page redraws its 3D at every frame, in software on CI)."""
    page.get_by_role("button", name="Pause", exact=True).press("Enter")
    page.get_by_role("button", name="Lecture", exact=True).wait_for(timeout=30_000)


def choose(page, label: str, option: str) -> None:
    """Pick ``option`` in the page's dropdown labelled ``label`` (Playwright page)."""
    row = page.locator("div.mantine-Flex-root", has=page.get_by_text(label, exact=True)).last
    row.locator("input").first.click()
    page.get_by_role("option", name=option, exact=True).click()


LESSON_FILE = """---
scene: compressor
title: Ma leçon à moi
level: L3
---

## Premier pas
preset: speed_rpm=1500

Regardez le piston.
"""
"""A teacher's own lesson file, valid, for the tests that open one from a path."""
