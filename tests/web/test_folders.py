"""« Panneau affiché » derives from one list: each panel declares its folders (title,
kept during a challenge or not, readouts it needs, refresh), and the view builds the
picker, closes folders during a challenge, asks the frame for readouts and refreshes
only what is shown from that list alone."""

from __future__ import annotations

import ast
from collections.abc import Iterator
from pathlib import Path

import pytest

from sandbox import challenges
from sandbox.scenes import SCENES
from sandbox.web.loop import EVERY
from sandbox.web.loop.secret import Secret
from sandbox.web.panels.accuracy import FOLDER as ACCURACY
from sandbox.web.panels.isolate import FOLDER as ISOLATE
from sandbox.web.panels.readouts import ENERGY_FOLDER, PLOTS_FOLDER, SCENE_FOLDER, TORSORS_FOLDER
from sandbox.web.views.browser import ALL_FOLDERS
from tests.robustness.test_hostile_web import Page

ROOT = Path(__file__).resolve().parents[2]


@pytest.fixture
def rotor_page(tmp_path: Path) -> Iterator[Page]:
    """The rotor's page, a few frames in."""
    made = Page("rotor", tmp_path)
    made.tick(0.2)
    yield made
    made.session.stop()


@pytest.mark.parametrize("scene", sorted(SCENES))
def test_the_picker_lists_the_panels_folders_in_order(scene: str, tmp_path: Path) -> None:
    page = Page(scene, tmp_path)
    try:
        view = page.view
        titles = [f.title for f in view.pickable]
        assert len(set(titles)) == len(titles)  # one folder per title
        assert list(view.picker.options) == [*titles, ALL_FOLDERS]
        assert titles[0] == SCENE_FOLDER and PLOTS_FOLDER in titles
        assert {ISOLATE, ACCURACY, TORSORS_FOLDER, ENERGY_FOLDER} <= set(titles)
    finally:
        page.session.stop()


def test_a_challenge_keeps_the_secret_safe_folders_only(rotor_page: Page) -> None:
    page = rotor_page
    view = page.view
    safe = [f.title for f in view.pickable if f.secret_safe]
    closed = [f.title for f in view.pickable if not f.secret_safe]
    assert SCENE_FOLDER in safe and ISOLATE in closed and ACCURACY in closed
    attempt = challenges.start("rotor_balance", "r", dict(page.ctl.sim.values), 0.0)
    view.restrict(Secret(attempt))
    assert list(view.picker.options) == [*safe, ALL_FOLDERS]
    view.show_folder(ISOLATE)  # a crafted pick of a closed folder is refused
    page.tick(0.2)
    assert view.shown != ISOLATE and not view.groups[ISOLATE].visible
    view.unrestrict()
    assert list(view.picker.options) == [*(f.title for f in view.pickable), ALL_FOLDERS]


def test_a_frame_asks_for_the_shown_folders_readouts_and_refreshes_only_it(
    rotor_page: Page,
) -> None:
    page = rotor_page
    view = page.view
    calls: list[str] = []
    for k, folder in enumerate(view.pickable):
        if folder.refresh is not None:
            inner = folder.refresh
            object.__setattr__(  # the same folder, counted
                view.pickable[k],
                "refresh",
                lambda frame, title=folder.title, inner=inner: (calls.append(title), inner(frame)),
            )
    view.show_folder(TORSORS_FOLDER)
    page.tick(0.5)
    assert set(calls) == {TORSORS_FOLDER} and len(calls) >= 3  # 10 Hz for 0.5 s
    torsors = view.wants(page.clock.now + 1.0)
    view.show_folder(ENERGY_FOLDER)
    energy = view.wants(page.clock.now + 2.0)
    assert torsors is not None and energy is not None and EVERY not in (torsors, energy)
    assert {"kin_R_x", "dyn_M_z"} <= set(torsors) - set(energy)
    calls.clear()
    view.show_folder(ALL_FOLDERS)
    page.tick(0.3)
    assert set(calls) == {f.title for f in view.pickable if f.refresh is not None}


def test_the_view_and_the_session_never_ask_what_their_source_is() -> None:
    """No ``isinstance`` on the source: a live page is given its session (``live``), a
    replay its own controls."""
    for rel in (
        "sandbox/web/views/browser.py",
        "sandbox/web/views/share.py",
        "sandbox/web/loop/session.py",
        "sandbox/web/serving/class_app.py",
    ):
        tree = ast.parse((ROOT / rel).read_text(encoding="utf-8"))
        for node in ast.walk(tree):
            if isinstance(node, ast.Call) and getattr(node.func, "id", "") == "isinstance":
                kinds = ast.unparse(node.args[1])
                assert not any(k in kinds for k in ("Controller", "WebView", "ControlPanel")), (
                    f"{rel}:{node.lineno}: isinstance(…, {kinds})"
                )
