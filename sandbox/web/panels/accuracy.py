"""Folder "Précision et coût": what this session costs, and where the setting in force
and the scene's default sit on the scene's work-precision chart, with their error against
the course and their drift measured on the scene's reference test
(:mod:`sandbox.accuracy`: the benchmark's own numbers, never a live estimate)."""

from __future__ import annotations

import logging
import math
import threading
from collections.abc import Callable
from concurrent.futures import Future

import numpy as np
import viser

from sandbox import accuracy
from sandbox.accuracy import Setting
from sandbox.bench import Run, SceneResult, load_results
from sandbox.bench.plot import decimal, draw, drift_words, duration, integrator_words
from sandbox.cores import default_workers
from sandbox.physics.readonly import ReadOnlySimulation
from sandbox.physics.spec import Scene
from sandbox.physics.units import display_unit
from sandbox.web.client import charts
from sandbox.web.client.text import html_text, number, table_row, with_unit
from sandbox.web.panels.folder import Folder
from sandbox.web.panels.tables import cell, fmt

log = logging.getLogger(__name__)

SETTLE = 1.0
"""Seconds a setting must stay in force before it is measured on the reference test (a
timestep typed digit by digit is measured once, at its last digit)."""

ROUND_OFF = 1e-12
"""A relative error or drift at most this is the arithmetic's own: written as a bound
("< 10⁻¹²"), never as a number that looks measured."""

_BASES: dict[tuple[str, int], tuple[np.ndarray, tuple[float, ...]]] = {}
_BASES_LOCK = threading.Lock()
CHART_DPI = 100
"""Pixels per inch of the web chart (4.2 x 5 in: 420 x 500 px, shown about 390 px wide)."""


def chart_base(res: SceneResult) -> tuple[np.ndarray, tuple[float, ...]]:
    """The scene's chart without its two marks, drawn once per process, and the map
    from (log10 cost, log10 error) to pixels: ``(ax, bx, ay, by, x0, x1, y0, y1)``."""
    with charts.LOCK, _BASES_LOCK:  # this order only: charts.submit holds LOCK first
        key = (res.scene, len(res.runs))  # every session loads its own copy
        cached = _BASES.get(key)
        if cached is not None:
            return cached
        fig = draw(res, None, compact=True)  # a Figure on its own Agg canvas: no pyplot
        fig.set_dpi(CHART_DPI)
        # matplotlib on the first chart only: its import takes 0.5-1 s of every start-up
        from matplotlib.backends.backend_agg import FigureCanvasAgg

        canvas = fig.canvas
        assert isinstance(canvas, FigureCanvasAgg)
        canvas.draw()
        rgba = np.asarray(canvas.buffer_rgba())
        image = np.ascontiguousarray(rgba[..., :3])
        axes = fig.axes[0]
        height = fig.bbox.height
        (px0, py0), (px1, py1) = axes.transData.transform([(1.0, 1.0), (10.0, 10.0)])
        box = axes.get_window_extent()
        mapping = (
            float(px0),
            float(px1 - px0),
            float(height - py0),
            float(py0 - py1),
            float(box.x0),
            float(box.x1),
            float(height - box.y1),
            float(height - box.y0),
        )
        _BASES[key] = (image, mapping)
        return image, mapping


def _star(radius: float) -> np.ndarray:
    """The ten corners (x, y) [px] of a five-pointed star of outer ``radius`` around
    (0, 0), a point upwards (image rows grow downwards)."""
    angles = np.pi / 2 + np.arange(10) * np.pi / 5
    radii = np.where(np.arange(10) % 2 == 0, radius, 0.42 * radius)
    return np.column_stack([radii * np.cos(angles), -radii * np.sin(angles)])


