"""« Précision et coût »: the session's cost, the reference test's error and drift for the
setting in force and the default, the chart with their two marks."""

from __future__ import annotations

import html
import math

import pytest

from sandbox import accuracy
from sandbox.bench import Run
from sandbox.physics.simulation import Simulation
from sandbox.scenes import SCENES, get_scene, resolve
from sandbox.web.client.text import GAP, number
from sandbox.web.panels.accuracy import NOT_LIVE, AccuracyPanel, chart_image, load_results


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

    def add_dropdown(self, label, options, **kwargs):
        handle = Handle()
        handle.options, handle.callbacks = options, []
        handle.on_update = handle.callbacks.append
        return handle


def live_cost() -> float:
    """A live session's measured cost [CPU s per simulated s] (the tests pass their own
    to refresh())."""
    return 2e-3


def test_shipped_benchmark_has_the_rotor_default_on_its_front():
    res = load_results("rotor")
    assert res is not None and res.default is not None and res.default.pareto
    assert load_results("no_such_scene") is None


def test_chart_image_is_rgb_with_its_two_marks():
    res = load_results("rotor")
    plain = chart_image(res, None)
    live = Run("rotor", "rk4", 1e-3, 0.0, error=1e-3, cpu_per_sim_s=5e-3)
    marked = chart_image(res, live)
    starred = chart_image(res, live, res.default)
    assert plain.ndim == 3 and plain.shape[2] == 3 and (plain != marked).any()

    def gold(image):  # the legend's star is gold too: the mark adds to it
        return int((image == (255, 215, 0)).all(axis=2).sum())

    assert gold(starred) > gold(marked) + 50


def _settle(panel: AccuracyPanel, sim: Simulation, cost: float = 2e-3) -> str:
    """Refresh until every measurement the panel asked for is in (at most 60 s)."""
    now = 100.0
    for _ in range(600):
        panel.refresh(sim, cost=cost, now=now)
        if "mesure en cours" not in panel.text.content:
            return html.unescape(panel.text.content)
        now += 0.5
        for future in list(panel._waiting.values()):
            future.result(timeout=60)
    raise AssertionError(panel.text.content)


def test_the_robot_axis_default_shows_the_error_the_benchmark_measured():
    """The default (speed servo) is not the reference test's motion (a torque step): the
    panel shows the torque step's error for its setting, as bench/results.md has it
    (1,1x10^-7 for RK4 at 1 ms), never an error against a closed form of another motion
    (it read 2,4 there)."""
    res = load_results("robot_axis")
    sim = Simulation(get_scene("robot_axis"))
    assert sim.values["profile"] != 0 and accuracy.in_force(sim) == accuracy.default(sim)
    saved = accuracy.saved(res, accuracy.in_force(sim))
    assert saved is not None and saved.error < 1e-6
    panel = AccuracyPanel(Gui(), sim, cost=live_cost)
    text = _settle(panel, sim)
    assert "◆ ★ Votre réglage, celui par défaut" in text
    assert f"| Erreur relative | {GAP}{number(saved.error, 2)} |" in text
    assert "Commande du moteur : couple constant" in text  # the test's conditions in words
    assert "kinetic" not in text and "integrated" not in text
    assert "écart au théorème de l'énergie cinétique intégré" in text


def test_star_and_diamond_coincide_when_the_setting_is_the_default():
    """Both marks come from the same run: the same pixel. Another timestep moves only
    the diamond, to the point the benchmark measured for it."""
    from sandbox.web.panels.accuracy import _place, chart_base

    res = load_results("rotor")
    sim = Simulation(get_scene("rotor"))
    mine, default = accuracy.in_force(sim), accuracy.default(sim)
    assert default is not None and mine.same(default)
    mapping = chart_base(res)[1]
    run = accuracy.saved(res, mine)
    assert run is not None and run.default
    panel = AccuracyPanel(Gui(), sim, cost=live_cost)
    _settle(panel, sim)
    assert panel._charted is not None and panel._charted[0] == panel._charted[1]
    sim.set_timestep(1e-3)  # on the benchmark's grid
    if panel._drawing is not None:
        panel._drawing.result(timeout=60)
    panel.refresh(sim, cost=2e-3, now=200.0)
    mine_mark, default_mark = panel._charted
    assert mine_mark != default_mark and mine_mark[1] == 1e-3
    other = accuracy.saved(res, accuracy.in_force(sim))
    assert _place(other, mapping) != _place(run, mapping)


