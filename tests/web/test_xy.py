"""The "Tracé X–Y": readouts sampled between frames by the session's probe, folded,
sorted and read at a cursor, against the course's closed forms."""

from __future__ import annotations

import csv
import io
import math

import numpy as np
import pytest

from sandbox.physics.presets import TIME
from sandbox.physics.simulation import Simulation
from sandbox.physics.units import RAD_S_TO_RPM
from sandbox.scenes import SCENES, get_scene, resolve
from sandbox.sweep import STATISTICS
from sandbox.web.loop import Controller
from sandbox.web.loop.probe import RATE, Probe
from sandbox.web.panels.xy_data import TIME_AXIS, Axis, XYData, finite_ends, slope_unit


def _axis(sim: Simulation, name: str) -> Axis:
    if name == TIME:
        return TIME_AXIS
    info = {i.name: i for i in sim.readout_infos()}[name]
    return Axis.of(name, info.label or name, info.unit)


class Clock:
    """A wall clock the frames move on (the session's time never goes back)."""

    def __init__(self) -> None:
        self.now = 100.0

    def __call__(self) -> float:
        return self.now


def _run(ctl: Controller, seconds: float, fps: float = 60.0) -> None:
    """Frames of the session loop over ``seconds`` of wall time (a fake clock, moved on
    by each frame when the controller has one)."""
    clock = ctl.clock
    t0 = clock()
    for k in range(1, int(seconds * fps) + 1):
        if isinstance(clock, Clock):
            clock.now = t0 + k / fps
        ctl.frame(t0 + k / fps)


def test_the_probe_splits_steps_and_keeps_its_rate():
    """Every step is run, and samples come at most RATE per wall second, spaced
    between half and one and a half times the mean."""
    probe = Probe()
    probe.want("view", ["pilon"])
    dt = 5e-4  # 10 steps per sample at speed 1
    pieces = list(probe.chunks(20_000, dt, 1.0))
    assert sum(m for m, _ in pieces) == 20_000
    samples = sum(1 for _, s in pieces if s)
    assert samples == pytest.approx(20_000 * dt * RATE, rel=0.02)
    spans = [m for m, s in pieces if s]
    assert 5 <= min(spans) and max(spans) <= 15
    assert len(set(spans)) > 3  # uneven: a periodic motion is met at every phase
    fresh = Probe()
    fresh.want("view", ["pilon"])
    slow = sum(1 for _, s in fresh.chunks(200, dt, 0.01) if s)  # slow motion: every step
    assert slow == 200
    probe.release("view")
    assert not probe.active and probe.names == ()


def test_nothing_is_sampled_while_no_view_wants_it():
    """Counted, not timed: no readout evaluated between frames when no X–Y plot is
    shown; with one, about RATE samples per wall second whatever the speed."""
    ctl = Controller(Simulation(get_scene("compressor")), clock=Clock())
    _run(ctl, 0.5)
    assert ctl.probe.since(0) == (0, [])
    ctl.probe.want("view", ["theta", "pilon"])
    _run(ctl, 1.0)
    seq, samples = ctl.probe.since(0)
    assert RATE * 0.9 <= len(samples) <= RATE * 1.1
    assert set(samples[0][1]) == {"theta", "pilon"}
    ctl.probe.release("view")
    _run(ctl, 0.5)
    assert ctl.probe.since(seq)[1] == []


def test_the_compressors_pilon_over_a_revolution_matches_the_course():
    """Course 7.3: the pilon and tamis against the crank angle θ, folded on one
    revolution at 3000 rpm, reach every angle the physics steps reach (its per-revolution
    timestep gives 40 steps a turn: every 9°) and equal the course's exact slider-crank
    expressions (dashed) within 0.1 % of their peak."""
    sim = Simulation(get_scene("compressor"))
    ctl = Controller(sim, clock=Clock())
    data = XYData(
        _axis(sim, "theta"),
        [_axis(sim, "pilon"), _axis(sim, "tamis")],
        {"pilon": "pilon_ref", "tamis": "tamis_ref"},
    )
    ctl.probe.want("view", data.names)
    _run(ctl, 2.0)
    data.add(ctl.probe.since(0)[1])
    x, values = data.shown()
    assert 0 <= x.min() and x.max() < 360 and np.all(np.diff(x) >= 0)
    step = 360.0 * 50.0 * sim.timestep  # degrees a timestep at 3000 rpm
    assert step == pytest.approx(9.0)
    assert np.max(np.diff(np.r_[x, x[0] + 360])) < step * 1.01
    for name in ("pilon", "tamis"):
        peak = np.max(np.abs(values[f"{name}_ref"]))
        assert np.max(np.abs(values[name] - values[f"{name}_ref"])) < 1e-3 * peak
    arrays = data.arrays(0.5)
    assert len(arrays) == 1 + len(data.layout()) == 8  # x, 2 × (y, ref, mark), range
    assert all(len(a) == len(arrays[0]) and np.isfinite(a[[0, -1]]).all() for a in arrays)