def inside(x: np.ndarray, y: np.ndarray, corners: np.ndarray) -> np.ndarray:
    """Whether each point (x, y) lies inside the polygon ``corners`` (even-odd rule: a
    ray towards +x crosses its edges an odd number of times). Plain numpy: the page's
    processes never import matplotlib for two marks (15 MB each)."""
    inside_ = np.zeros(np.broadcast(x, y).shape, dtype=bool)
    for (x0, y0), (x1, y1) in zip(corners, np.roll(corners, -1, axis=0), strict=True):
        if y0 == y1:
            continue
        spans = (y0 > y) != (y1 > y)
        crossing = x0 + (y - y0) * (x1 - x0) / (y1 - y0)
        inside_ ^= spans & (x < crossing)
    return inside_


def _place(run: Run | None, mapping: tuple[float, ...]) -> tuple[float, float] | None:
    """Pixel of ``run``'s (cost, error) on the chart, on its edge when off it."""
    if run is None or run.diverged:
        return None
    cost, error = run.cpu_per_sim_s, run.error
    if not (math.isfinite(cost) and cost > 0 and math.isfinite(error)):
        return None
    ax, bx, ay, by, x0, x1, y0, y1 = mapping
    px = ax + bx * math.log10(cost)
    py = ay + by * math.log10(max(error, 1e-16))
    return min(max(px, x0), x1), min(max(py, y0), y1)


def chart_image(res: SceneResult, mine: Run | None, default: Run | None = None) -> np.ndarray:
    """The work-precision chart as an RGB array with the scene's default (a gold star)
    and the setting in force (a black diamond, drawn over the star: when they are the
    same setting the diamond sits in the star's middle) where their runs on the reference
    test put them; the base is drawn once, the marks in numpy."""
    base, mapping = chart_base(res)
    image = base.copy()
    for at, reach, star in (
        (_place(default, mapping), 13, True),
        (_place(mine, mapping), 7, False),
    ):
        if at is None:
            continue
        x, y = at  # only the pixels around the mark are tested
        top, left = max(0, int(y) - reach), max(0, int(x) - reach)
        rows, cols = np.mgrid[top : int(y) + reach + 1, left : int(x) + reach + 1]
        patch = image[top : top + rows.shape[0], left : left + rows.shape[1]]
        rows, cols = (
            rows[: patch.shape[0], : patch.shape[1]],
            cols[: patch.shape[0], : patch.shape[1]],
        )
        if star:  # the default: a gold star edged in black
            for radius, colour in ((12.0, (0, 0, 0)), (10.0, (255, 215, 0))):
                patch[inside(cols - x, rows - y, _star(radius))] = colour
        else:  # the setting in force: a black diamond, over the star
            patch[np.abs(rows - y) + np.abs(cols - x) <= 6] = 0
    return image


def relative(value: float) -> str:
    """A relative error or drift as the panel writes it: two digits, a bound at or below
    :data:`ROUND_OFF`, "—" when unknown."""
    if not math.isfinite(value):
        return "—"
    if value <= ROUND_OFF:
        return "< 10⁻¹²"
    return number(value, 2)


def conditions(scene: Scene) -> str:
    """The reference test in French: its parameter values and the time simulated, e.g.
    "Vitesse du vilebrequin ω = 17 000 tr/min ; 0,04 s simulée depuis le lancement"."""
    acc = scene.accuracy
    if acc is None:
        return ""
    parts = []
    for name, value in acc.values.items():
        param = next((p for p in scene.params if p.name == name), None)
        if param is None:
            continue
        words = param.label or name
        if param.choices and 0 <= int(value) < len(param.choices):
            parts.append(f"{words} : {param.choices[int(value)].lower()}")
        else:
            parts.append(f"{words} = {with_unit(number(value), display_unit(param.unit))}")
    plural = "s" if acc.duration >= 2 else ""
    parts.append(f"{with_unit(number(acc.duration), 's')} simulée{plural} depuis le lancement")
    return " ; ".join(parts)


TOLERANCES: dict[str, float] = {
    "1 %": 1e-2,
    "0,1 %": 1e-3,
    "10⁻⁴": 1e-4,
    "10⁻⁵": 1e-5,
    "10⁻⁶": 1e-6,
}
"""The precisions a user may ask for (relative error on the scene's key quantity)."""