def test_a_setting_off_the_grid_is_measured_the_way_the_benchmark_does():
    """dt = 2 ms is not on the rotor's grid: measured once on the reference test after
    the setting has stayed SETTLE seconds, by bench.run_one, then kept."""
    from sandbox.bench import run_one
    from sandbox.scenes import get_scene

    sim = Simulation(get_scene("rotor"))
    sim.set_timestep(2e-3)
    panel = AccuracyPanel(Gui(), sim, cost=live_cost)
    panel.refresh(sim, cost=2e-3, now=0.0)
    assert "mesure en cours" in panel.text.content and not panel._waiting  # typing...
    text = _settle(panel, sim)
    scene = get_scene("rotor")
    kept = accuracy.measured(scene, accuracy.in_force(sim))
    assert kept is not None and not kept.diverged
    again = run_one(scene, scene.accuracy, sim.integrator, 2e-3, scene.accuracy.duration)
    assert math.isclose(kept.error, again.error, rel_tol=1e-9, abs_tol=1e-15)
    assert "Implicite rapide, dt = 2 ms" in text and "Implicite rapide, dt = 10 ms" in text
    assert "< 10⁻¹²" in text  # the rotor at constant speed is exact: no round-off shown


def test_the_table_reads_the_setting_in_force():
    """The wheel balancer opens on its rigid bench at 10 ms (its reference test, the soft
    bench, defaults to 3 ms): the panel names 10 ms, never 3."""
    sim = Simulation(get_scene("wheel_balancer"))
    panel = AccuracyPanel(Gui(), sim, cost=live_cost)
    text = _settle(panel, sim)
    table = text.split("\n\n")[2]  # the test's table: the setting in force, never 3 ms
    assert "Runge-Kutta 4, dt = 10 ms" in table and "3 ms" not in table
    assert "Montage des paliers : paliers souples" in text
    # The default follows the parameters: the soft bench's own is said apart, in words.
    assert "aux valeurs de l'essai, il vaut 3 ms" in text


def test_a_timestep_per_crank_angle_is_measured_at_the_same_angle_on_the_test():
    """The compressor's timestep is a crank angle per step (ω dt = 0,178 rad): 500 µs at
    the page's 3000 tr/min, 100 µs at the test's 17 000 tr/min. The page's default is
    measured at the test's speed at that angle, 100 µs, where it is admissible (it was
    measured at 500 µs, 0,89 rad a step there: its energy-theorem gap 0,94 %, the star on
    an open circle); a timestep typed twice as long is measured twice as long there."""
    res = load_results("compressor")
    sim = Simulation(get_scene("compressor"))
    mine = accuracy.in_force(sim)
    assert mine.timestep == 5e-4 and accuracy.on_test(sim, mine).timestep == 1e-4
    assert res.default.timestep == 1e-4 and res.admissible(res.default)
    text = _settle(AccuracyPanel(Gui(), sim, cost=live_cost), sim)
    assert "Runge-Kutta 4, dt = 500 µs (100 µs à la vitesse de l'essai)" in text
    row = text.split("| Erreur relative |")[1].split("\n")[0]
    assert number(res.default.error, 2) in row  # the test's default, the saved one
    assert "au même angle par pas" in text and "fermeture des boucles au-delà" in text
    sim.set_timestep(1e-3)
    assert accuracy.on_test(sim, accuracy.in_force(sim)).timestep == 2e-4
    rotor = Simulation(get_scene("rotor"))  # a fixed default: measured as it is
    assert accuracy.on_test(rotor, accuracy.in_force(rotor)) == accuracy.in_force(rotor)
    panel = AccuracyPanel(Gui(), rotor, cost=live_cost)
    assert "à la vitesse de l'essai" not in _settle(panel, rotor)


@pytest.mark.parametrize("name", sorted(SCENES))
def test_every_scenes_default_is_admissible_on_its_own_test(name):
    """What « Précision et coût » shows for a scene as it opens: its default, as the test
    measures it, admissible (drift and closure within the limits) and within 0,5 % of the
    course; measured here when the saved benchmark did not run it."""
    sim = Simulation(resolve(name))
    scene = sim.scene
    if scene is None or scene.accuracy is None:
        pytest.skip("no reference test")
    res = load_results(name)
    setting = accuracy.on_test(sim, accuracy.in_force(sim))
    run = accuracy.saved(res, setting) or accuracy.measure(scene, setting)
    assert not run.diverged, run.detail
    assert res is not None and res.admissible(run), (setting, run.drift, run.constraint)
    assert run.error <= 5e-3, (setting, run.error)
    if scene.accuracy.same_angle:  # the same angle per step holds at the page's own speed
        import dataclasses

        from sandbox.bench import run_one

        acc = scene.accuracy
        slower = acc.values["speed_rpm"] / sim.values["speed_rpm"]  # the same revolutions
        at_page = dataclasses.replace(
            acc,
            values={**acc.values, "speed_rpm": sim.values["speed_rpm"]},
            duration=acc.duration * slower,
            settle=acc.settle * slower,
            rate=acc.rate / slower,
        )
        mine = accuracy.in_force(sim)
        page = run_one(get_scene(name), at_page, mine.integrator, mine.timestep, at_page.duration)
        assert res.admissible(page) and page.error <= 5e-3, (page.drift, page.constraint)


