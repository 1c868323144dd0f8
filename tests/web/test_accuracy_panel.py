"""Live accuracy panel: shipped benchmark, live error and drift, chart with the live point."""

from __future__ import annotations

import math

from sandbox.bench import Run
from sandbox.physics.simulation import Simulation
from sandbox.web.accuracy_panel import AccuracyPanel, chart_image, load_results


class Handle:
    def __init__(self, content="", image=None):
        self.content = content
        self.image = image


class Gui:
    """Just enough of viser's GuiApi for a panel."""

    def add_folder(self, label):
        import contextlib

        return contextlib.nullcontext()

    def add_markdown(self, content):
        return Handle(content)

    def add_image(self, image, **kwargs):
        return Handle(image=image)


def test_shipped_benchmark_has_the_rotor_default_on_its_front():
    res = load_results("rotor")
    assert res is not None and res.default is not None and res.default.pareto
    assert load_results("no_such_scene") is None


def test_chart_image_is_rgb_with_the_live_point():
    res = load_results("rotor")
    plain = chart_image(res, None)
    live = Run("rotor", "rk4", 1e-3, 0.0, error=1e-3, cpu_per_sim_s=5e-3)
    marked = chart_image(res, live)
    assert plain.ndim == 3 and plain.shape[2] == 3 and (plain != marked).any()


def test_live_error_and_drift_follow_the_simulation():
    sim = Simulation("rotor", values={"speed_rpm": 3000})
    panel = AccuracyPanel(Gui(), sim)
    for _ in range(10):
        sim.advance(0.05)
        panel.sample(sim, sim.readouts(), generation=0)
    error, drift = panel.measures(sim)
    assert error < 1e-9 and drift < 1e-9  # a uniform rotation: exact
    panel.refresh(sim, cost=2e-3, now=100.0)
    assert "×500" in panel.text.content and "bearing_A" in panel.text.content
    sim.set_timestep(2e-3)  # a new setting starts a new series
    panel.sample(sim, sim.readouts(), generation=0)
    assert len(panel.samples) == 1
    assert math.isnan(panel.measures(sim)[0])


def test_a_file_has_cost_but_no_error(pendulum_xml):
    sim = Simulation(pendulum_xml)
    panel = AccuracyPanel(Gui(), sim)
    panel.refresh(sim, cost=1e-3, now=0.0)
    assert "×1000" in panel.text.content and panel.image is None
    assert "Erreur" not in panel.text.content


def test_the_chart_is_drawn_off_the_session_loop_and_shown_when_ready():
    """refresh() only submits the drawing; a later refresh shows the finished image."""
    sim = Simulation("rotor")
    panel = AccuracyPanel(Gui(), sim)
    blank = panel.image.image
    panel.refresh(sim, cost=2e-3, now=100.0)
    assert panel._drawing is not None
    panel._drawing.result(timeout=60)
    assert panel.image.image is blank  # not yet picked up: no frame waited for it
    panel.refresh(sim, cost=2e-3, now=100.1)
    assert panel.image.image is not blank and panel.image.image.shape[2] == 3
    assert panel._drawing is None


def test_the_chart_base_is_drawn_once_per_scene_not_per_session():
    from sandbox.web.accuracy_panel import _BASES, chart_base

    first = chart_base(load_results("rotor"))
    count = len(_BASES)
    again = chart_base(load_results("rotor"))  # a second session loads its own results
    assert again[0] is first[0] and len(_BASES) == count


def test_charts_drawn_by_several_threads_at_once_are_all_correct():
    """Four sessions' charts and a bench chart drawn together: every image is the one
    drawn alone (matplotlib's mathtext parser, used by the log axes, is not thread-safe;
    the lock and the Figure objects keep the threads apart)."""
    import threading

    import numpy as np

    from sandbox.bench_plot import LOCK, draw
    from sandbox.web import charts
    from sandbox.web.accuracy_panel import _BASES

    res = load_results("rotor")
    live = Run("rotor", "rk4", 1e-3, 0.0, error=1e-3, cpu_per_sim_s=5e-3)
    _BASES.clear()
    alone = chart_image(res, live)
    _BASES.clear()

    def rgb(fig):
        with LOCK:
            fig.canvas.draw()
            return np.asarray(fig.canvas.buffer_rgba())[..., :3].copy()

    reference_fig = rgb(draw(res, live))
    images: list[np.ndarray] = []
    figures: list[np.ndarray] = []
    errors: list[BaseException] = []
    start = threading.Barrier(8)

    def session() -> None:
        try:
            start.wait()
            images.append(charts.submit(chart_image, res, live).result(timeout=60))
            images.append(chart_image(res, live))  # also straight from a session thread
        except BaseException as exc:  # noqa: BLE001  (reported below)
            errors.append(exc)

    def bench() -> None:
        try:
            start.wait()
            figures.append(rgb(draw(res, live)))
        except BaseException as exc:  # noqa: BLE001
            errors.append(exc)

    threads = [threading.Thread(target=session) for _ in range(4)]
    threads += [threading.Thread(target=bench) for _ in range(4)]
    for t in threads:
        t.start()
    for t in threads:
        t.join(120)
    assert not errors, errors
    assert len(images) == 8 and len(figures) == 4
    assert all(np.array_equal(image, alone) for image in images)
    assert all(np.array_equal(f, reference_fig) for f in figures)
    assert not (alone == 255).all()  # a real chart, not a blank