ASK = "Précision voulue"
KEEP = "Réglage actuel"


def chosen_words(run: Run, tolerance: str, key: str) -> str:
    """What a precision chose, in French: the setting, its error, its speed and how many
    students' simulations the laptop's cores could step at that speed."""
    cores = default_workers()
    students = int(cores * run.realtime_factor) if math.isfinite(run.realtime_factor) else 0
    return (
        f"{ASK} {tolerance} : {integrator_words(run.integrator)}, dt = "
        f"{duration(run.timestep)} (erreur {decimal(run.error)} sur « {key} » à l'essai de "
        f"référence ; {number(run.realtime_factor, 3)} fois le temps réel : le calcul seul de "
        f"{cores} cœur{'s' if cores > 1 else ''} suivrait environ {students} élèves)."
    )


FOLDER = "Précision et coût"
"""The folder's title (in « Panneau affiché »)."""


NOT_LIVE = (
    "Une relecture rejoue des états enregistrés : elle ne calcule rien, donc n'a ni "
    "coût de calcul ni erreur à mesurer. Ouvrez la scène en direct (`sandbox serve`) pour "
    "comparer intégrateurs et pas de temps."
)
"""What the folder says where no cost is measured (a replay)."""


class AccuracyPanel:
    """What accuracy costs in one session.

    The table gives this session's CPU cost (measured here) and, for the setting in force
    and the scene's default for the parameters, their error and drift on the scene's
    reference test; the chart puts both on the benchmark's grid (star: default, diamond:
    in force; the same point when they are the same setting).

    Args:
        gui: A viser ``GuiApi``.
        sim: The session's simulation.
    """

    def __init__(
        self,
        gui: viser.GuiApi,
        sim: ReadOnlySimulation,
        *,
        choose: Callable[[str, float], None] | None = None,
        cost: Callable[[], float] | None = None,
    ) -> None:
        self.sim = sim
        self.cost = cost
        scene = sim.scene
        self.scene = scene if scene is not None and scene.accuracy is not None else None
        self.results = load_results(scene.name) if scene is not None else None
        self._since: tuple[Setting, float] | None = None
        self._waiting: dict[Setting, Future[Run]] = {}
        self._charted: tuple | None = None
        self._drawing: Future[np.ndarray] | None = None
        self.key_words = self.invariant_words = self.test_words = ""
        if self.scene is not None and self.scene.accuracy is not None:
            acc = self.scene.accuracy
            labels = {i.name: i.label for i in sim.readout_infos()}
            key = labels.get(acc.key) or acc.key
            self.key_words = key[0].lower() + key[1:] if key[1:2].islower() else key
            self.invariant_words = drift_words(acc.invariant)
            self.test_words = conditions(self.scene)
        self.choose = choose
        self.ask: viser.GuiDropdownHandle[str] | None = None
        self.chosen: viser.GuiMarkdownHandle | None = None
        with gui.add_folder(FOLDER) as self.folder:
            if choose is not None and self.results is not None:
                self.ask = gui.add_dropdown(
                    ASK,
                    (KEEP, *TOLERANCES),
                    initial_value=KEEP,
                    hint="L'erreur relative acceptée sur la grandeur clé : le réglage le "
                    "moins coûteux mesuré par le banc d'essai qui l'atteint est appliqué",
                )
                self.chosen = gui.add_markdown("")
                self.ask.on_update(lambda event: self._asked(event.client, event.target.value))
            self.text = gui.add_markdown("" if cost is not None else NOT_LIVE)
            self.image = None
            if self.results is not None and self.scene is not None and cost is not None:
                blank = np.full((8, 12, 3), 255, dtype=np.uint8)  # drawn at the first refresh
                self.image = gui.add_image(blank, label="Erreur relative et coût CPU", format="png")

    def _asked(self, client: object, choice: object) -> None:
        """A precision asked for: the cheapest measured setting reaching it, applied."""
        if client is None or self.choose is None or self.chosen is None:
            return
        if not isinstance(choice, str) or choice not in TOLERANCES or self.results is None:
            self.chosen.content = ""
            return
        found = accuracy.cheapest(self.results, TOLERANCES[choice])
        if found is None:
            best = accuracy.most_accurate(self.results)
            self.chosen.content = f"Aucun réglage mesuré n'atteint {choice}" + (
                f" (le meilleur : {decimal(best.error)}, {integrator_words(best.integrator)} à "
                f"dt = {duration(best.timestep)})."
                if best is not None
                else "."
            )
            return
        self.choose(found.integrator, found.timestep)
        self.chosen.content = chosen_words(found, choice, self.key_words or "la grandeur clé")

    def run(self, setting: Setting, now: float, *, at_once: bool = False) -> Run | None:
        """``setting``'s run on the reference test: saved by the benchmark, measured by
        this process, or None while it is being measured (asked for once the setting has
        been in force :data:`SETTLE` seconds, or ``at_once``)."""
        if self.scene is None:
            return None
        found = accuracy.saved(self.results, setting) or accuracy.measured(self.scene, setting)
        if found is not None:
            self._waiting.pop(setting, None)
            return found
        waiting = self._waiting.get(setting)
        if waiting is not None:
            if not waiting.done():
                return None
            del self._waiting[setting]
            try:
                return waiting.result()
            except Exception:  # a measurement is a bonus: the table says it is missing
                log.exception("measuring %s on the reference test failed", setting)
                return None
        if not at_once:
            if self._since is None or not self._since[0].same(setting):
                self._since = (setting, now)
            if now - self._since[1] < SETTLE:
                return None
        self._waiting[setting] = accuracy.submit(self.scene, setting)
        return None

    def pickable(self) -> list[Folder]:
        """Its folder of « Panneau affiché »: it runs the simulation's reference test, so
        a challenge closes it; refreshed only where the session's cost is measured (a
        replay measures none: its folder keeps the benchmark's grid)."""
        cost = self.cost
        if cost is None:
            return [Folder(FOLDER, self.folder)]
        return [Folder(FOLDER, self.folder, lambda f: self.refresh(self.sim, cost(), f.now))]

    def refresh(self, sim: ReadOnlySimulation, cost: float, now: float) -> None:
        """Rewrite the table; redraw the chart when a mark moves."""
        mine = accuracy.in_force(sim)
        default = accuracy.default(sim)
        same = default is not None and default.same(mine)
        # as the reference test measures them (the same angle per step where the default
        # is one: the page's default is then the test's)
        mine_test = accuracy.on_test(sim, mine)
        default_test = accuracy.on_test(sim, default) if default is not None else None
        mine_run = self.run(mine_test, now, at_once=same) if self.scene is not None else None
        default_run = None
        if default_test is not None and self.scene is not None:
            default_run = mine_run if same else self.run(default_test, now, at_once=True)
        at_test = accuracy.test_default(self.scene) if self.scene is not None else None
        if at_test is not None and default_test is not None and at_test.same(default_test):
            at_test = None
        at_test_run = self.run(at_test, now, at_once=True) if at_test is not None else None
        imposed = sim.motion == "imposed"
        text = accuracy_markdown(
            mine,
            math.nan if imposed else cost,  # this session's cost is the imposed motion's
            title=FREE_TITLE if imposed else SESSION_TITLE,
            default=default if self.scene is not None else None,
            mine_run=mine_run,
            default_run=default_run,
            key=self.key_words,
            invariant=self.invariant_words,
            test=self.test_words,
            result=self.results,
            chart=self.image is not None,
            at_test=at_test,
            at_test_run=at_test_run,
            tested=(mine_test, default_test),
        )
        if imposed:
            exact = self.results.imposed if self.results is not None else None
            text = imposed_markdown(exact, cost, key=self.key_words) + "\n\n" + text
        if self.text.content != text:
            self.text.content = text
        self._chart(mine_run, default_run)

    def _chart(self, mine: Run | None, default: Run | None) -> None:
        if self.image is None or self.results is None:
            return
        if self._drawing is not None and self._drawing.done():
            drawing, self._drawing = self._drawing, None
            try:
                self.image.image = drawing.result()
            except Exception:  # a chart is a bonus: the table stays
                log.exception("work-precision chart failed")
        if self._drawing is not None:
            return
        marks = (_mark(mine), _mark(default))
        if marks != self._charted:
            self._charted = marks
            # Drawn by the chart thread: the frames of every session go on meanwhile.
            self._drawing = charts.submit(chart_image, self.results, mine, default)


