"""The page's "Étude paramétrique" and "Tracé X–Y" folders, driven through the real
view and session loop on a fake viser client (tests/robustness/test_hostile_web.py):
the form makes the study the CLI would, refusals are French, dots and the closed form
reach the chart, files keep the contracts."""

from __future__ import annotations

import csv
import io
from pathlib import Path

import numpy as np
import pytest
from conftest import wait_for

from sandbox.sweep import COLUMNS_AFTER, Measure, Study, Vary
from sandbox.web.loop import Refused
from sandbox.web.loop.secret import Secret
from sandbox.web.panels.study import FOLDER, RUN, StudyPanel
from sandbox.web.panels.xy import FOLDER as XY_FOLDER
from tests.robustness.test_hostile_web import Page


@pytest.fixture
def page(tmp_path: Path) -> Page:
    return Page("rotor", tmp_path)


def _panel(page: Page) -> StudyPanel:
    panel = page.view.study
    assert panel is not None
    return panel


def test_the_preset_is_the_study_the_command_line_runs(page):
    """The rotor's preset fills the form; the study it makes is `sandbox sweep rotor
    --vary speed_rpm=0:6000:13 --measure bearing_A --duration 0.1`, the other
    parameters at the page's current values."""
    page.send(page.find("slider", "Masselotte de défaut [g]"), 40.0)
    page.tick(0.2)
    study = _panel(page).study()
    assert study.varies == (Vary("speed_rpm", 0.0, 6000.0, 13),)
    assert study.measure == Measure("bearing_A", "final") and study.duration == 0.1
    fixed = dict(study.fixed)
    assert "speed_rpm" not in fixed and float(fixed["defect_mass_g"]) == 40.0


@pytest.mark.parametrize(
    ("field", "value", "words"),
    [
        ("À", 7000.0, "choisissez entre 0 et 6"),
        ("Nombre de points", 500, "Nombre de points : choisissez entre 2 et 50."),
        ("Nombre de points", 2.5, "Nombre de points"),
        ("Mesure à partir de [s]", 5.0, "La mesure doit commencer avant la fin"),
        ("Durée de chaque simulation [s]", "abc", "un nombre est attendu"),
        ("Durée de chaque simulation [s]", 1e9, "entre 0 et 60 s"),
    ],
)
def test_bad_input_is_one_french_refusal(page, field, value, words):
    page.find("number", field).value = value
    with pytest.raises(Refused, match=words):
        _panel(page).study()
    page.show(FOLDER)
    page.send(page.find("button", RUN), True)
    assert page.client.toasts[-1][0] == "Étude paramétrique"
    assert words.split(" :")[0] in page.client.toasts[-1][1]
    assert _panel(page).job is None


def test_a_second_parameter_must_differ(page):
    panel = _panel(page)
    panel.family.value = panel.vary.value
    with pytest.raises(Refused, match="doit différer du premier"):
        panel.study()


@pytest.mark.solo  # waits on a lowest-priority worker, which a busy machine starves by design
def test_a_study_runs_and_its_dots_and_closed_form_reach_the_chart(page):
    page.show(FOLDER)
    panel = _panel(page)
    panel.count.value = 4
    page.send(page.find("button", RUN), True)
    job = panel.job
    assert job is not None and job.total == 4
    assert wait_for(lambda: job.finished, timeout=60)
    page.tick(0.3)
    assert "Étude terminée : 4 simulations" in panel.status.content
    assert panel.button.label == RUN and not panel.progress.visible
    assert panel.chart is not None
    x, dots, course = panel.chart.chart.data
    assert x.tolist() == [0.0, 2000.0, 4000.0, 6000.0]
    assert np.allclose(dots, course, rtol=1e-6) and dots[-1] > 800  # ω² (course 7.2)
    got: dict[str, bytes] = {}
    page.client.send_file_download = lambda name, data, **_: got.__setitem__(name, data)
    page.send(page.find("button", "Télécharger l'étude (CSV)"), True)
    page.send(page.find("button", "Télécharger l'étude (PNG)"), True)
    (csv_name,) = [n for n in got if n.endswith(".csv")]
    rows = list(csv.reader(io.StringIO(got[csv_name].decode())))
    assert rows[0] == ["speed_rpm", *COLUMNS_AFTER] and len(rows) == 5
    (png,) = [d for n, d in got.items() if n.endswith(".png")]
    assert png[:4] == b"\x89PNG"


