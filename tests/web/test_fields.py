"""Controls that tell the truth, French labels and numbers typed the French way (no
browser: a stand-in for viser's input handle)."""

from __future__ import annotations

import math

import pytest

from sandbox.physics.model import integrator_words
from sandbox.physics.spec import Param
from sandbox.web.client.fields import (
    GRACE,
    Mirror,
    engineering,
    integrator_name,
    param_hint,
    param_label,
    parse_number,
)
from sandbox.web.panels.projector import overlay_html, overlay_lines, style_html


class Handle:
    """viser's input handle as Mirror sees it: a value and the time it last changed."""

    def __init__(self, value: object, at: float = 0.0) -> None:
        self._value = value
        self.update_timestamp = at
        self.sent: list[object] = []
        self.clock = at
        self.visible = True

    @property
    def value(self) -> object:
        return self._value

    @value.setter
    def value(self, value: object) -> None:  # the server shows a value
        self._value = value
        self.update_timestamp = self.clock
        self.sent.append(value)

    def user(self, value: object, at: float) -> None:  # the browser changes it
        self._value = value
        self.update_timestamp = at


def _mirror(handle: Handle, truth: dict[str, float], busy: list[bool] | None = None) -> Mirror:
    flag = busy if busy is not None else [False]
    return Mirror(
        handle,  # type: ignore[arg-type]
        lambda: truth["v"],
        busy=lambda: flag[0],
        clock=lambda: handle.clock,
    )


def test_a_value_changed_and_changed_back_between_refreshes_is_still_shown():
    """The issue's step 4: the user types 32 g, the step's preset puts 0 back before the
    panel refreshes; the slider must show 0 (the old code compared the simulation with
    the last value it had seen, 0, and left 32 on screen)."""
    truth = {"v": 0.0}
    handle = Handle(0.0)
    mirror = _mirror(handle, truth)
    handle.user(32.0, at=1.0)  # typed; the preset then sets the simulation back to 0
    handle.clock = 1.0 + GRACE + 0.01
    assert mirror.refresh()
    assert handle.value == 0.0 and handle.sent == [0.0]
    # viser's box remembers the typed "32": it is built anew (hidden for one refresh)
    # so that typing 32 again is sent
    assert not handle.visible
    assert not mirror.refresh() and handle.visible


def test_a_control_just_moved_by_the_user_is_left_alone_until_its_request_is_applied():
    truth = {"v": 1500.0}
    handle = Handle(1500.0)
    busy = [True]
    mirror = _mirror(handle, truth, busy)
    handle.user(3000.0, at=5.0)
    handle.clock = 5.05
    assert not mirror.refresh()  # requests waiting, and the user moved it just now
    busy[0] = False
    assert not mirror.refresh()  # within the grace period
    truth["v"] = 3000.0  # applied
    handle.clock = 6.0
    assert not mirror.refresh() and handle.value == 3000.0


def test_a_refusal_puts_the_value_in_force_back_at_once():
    truth = {"v": 0.01}
    handle = Handle(0.01)
    mirror = _mirror(handle, truth)
    handle.user(0.0, at=2.0)
    handle.clock = 2.01
    assert mirror.refresh(force=True)
    assert handle.value == 0.01


def test_server_side_changes_follow_without_delay():
    truth = {"v": 1500.0}
    handle = Handle(1500.0)
    mirror = _mirror(handle, truth)
    for value in (3000.0, 1500.0, 3000.0):  # presets, steps, a teacher's push
        truth["v"] = value
        handle.clock += 0.1
        assert mirror.refresh()
        assert handle.value == value


@pytest.mark.parametrize(
    ("typed", "value"),
    [
        ("0,0002", 2e-4),
        ("2e-4", 2e-4),
        ("2×10⁻⁴", 2e-4),
        ("2·10^-4", 2e-4),
        ("1 500", 1500.0),
        ("1\u202f500,5", 1500.5),
        ("−3", -3.0),
    ],
)
def test_numbers_typed_the_french_way(typed: str, value: float):
    assert parse_number(typed) == pytest.approx(value)


@pytest.mark.parametrize("typed", ["abc", "nan", "inf", "1e999", "", "x" * 100])
def test_what_is_not_a_number_goes_to_the_session_unchanged(typed: str):
    assert parse_number(typed) == typed