def _mark(run: Run | None) -> tuple | None:
    if run is None:
        return None
    return (run.integrator, run.timestep, run.cpu_per_sim_s, run.error, run.diverged)


def _setting_cell(setting: Setting, tested: Setting | None = None) -> str:
    """A setting in words, and the timestep the test measures it at when another (the
    same angle per step at the test's speed)."""
    text = f"{integrator_words(setting.integrator)}, dt = {duration(setting.timestep)}"
    if tested is not None and not tested.same(setting):
        text += f" ({duration(tested.timestep)} à la vitesse de l'essai)"
    return html_text(text)


def _measured(run: Run | None, what: str) -> str:
    """One measured cell: the value, "mesure en cours…", or why there is none."""
    if run is None:
        return "mesure en cours…"
    if run.diverged:
        return "diverge"
    if what == "error":
        return relative(run.error)
    if what == "drift":
        return relative(run.drift)
    return with_unit(fmt(run.cpu_per_sim_s, digits=2), "s")


def imposed_markdown(exact: Run | None, cost: float, *, key: str = "") -> str:
    """What « Précision et coût » says first while the motion is imposed: computed
    exactly at each instant, its error on the reference test and what an evaluation
    costs (the benchmark's), and that the table below is the free simulation's."""
    text = (
        "**Mouvement imposé : calcul exact à chaque instant** (équations de fermeture et "
        "dynamique inverse : ni intégrateur ni pas de temps)."
    )
    if exact is not None and math.isfinite(exact.error):
        text += (
            f" Sur l'essai de référence, erreur relative sur {cell(key)} : {relative(exact.error)}"
        )
        if math.isfinite(exact.evaluation_s):
            text += f", {fmt(exact.evaluation_s * 1e6, digits=2)} µs de calcul par image"
        text += "."
    if math.isfinite(cost) and cost > 0:
        text += f" Cette session : {fmt(cost, digits=3)} s de calcul par seconde simulée."
    return text + " Le tableau ci-dessous vaut pour le mouvement libre (simulé)."