def test_the_rotors_start_draws_the_course_parabola():
    """Course 7.2 during the rotor's start from rest (the preset: τ = 2 s to 6000 rpm):
    bearing A against ω follows K·ω² (its dashed closed form) within 0.1 % above
    1000 rpm, and the cursor's slope equals 2·K·ω within 2 %."""
    preset = next(p for p in SCENES["rotor"].page.xy_presets if p.values)
    sim = Simulation(get_scene("rotor"), values=dict(preset.values))
    ctl = Controller(sim, clock=Clock())
    data = XYData(
        _axis(sim, preset.x),
        [_axis(sim, y) for y in preset.ys],
        {y: f"{y}_ref" for y in preset.ys},
    )
    assert data.names == ("omega", "bearing_A", "bearing_B", "bearing_A_ref", "bearing_B_ref")
    ctl.probe.want("view", data.names)
    _run(ctl, 6.0)
    data.add(ctl.probe.since(0)[1])
    x, values = data.shown()  # ω in tr/min
    assert x.max() > 5000 and x.min() < 200
    fast = x > 1000
    gap = np.abs(values["bearing_A"][fast] / values["bearing_A_ref"][fast] - 1)
    assert gap.max() < 1e-3
    found = data.read(0.8)
    assert found is not None
    at, ((axis, value, slope), _) = found
    assert axis.name == "bearing_A"
    k = value / at**2  # N per (tr/min)²
    assert slope == pytest.approx(2 * k * at, rel=0.02)
    text = data.reading(0.8, SCENES["rotor"].zero)
    assert "pente" in text and "N/(tr/min)" in text and "tr/min" in text
    assert "." not in text.replace("**", "")  # decimal commas only


def test_constant_x_says_what_to_do():
    sim = Simulation(get_scene("rotor"))
    data = XYData(_axis(sim, "omega"), [_axis(sim, "bearing_A")], {})
    data.add((t, {"omega": 157.0, "bearing_A": 54.4}) for t in (0.0, 0.1, 0.2))
    assert "X ne varie pas" in data.reading(0.5)
    assert "lancez la simulation" in XYData(TIME_AXIS, [_axis(sim, "T")], {}).reading(0.5)


def test_time_keeps_a_window_and_a_reset_starts_again():
    sim = Simulation(get_scene("rotor"))
    data = XYData(TIME_AXIS, [_axis(sim, "bearing_A")], {})
    data.add((t / 10, {"bearing_A": 1.0}) for t in range(300))
    assert len(data) == 101  # 10 s kept
    data.add([(0.0, {"bearing_A": 2.0})])  # time went back: a reset
    assert len(data) == 1


def test_the_csv_keeps_contract_names_and_units():
    """Files keep the contract: ω in rad/s and the readouts' names, dot decimals."""
    sim = Simulation(get_scene("rotor"))
    data = XYData(_axis(sim, "omega"), [_axis(sim, "bearing_A")], {"bearing_A": "bearing_A_ref"})
    data.add([(0.5, {"omega": 100.0, "bearing_A": 22.0, "bearing_A_ref": 22.1})])
    rows = list(csv.reader(io.StringIO(data.csv_text())))
    assert rows == [["time", "omega", "bearing_A", "bearing_A_ref"], ["0.5", "100", "22", "22.1"]]
    x, _ = data.shown()
    assert x[0] == pytest.approx(100 * RAD_S_TO_RPM)  # the page: tr/min


def test_the_png_is_a_png_in_french():
    sim = Simulation(get_scene("rotor"))
    data = XYData(_axis(sim, "omega"), [_axis(sim, "bearing_A")], {"bearing_A": "bearing_A_ref"})
    data.add(
        (t, {"omega": w, "bearing_A": w * w, "bearing_A_ref": w * w})
        for t, w in enumerate(np.linspace(1, 100, 20))
    )
    png = data.png("Effort du palier A selon ω", ["#2860e6"])
    assert png[:8] == b"\x89PNG\r\n\x1a\n" and len(png) > 10_000


