"""How a readout is written, one definition for every view (issue 36)."""

from __future__ import annotations

import math

import pytest

from sandbox.written import Written, time_words, with_unit, written


def test_a_value_is_written_with_the_tables_digits_in_the_pages_unit():
    assert str(written("motor_torque", 1.0043, "N·m")) == "1,004\u00a0N·m"  # not « 1 »
    assert str(written("omega", 157.0796, "rad/s")) == "1\u202f500\u00a0tr/min"
    assert str(written("omega", 157.0796, "rad/s", digits=3)) == "1\u202f500\u00a0tr/min"
    assert str(written("gimbal_outer", -0.5, "rad")) == "−28,65°"  # swings both ways
    assert str(written("speed_rpm", 3000.0, "rpm")) == "3\u202f000\u00a0tr/min"
    assert written("bearing_A", 54.4174, "N") == Written("54,42", "N", 54.4174)


def test_a_turn_counter_is_written_modulo_a_turn_after_rounding():
    """θ unwrapped in files (16 994 rad after a minute at 3000 tr/min) is an angle on
    the page: 973 684° was written; and 359,99996° rounds to 0, never to « 360 »."""
    assert str(written("theta", 16994.0, "rad")) == str(
        written("theta", 16994.0 % (2 * math.pi), "rad")
    )
    assert 0.0 <= written("theta", 16994.0, "rad").value < 360.0
    almost = math.radians(359.99996) + 20 * math.pi
    assert written("theta", almost, "rad").number == "0"
    assert written("theta", 4 * math.pi + 0.5, "rad").number == "28,65"
    # a turn's precision: 3,3×10⁻⁸ rad past 3000 turns is 0°, not 1,88×10⁻⁶°
    assert written("theta", 6000 * math.pi + 3.3e-8, "rad").number == "0"
    assert written("theta", 0.001, "rad").number == "0,0573"


def test_flags_round_off_and_missing_values():
    assert str(written("contact", 1.0, "")) == "oui" and str(written("contact", 0.0, "")) == "non"
    assert str(written("P_int", -5.5e-15, "W", zero=1e-9)) == "0\u00a0W"
    assert str(written("P_int", 5.5e-15, "W")) == "5,5×10⁻¹⁵\u00a0W"
    # the round-off is in the contract unit: 1e-9 rad/s is 1e-8 tr/min
    assert written("omega", 2e-9, "rad/s", zero=1e-9).number != "0"
    assert written("omega", 0.9e-9, "rad/s", zero=1e-9).number == "0"
    assert str(written("bearing_A", math.nan, "N")) == "—\u00a0N"
    assert written("contact", math.inf, "").number == "—"
    assert written("bearing_A", "abc", "N").number == "—"  # type: ignore[arg-type]


@pytest.mark.parametrize(
    "t, words",
    [(13.46, "13,46"), (13.4600000001, "13,46"), (0.0, "0,00"), (1234.5, "1\u202f234,50"),
     (-0.004, "0,00"), (-1.5, "−1,50"), (math.nan, "—")],
)  # fmt: skip
def test_a_time_is_written_to_the_hundredth(t, words):
    assert time_words(t) == words


def test_the_unit_follows_french_typography():
    assert with_unit("29", "°") == "29°" and with_unit("3", "N") == "3\u00a0N"
    assert with_unit("0,5", "") == "0,5"


def test_the_compressors_dead_centre_reads_zero_not_round_off():
    """Seen by a teacher at θ = 270° while the compressor ran: « Effet de tamis =
    −2,622×10⁻⁷ N » beside a 269,8 N pilon and « Couple nécessaire = −1,969×10⁻⁹ N·m »:
    the inverse dynamics' round-off, written as a number. They read 0; the pilon keeps
    its four digits."""
    from sandbox.scenes import SCENES

    scene = SCENES["compressor"]
    assert str(written("tamis", -2.622e-7, "N", zero=scene.zero_for("N"))) == "0\u00a0N"
    torque = written("motor_torque", -1.969e-9, "N·m", zero=scene.zero_for("N·m"))
    assert str(torque) == "0\u00a0N·m"
    assert str(written("pilon", -269.78, "N", zero=scene.zero_for("N"))) == "−269,8\u00a0N"


def test_a_recordings_date_reads_in_french():
    """A replay's header wrote « enregistré le 2026-11-29T11:20:41+00:00 »."""
    from sandbox.written import date_words

    assert date_words("2026-11-29T11:20:41+00:00") == "29/11/2026 à 11 h 20 (UTC)"
    assert date_words("2026-11-29T09:05:00") == "29/11/2026 à 9 h 05"
    assert date_words("<b>pas une date</b>") == "<b>pas une date</b>"  # escaped where shown


@pytest.mark.parametrize(("duration", "frames"), [(13.46, 137), (13.4600000001, 1347), (0.05, 3)])
def test_the_replay_s_time_box_has_the_status_line_s_hundredths(duration, frames):
    """« 13,4600000 » was the replay's time box: its step, end (and so its value) have at
    most two decimals."""
    from sandbox.web.replay.player import timeline_scale

    step, top = timeline_scale(duration, frames)
    for value in (step, top):
        assert value == round(value, 2) and len(repr(value).split(".")[-1]) <= 2
    assert top >= duration - 1e-9 and step >= 0.01
