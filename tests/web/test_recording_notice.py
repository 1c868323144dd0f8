"""The recording pop-ups name the file, never where the server keeps it; the teacher's
terminal says where."""

from __future__ import annotations

import logging
from pathlib import Path
from types import SimpleNamespace

from sandbox.physics.simulation import Simulation
from sandbox.scenes import get_scene
from sandbox.web.loop import Controller, Notice
from sandbox.web.loop.requests import Record, StopRecord
from sandbox.web.views.browser import WebView


class Clock:
    def __init__(self) -> None:
        self.now = 100.0

    def __call__(self) -> float:
        return self.now


class Page:
    """What notify() uses of a viser client: downloads and notifications."""

    def __init__(self) -> None:
        self.downloads: list[tuple[str, int]] = []
        self.toasts: list[tuple[str, str]] = []

    def send_file_download(self, name: str, content: bytes) -> None:
        self.downloads.append((name, len(content)))

    def add_notification(self, title: str, body: str, **_: object) -> None:
        self.toasts.append((title, body))


def _frames(ctl: Controller, seconds: float) -> list[Notice]:
    notices = []
    for _ in range(round(seconds * 60)):
        ctl.clock.now += 1 / 60
        notices += ctl.frame()
    return notices


def test_the_recording_pop_ups_name_the_file_only(tmp_path, caplog):
    folder = tmp_path / "secret-server-folder"
    ctl = Controller(Simulation(get_scene("rotor")), clock=Clock(), record_dir=folder)
    ctl.submit(Record())
    notices = _frames(ctl, 0.3)
    ctl.submit(StopRecord())
    notices += ctl.frame()
    (closed,) = [Path(n.text) for n in notices if n.level == "file"]
    page = Page()
    view = SimpleNamespace(client=page, _resync_controls=False, _last_panel=0.0)
    caplog.set_level(logging.INFO)
    for notice in notices:
        WebView.notify(view, notice)  # type: ignore[arg-type]
    shown = " ".join(f"{title} {body}" for title, body in page.toasts)
    assert "secret-server-folder" not in shown and str(tmp_path) not in shown, shown
    assert f"Enregistrement en cours dans {closed.name}" in shown
    assert f"Fichier {closed.name} (aussi téléchargé)." in shown
    assert page.downloads == [(closed.name, closed.stat().st_size)]
    logged = [r.getMessage() for r in caplog.records if r.levelno >= logging.WARNING]
    assert f"recording saved: {closed}" in logged  # the full path, in the terminal


def test_a_full_recording_names_the_next_file_only(tmp_path, monkeypatch):
    from sandbox.recording import limits

    monkeypatch.setattr(limits, "MAX_RECORDS", 150)
    ctl = Controller(Simulation(get_scene("rotor")), clock=Clock(), record_dir=tmp_path / "secret")
    ctl.submit(Record())
    notices = _frames(ctl, 3.0)
    full = next(n.text for n in notices if "Fichier plein" in n.text)
    name = full.rpartition(" dans ")[2]
    assert "secret" not in full and "/" not in name, full
    assert (tmp_path / "secret" / name).is_file()  # the file the recording goes on in
    ctl.stop_recording()