def test_helpers():
    assert slope_unit("N", "tr/min") == "N/(tr/min)"
    assert slope_unit("N", "°") == "N/°"
    assert slope_unit("", "s") == "1/s"
    column = np.array([math.nan, 1.0, math.nan, 3.0, math.nan])
    assert finite_ends(column)[[0, -1]].tolist() == [1.0, 3.0]
    assert finite_ends(np.full(3, math.nan))[[0, -1]].tolist() == [0.0, 0.0]


@pytest.mark.parametrize("name", sorted(SCENES))
def test_every_preset_names_what_its_scene_has(name):
    """Each scene proposes X–Y plots and studies made of its own readouts and
    parameters, within the parameters' bounds, with French labels."""
    scene = SCENES[name]
    sim = Simulation(resolve(name))
    readouts = set(sim.readout_names())
    params = {p.name: p for p in scene.params}
    assert scene.page.xy_presets, f"{name} proposes no X–Y plot"
    for p in scene.page.xy_presets:
        assert p.x in readouts and 1 <= len(p.ys) <= 3 and set(p.ys) <= readouts
        assert set(p.refs.values()) <= readouts
        assert set(p.values) <= set(params) and p.hint
        units = {u for n, u in ((i.name, i.unit) for i in sim.readout_infos()) if n in p.ys}
        assert len(units) == 1, f"{p.label}: one unit on the Y axis"
    for s in scene.page.study_presets:
        for vary in (s.vary, s.family) if s.family else (s.vary,):
            q = params[vary[0]]
            assert q.min <= vary[1] < vary[2] <= q.max and vary[3] >= 2
        assert s.measure in readouts and s.statistic in STATISTICS and s.hint
        assert set(s.fixed) <= set(params)


def test_a_flat_curve_reads_a_slope_of_zero_not_round_off():
    """The rotor's bearing force at constant speed: its slope against time is round-off
    (3×10⁻¹⁴ N/s), shown as 0."""
    sim = Simulation(get_scene("rotor"))
    data = XYData(TIME_AXIS, [_axis(sim, "bearing_A")], {})
    rng = np.random.default_rng(0)
    data.add((t / 100, {"bearing_A": 54.4 + 1e-13 * rng.standard_normal()}) for t in range(300))
    text = data.reading(0.5, SCENES["rotor"].zero)
    assert "pente 0\u00a0N/s" in text and "10⁻" not in text


def test_a_nearly_flat_curve_gets_room_around_it_and_a_wide_one_keeps_its_range():
    """The heavy top's nutation rate steady to 3×10⁻⁷ °/s: uPlot zoomed into round-off
    and every tick read « 30 ». The chart's last, invisible column holds 30 ± 2 % at its
    ends (flat_limits); a curve that spans its range keeps its own ends."""
    sim = Simulation(get_scene("rotor"))
    data = XYData(TIME_AXIS, [_axis(sim, "bearing_A")], {})
    assert data.layout()[-1][0] == "range"
    data.add((t / 100, {"bearing_A": 30.0 + 3e-7 * math.sin(t)}) for t in range(200))
    bounds = data.arrays()[-1]
    assert bounds[0] == pytest.approx(29.4, rel=1e-6) and bounds[-1] == pytest.approx(30.6)
    assert np.isnan(bounds[1:-1]).all()  # drawn nowhere
    wide = XYData(TIME_AXIS, [_axis(sim, "bearing_A")], {})
    wide.add((t / 100, {"bearing_A": float(t)}) for t in range(200))
    ends = wide.arrays()[-1]
    assert (ends[0], ends[-1]) == (0.0, 199.0)


def test_a_slope_below_what_the_written_digits_show_reads_zero():
    """The heavy top's steady nutation, 30° drifting 3×10⁻⁶° in 10 s (its integration's
    own drift): « pente 3,35×10⁻⁷ °/s » was a number no digit of the curve shows. A
    slope that moves Y by less than half its fourth significant digit over the range
    reads 0; one that moves it by more is written."""
    sim = Simulation(get_scene("heavy_gyroscope"))
    data = XYData(TIME_AXIS, [_axis(sim, "nutation")], {})
    data.add((t / 10, {"nutation": math.radians(30.0 + 3.35e-7 * t / 10)}) for t in range(100))
    assert "pente 0\u00a0°/s" in data.reading(0.5, SCENES["heavy_gyroscope"].zero)
    moving = XYData(TIME_AXIS, [_axis(sim, "nutation")], {})
    moving.add((t / 10, {"nutation": math.radians(30.0 + 0.01 * t / 10)}) for t in range(100))
    assert "pente 0,01\u00a0°/s" in moving.reading(0.5, SCENES["heavy_gyroscope"].zero)