SESSION_TITLE = "Cette session"
FREE_TITLE = "En mouvement libre (simulé)"
"""The first table's title: the session's setting, or while the motion is imposed the
free simulation's setting, should the session switch to it."""


def accuracy_markdown(
    setting: Setting,
    cost: float,
    *,
    title: str = SESSION_TITLE,
    default: Setting | None = None,
    mine_run: Run | None = None,
    default_run: Run | None = None,
    key: str = "",
    invariant: str = "",
    test: str = "",
    result: SceneResult | None = None,
    chart: bool = False,
    at_test: Setting | None = None,
    at_test_run: Run | None = None,
    tested: tuple[Setting | None, Setting | None] = (None, None),
) -> str:
    """The table of "Précision et coût", in French with decimal commas.

    Args:
        setting: The integrator and timestep in force.
        cost: This session's CPU seconds per simulated second (NaN: not measured, "—").
        title: The first table's title (:data:`SESSION_TITLE`, :data:`FREE_TITLE`).
        default: The scene's default setting for the parameters (None: no reference
            test, only the cost is shown).
        mine_run, default_run: Their runs on the reference test (None: being measured).
        key: The key quantity in words (its label).
        invariant: What the drift measures (:func:`~sandbox.bench.plot.drift_words`).
        test: The reference test in words (:func:`conditions`).
        result: The saved benchmark (for the chart's legend notes).
        chart: Add the sentences that explain the chart.
        at_test: The scene's default at the test's own parameter values, when the
            default follows the parameters and differs there (None otherwise), with
            ``at_test_run`` its run: a sentence says what it gives.
        tested: ``setting`` and ``default`` as the test measures them, when it does at
            the same angle per step (:func:`sandbox.accuracy.on_test`; None: as they are).
    """
    rtf = 1.0 / cost if cost > 0 else math.nan
    factor = fmt(round(rtf)) if rtf >= 10 else fmt(rtf, digits=2)
    lines = [
        f"| {title} | |",
        "|:--|--:|",
        table_row("Intégrateur", html_text(integrator_words(setting.integrator))),
        table_row("Pas de temps dt", html_text(duration(setting.timestep))),
    ]
    if math.isfinite(cost):  # (not the free simulation's while the motion is imposed)
        lines += [
            table_row("Coût CPU par seconde simulée", f"{fmt(cost, digits=3)} s"),
            table_row("Facteur temps réel possible", f"×{factor}"),
        ]
    if default is None:
        return "\n".join(lines)
    same = default.same(setting)
    drift_label = cell(invariant[:1].upper() + invariant[1:]) + " (relatif)"
    lines += [
        "",
        f"**Essai de référence** ({cell(test)}) : erreur relative sur {cell(key)} par "
        "rapport au cours, et " + cell(invariant) + ".",
        "",
    ]
    if same:
        runs = [("◆ ★ Votre réglage, celui par défaut", setting, mine_run)]
    else:
        runs = [("◆ Votre réglage", setting, mine_run), ("★ Par défaut", default, default_run)]
    scaled = dict(zip((id(setting), id(default)), tested, strict=True))
    lines += [
        table_row("", *(title for title, _, _ in runs)),
        "|:--|" + "--:|" * len(runs),
        table_row("Réglage", *(_setting_cell(s, scaled.get(id(s))) for _, s, _ in runs)),
        table_row("Erreur relative", *(_measured(r, "error") for _, _, r in runs)),
        table_row(drift_label, *(_measured(r, "drift") for _, _, r in runs)),
        table_row(
            "Coût CPU du calcul seul, par seconde simulée",
            *(_measured(r, "cost") for _, _, r in runs),
        ),
    ]
    text = "\n".join(lines)
    pairs = zip(tested, (setting, default), strict=True)
    if any(t is not None and s is not None and not t.same(s) for t, s in pairs):
        text += (
            "\n\nLe pas de temps par défaut est un angle du vilebrequin par pas (l'erreur ne "
            "dépend que de ω·dt) : l'essai mesure chaque réglage au même angle par pas, à sa "
            "propre vitesse."
        )
    if at_test is not None:
        text += (
            f"\n\nLe pas par défaut suit les paramètres : aux valeurs de l'essai, il vaut "
            f"{html_text(duration(at_test.timestep))} (erreur relative "
            f"{_measured(at_test_run, 'error')}, {cell(invariant)} "
            f"{_measured(at_test_run, 'drift')})."
        )
    if chart:
        text += (
            "\n\nSur le graphique : une courbe par intégrateur, du plus petit pas (à droite, "
            "le plus cher) au plus grand ; la bande grise relie les meilleurs compromis. "
            "L'étoile marque le réglage par défaut, le losange le vôtre (au milieu de "
            "l'étoile quand c'est le même)."
        )
        if result is not None and any(
            not r.diverged and math.isfinite(r.error) and not result.admissible(r)
            for r in result.runs
        ):
            limits = f"{cell(invariant)} au-delà de {relative(result.drift_tol)}"
            if math.isfinite(result.constraint_tol):
                limits += (
                    f", ou fermeture des boucles au-delà de "
                    f"{with_unit(fmt(result.constraint_tol), 'm')}"
                )
            text += f" Un cercle vide est un réglage non admissible : {limits}."
    return text