def test_no_study_during_a_challenge(page):
    page.ctl.secret = Secret.__new__(Secret)  # any secret: the page refuses
    page.show(FOLDER)
    page.send(page.find("button", RUN), True)
    assert "défi" in page.client.toasts[-1][1] and _panel(page).job is None


@pytest.mark.solo  # waits on a lowest-priority worker, which a busy machine starves by design
def test_the_compressor_plots_against_r_over_l(tmp_path):
    """The preset's horizontal axis is R/L while L varies."""
    page = Page("compressor", tmp_path)
    panel = _panel(page)
    panel.count.value = 3
    page.show(FOLDER)
    page.send(page.find("button", RUN), True)
    job = panel.job
    assert job is not None and panel.chart is not None
    title, x_of = panel.chart.x_of(job)
    assert title == "Rapport R/L"
    assert x_of({"R": 0.015, "L": job.points[0]["L"]}) == pytest.approx(0.015 / 0.04)
    assert wait_for(lambda: job.finished, timeout=60)
    page.tick(0.3)
    x = panel.chart.chart.data[0]
    assert x.tolist() == sorted(0.015 / L for L in (0.04, 0.12, 0.2))


def test_the_xy_folder_samples_only_while_shown(page):
    """Counted: no readout is sampled between frames until the X–Y folder is shown,
    and the chart gets points once it is."""
    page.tick(0.5)
    assert page.ctl.probe.since(0) == (0, [])
    page.show(XY_FOLDER)
    page.tick(1.0)
    assert len(page.ctl.probe.since(0)[1]) > 100
    xy = page.view.xy
    assert xy is not None and len(xy.data) > 100
    assert "pente" in xy.reading.content
    page.show("Courbes")
    page.tick(0.1)
    seq = page.ctl.probe.since(0)[0]
    page.tick(0.5)
    assert page.ctl.probe.since(seq)[1] == []


def test_an_xy_preset_that_changes_parameters_restarts_the_run(page):
    page.show(XY_FOLDER)
    page.send(page.find("dropdown", "Tracé proposé"), "Efforts des paliers selon ω, au démarrage")
    page.tick(0.5)
    assert page.ctl.sim.values["ramp_s"] == 2.0 and page.ctl.sim.values["speed_rpm"] == 6000.0
    assert page.ctl.generation == 1
    _ = Study  # the contract type the page builds


@pytest.mark.solo  # waits on a lowest-priority worker, which a busy machine starves by design
def test_a_period_is_charted_in_seconds(tmp_path):
    """The inertia lab's flip period: a time, whatever the angle's unit, titled as one."""
    page = Page("inertia", tmp_path)
    panel = _panel(page)
    panel.count.value = 2
    page.show(FOLDER)
    page.send(page.find("button", RUN), True)
    job = panel.job
    assert job is not None and wait_for(lambda: job.finished, timeout=60)
    page.tick(0.3)
    charts = [h for h in page.client.gui.handles if h.kind == "uplot" and h.visible]
    titles = [h.label for h in charts]
    assert "Période de : Angle entre ω et l'axe de lancement [s]" in titles
    assert panel.chart is not None
    _, dots, course = panel.chart.chart.data
    assert np.allclose(dots, course, rtol=1e-5) and 3 < dots.min() < dots.max() < 6  # s


def test_the_bounds_show_the_decimals_of_the_parameter_they_vary(tmp_path):
    """The compressor's preset varies the rod length L from 0,04 to 0,2 m, but the bound
    fields were made for a speed (step 50 tr/min): they showed « De 0 » « À 0 ». They
    take the decimals of the parameter's step (0,0005 m: four)."""
    page = Page("compressor", tmp_path)
    panel = _panel(page)
    assert (panel.start.value, panel.stop.value) == (0.04, 0.2)
    assert panel.start.step == panel.stop.step == 0.0005
    assert panel.start.precision == panel.stop.precision == 4
    # another parameter picked by hand: its own step and decimals
    page.show(FOLDER)
    page.send(page.find("dropdown", "Paramètre varié"), "Vitesse du vilebrequin ω [tr/min]")
    page.tick(0.3)
    assert panel.start.step == 50.0 and panel.start.precision == 0