def test_engineering_notation_never_shows_zeros_for_a_small_inertia():
    assert engineering(2e-4) == "0,0002"
    assert engineering(1.2e-7) == "1,2×10⁻⁷"
    assert engineering(0.0) == "0"
    assert parse_number(engineering(1.2e-7)) == pytest.approx(1.2e-7)


def test_labels_in_words_with_the_display_unit_and_a_french_tooltip():
    p = Param("speed_rpm", "rpm", 1500.0, 0.0, 6000.0, "Rotor speed.", label="Vitesse ω")
    assert param_label(p) == "Vitesse ω [tr/min]"
    bare = Param("angle1_deg", "deg", 0.0, -180.0, 180.0, "Angle.", hint="Angle de la masse.")
    assert param_label(bare) == "angle1_deg [°]"  # until the labels are filled
    assert param_hint(bare) == "Angle de la masse (de −180 à 180 °)."


def test_integrators_in_words_and_back():
    for name in ("euler", "implicit", "implicitfast", "rk4", "discrete"):
        assert integrator_name(integrator_words(name)) == name
    assert integrator_name("leapfrog") == "leapfrog"  # refused later, in French


def test_overlay_lines_are_french_and_escaped():
    lines = overlay_lines(
        ["omega", "bearing_A", "gone"],
        {"omega": 157.08, "bearing_A": 54.4},
        {"omega": "Vitesse ω", "bearing_A": "<b>Palier A</b>"},
        {"omega": "rad/s", "bearing_A": "N"},
    )
    # ω in tr/min, as the speed slider (157,08 rad/s = 1500 tr/min)
    assert lines == [
        "Vitesse ω = 1\u202f500\u00a0tr/min",
        "<b>Palier A</b> = 54,4\u00a0N",
        "gone = —",
    ]
    html = overlay_html(lines)
    assert "<b>" not in html and "&lt;b&gt;" in html


def test_the_page_style_sets_at_least_16_px():
    css = style_html(16)
    assert "--mantine-font-size-xs:16px" in css and "sandbox-overlay" in css


def test_overlay_shows_turning_angles_modulo_a_turn_and_flags_in_words():
    lines = overlay_lines(
        ["theta", "contact"], {"theta": 4 * math.pi + 0.5, "contact": 1.0}, {}, {"theta": "rad"}
    )
    assert lines == ["theta = 28,65°", "contact = oui"]
    (gimbal,) = overlay_lines(["gimbal_outer"], {"gimbal_outer": -0.5}, {}, {"gimbal_outer": "rad"})
    (residual,) = overlay_lines(["r"], {"r": -5.5e-15}, {"r": "Écart"}, {"r": "W"}, {"r": 1e-9})
    assert residual == "Écart = 0\u00a0W"  # below the scene's round-off
    assert gimbal == "gimbal_outer = −28,65°"  # not modulo: a gimbal swings both ways


def test_typing_a_number_never_refuses_its_first_digits(monkeypatch):
    """The browser sends a number box's value at every key: typing « 0,01 » in « Vitesse
    × » (×0,01 to ×4) sent 0 first, refused at once, and the old value put back under
    the user's fingers made « 1.01 ». A value outside the control's range waits TYPING
    seconds; the next key's in-range value replaces it and applies at once; one left
    alone is applied (and refused by the session) once the user stops."""
    from types import SimpleNamespace

    from conftest import wait_for

    from sandbox.web.client import fields

    monkeypatch.setattr(fields, "TYPING", 0.2)
    callbacks, applied = [], []
    handle = SimpleNamespace(disabled=False, on_update=callbacks.append, min=0.01, max=4.0)
    fields.on_user(handle, applied.append)  # type: ignore[arg-type]

    def key(value: float) -> None:
        callbacks[0](SimpleNamespace(client=object(), target=SimpleNamespace(value=value)))

    key(0.0)  # « 0 »
    key(0.0)  # « 0,0 »
    key(0.01)  # « 0,01 »: in range, applied at once
    assert applied == [0.01]
    key(5.0)  # out of range, then nothing more: applied once the user stops
    assert applied == [0.01]
    assert wait_for(lambda: applied == [0.01, 5.0], timeout=5)
    # the zeros typed first were never applied, even later
    assert applied == [0.01, 5.0]
