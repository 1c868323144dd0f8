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
    text = panel.text.content
    assert "×500" in text and "Erreur relative sur Effort du palier A" in text
    assert "bearing_A" not in text and "Implicite rapide (implicitfast)" in text
    assert "| Dérive de T (relatif) |" in text  # the symbol, without "(constant speed)"
    assert "| Coût CPU par seconde simulée | 0,002 s |" in text
    sim.set_timestep(2e-3)  # a new setting starts a new series
    panel.sample(sim, sim.readouts(), generation=0)
    assert len(panel.samples) == 1
    assert math.isnan(panel.measures(sim)[0])


def test_a_file_has_cost_but_no_error(pendulum_xml):
    sim = Simulation(pendulum_xml)
    panel = AccuracyPanel(Gui(), sim)
    panel.refresh(sim, cost=1e-3, now=0.0)
    assert "×1\u202f000" in panel.text.content and panel.image is None
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


def test_the_chart_speaks_french_with_decimal_commas():
    """Title, axes and legend in French (integrator names as they are), timesteps in
    ms, the 0,5 % line, tick labels without a decimal point, no scene code name."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    from sandbox.bench_plot import LOCK, draw

    res = load_results("rolling_cylinder")
    assert res is not None
    live = Run("rolling_cylinder", "rk4", 2e-3, 0.0, error=1e-3, cpu_per_sim_s=5e-3)
    with LOCK:
        fig = draw(res, live)
        canvas = fig.canvas
        assert isinstance(canvas, FigureCanvasAgg)
        canvas.draw()
        ax = fig.axes[0]
        texts = [ax.get_title(), ax.get_xlabel(), ax.get_ylabel()]
        legend = ax.get_legend()
        assert legend is not None
        texts += [t.get_text() for t in legend.get_texts()]
        texts += [t.get_text() for t in ax.texts]
        ticks = [
            t.get_text()
            for axis in (ax.xaxis, ax.yaxis)
            for t in axis.get_ticklabels() + axis.get_ticklabels(minor=True)
        ]
    joined = "\n".join(texts)
    assert ax.get_title().startswith("Ce que coûte la précision\nCylindre")
    assert ax.get_xlabel() == "Coût CPU par seconde simulée [s]"
    assert ax.get_ylabel().startswith("Erreur relative sur accélération")
    assert "rk4" in joined and "front de Pareto" in joined
    assert "réglage par défaut (rk4, dt = 1 ms)" in joined
    assert "réglage actuel (rk4, dt = 2 ms)" in joined
    assert " 0,5 %" in joined
    assert "rolling_cylinder" not in joined and "cost" not in joined and "error" not in joined
    assert ticks and not any("." in t for t in ticks), ticks


def test_drift_words():
    from sandbox.bench_plot import drift_words

    assert drift_words("T (constant speed)") == "dérive de T"
    assert drift_words("|σG|") == "dérive de |σG|"
    assert drift_words("energy theorem (|P_int| / peak P_ext)") == (
        "écart au théorème de l'énergie cinétique"
    )