def test_a_file_has_cost_but_no_error(pendulum_xml):
    sim = Simulation(pendulum_xml)
    panel = AccuracyPanel(Gui(), sim, cost=live_cost)
    panel.refresh(sim, cost=1e-3, now=0.0)
    assert "×1\u202f000" in panel.text.content and panel.image is None
    assert "Erreur" not in panel.text.content


def test_the_chart_is_drawn_off_the_session_loop_and_shown_when_ready():
    """refresh() only submits the drawing; a later refresh shows the finished image."""
    sim = Simulation(get_scene("rotor"))
    panel = AccuracyPanel(Gui(), sim, cost=live_cost)
    blank = panel.image.image
    panel.refresh(sim, cost=2e-3, now=100.0)  # the default: saved by the benchmark
    assert panel._drawing is not None
    panel._drawing.result(timeout=60)
    assert panel.image.image is blank  # not yet picked up: no frame waited for it
    panel.refresh(sim, cost=2e-3, now=100.1)
    assert panel.image.image is not blank and panel.image.image.shape[2] == 3
    assert panel._drawing is None


def test_the_chart_base_is_drawn_once_per_scene_not_per_session():
    from sandbox.web.panels.accuracy import _BASES, chart_base

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

    from sandbox.bench.plot import LOCK, draw
    from sandbox.web.client import charts
    from sandbox.web.panels.accuracy import _BASES

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
    """Title, axes and legend in French (integrators in words), timesteps in ms, the
    0,5 % line, tick labels without a decimal point, no code name."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    from sandbox.bench.plot import LOCK, draw

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
    assert "Runge-Kutta 4" in joined and "front de Pareto" in joined
    assert "Implicite rapide" in joined and "Euler semi-implicite" in joined
    assert "réglage par défaut (Runge-Kutta 4, dt = 1 ms)" in joined
    assert "réglage actuel (Runge-Kutta 4, dt = 2 ms)" in joined
    for code in ("rk4", "implicitfast", "euler", "discrete"):
        assert code not in joined
    assert "0,5 % " in joined
    assert "rolling_cylinder" not in joined and "cost" not in joined and "error" not in joined
    assert ticks and not any("." in t for t in ticks), ticks


def test_drift_words():
    from sandbox.bench.plot import drift_words

    assert drift_words("T (constant speed)") == "dérive de T"
    assert drift_words("|σG|") == "dérive de |σG|"
    assert drift_words("energy theorem (|P_int| / peak P_ext)") == (
        "écart au théorème de l'énergie cinétique"
    )
    assert drift_words("T and |σ_G| (torque-free motion)") == "dérive de T et de |σG|"
    robot = "kinetic-energy theorem, integrated (|ΔE_c − ∫ΣP dt| / max E_c)"
    assert drift_words(robot) == "écart au théorème de l'énergie cinétique intégré"


def test_the_web_chart_is_readable_at_panel_size():
    """Every text of the panel's chart is at least 12 px once the page shows the image
    390 px wide (the control panel's width), and nothing is clipped: the image's outer
    frame is blank (a word cut by the edge would mark it)."""
    import numpy as np

    from sandbox.bench.plot import LOCK, draw
    from sandbox.web.panels.accuracy import CHART_DPI, chart_base

    shown_width = 390.0
    for scene in ("rotor", "robot_axis", "wheel_balancer", "inertia", "compressor"):
        res = load_results(scene)
        with LOCK:
            fig = draw(res, None, compact=True)
            fig.set_dpi(CHART_DPI)
            fig.canvas.draw()
            scale = shown_width / fig.bbox.width
            texts = [
                t
                for t in fig.findobj(lambda a: hasattr(a, "get_fontsize"))
                if getattr(t, "get_text", lambda: "")() and t.get_visible()
            ]
            assert len(texts) > 10
            for t in texts:
                px = t.get_fontsize() * CHART_DPI / 72.0 * scale
                assert px >= 12.0, (scene, t.get_text(), px)
        image = chart_base(res)[0]
        frame = np.concatenate(
            [
                image[:3].reshape(-1, 3),
                image[-3:].reshape(-1, 3),
                image[:, :3].reshape(-1, 3),
                image[:, -3:].reshape(-1, 3),
            ]
        )
        assert (frame == 255).all(), scene


def test_the_page_does_not_import_matplotlib_until_a_chart_is_drawn():
    """matplotlib and Pillow cost every server process 15 MB (30 browsers: +37 MB over the
    server): the page's modules load them only when a chart is drawn."""
    import subprocess
    import sys

    code = (
        "import sys, sandbox.cli, sandbox.web.serving.app, sandbox.web.serving.workers, "
        "sandbox.accuracy; "
        "print(sorted(m for m in ('matplotlib', 'PIL') if m in sys.modules))"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "[]", out.stdout


def test_the_star_is_a_five_pointed_star():
    """The mark's polygon test: its area against the closed form of a star polygon, its
    centre inside, the gaps between its points outside."""
    import numpy as np

    from sandbox.web.panels.accuracy import _star, inside

    radius = 100.0
    y, x = np.mgrid[-120:120:0.5, -120:120:0.5]
    mask = inside(x, y, _star(radius))
    area = mask.sum() * 0.25
    # ten triangles centre-outer-inner: 10 * 1/2 R r sin(36°), r = 0.42 R
    expected = 10 * 0.5 * radius * 0.42 * radius * math.sin(math.radians(36))
    assert area == pytest.approx(expected, rel=1e-2)
    assert inside(np.array(0.0), np.array(0.0), _star(radius))
    assert inside(np.array(0.0), np.array(-95.0), _star(radius))  # the upper point
    assert not inside(np.array(0.0), np.array(80.0), _star(radius))  # between two points


def test_a_precision_asked_applies_the_cheapest_measured_setting_that_reaches_it():
    """Issue 25's accuracy knob: "10⁻⁴" on the compressor applies what the benchmark found
    cheapest at that error (RK4 at 100 µs, 6,24×10⁻⁵ on the pilon), says its speed and how
    many students that speed allows; an error no setting reached is refused in French."""
    import sandbox.scenes  # noqa: F401

    sim = Simulation(get_scene("compressor"))
    applied: list[tuple[str, float]] = []
    panel = AccuracyPanel(Gui(), sim, choose=lambda i, dt: applied.append((i, dt)), cost=live_cost)
    assert panel.ask is not None and "10⁻⁴" in panel.ask.options
    panel._asked(object(), "10⁻⁴")
    assert applied == [("rk4", 1e-4)]
    assert panel.chosen is not None
    words = panel.chosen.content
    assert words.startswith(
        "Précision voulue 10⁻⁴ : Runge-Kutta 4, dt = 100 µs (erreur 6,24×10⁻⁵ sur « effet de"
    )
    assert "fois le temps réel" in words and "élèves" in words
    panel._asked(object(), "10⁻⁶")
    assert applied == [("rk4", 1e-4)]  # nothing applied
    assert panel.chosen.content.startswith("Aucun réglage mesuré n'atteint 10⁻⁶ (le meilleur : ")
    panel._asked(None, "1 %")  # the server's own change of the dropdown: nothing
    assert len(applied) == 1
    panel._asked(object(), "<img>")  # a crafted option
    assert len(applied) == 1 and panel.chosen.content == ""


def test_an_imposed_motion_says_it_is_exact_with_the_benchmark_s_error_and_cost():
    """Issue 35: « Précision et coût » of an imposed motion starts by what it is (exact at
    each instant), its error on the reference test and an evaluation's cost from
    bench/results.json, then says the table below is the free simulation's."""
    from sandbox.bench import load_results
    from sandbox.web.panels.accuracy import imposed_markdown

    result = load_results("compressor")
    assert result is not None and result.imposed is not None
    exact = result.imposed
    assert exact.motion == "imposed" and exact.error < 1e-12 and exact.evaluation_s > 0
    text = imposed_markdown(exact, 2e-3, key="Effet de pilon")
    assert text.startswith("**Mouvement imposé : calcul exact à chaque instant**")
    assert "erreur relative sur Effet de pilon : < 10⁻¹²" in text
    assert "µs de calcul par image" in text and "0,002 s de calcul par seconde simulée" in text
    assert text.endswith("Le tableau ci-dessous vaut pour le mouvement libre (simulé).")
    assert "." not in text.split("µs")[0].split(":")[-1]  # decimal comma, never a point


def test_a_replay_says_why_it_measures_nothing():
    """A replay measures no cost (it computes nothing): the folder says so in words and
    draws no empty chart."""
    sim = Simulation(get_scene("rotor"))
    panel = AccuracyPanel(Gui(), sim)
    assert panel.text.content == NOT_LIVE and panel.image is None
    assert [f.refresh for f in panel.pickable()] == [None]
