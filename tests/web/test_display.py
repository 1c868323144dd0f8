"""Motion at display rate: the drawn state between physics steps, "Ralenti" and "Pas"."""

from __future__ import annotations

import dataclasses
import math

import mujoco
import numpy as np
import pytest

from sandbox.errors import BadModel, BadOption, BadParameter, Diverged, UnknownParameter
from sandbox.physics.display import angle_between, main_joint
from sandbox.physics.picture import picture
from sandbox.physics.simulation import Simulation
from sandbox.scenes import get_scene, resolve
from sandbox.web.loop import (
    SPEEDS,
    Controller,
    divergence_message,
    french_message,
)
from sandbox.web.loop.requests import Advance, Pause, Play, Reset, Speed


class Clock:
    def __init__(self) -> None:
        self.now = 100.0

    def __call__(self) -> float:
        return self.now


def _rotor(speed_rpm: float = 6000.0, dt: float | None = None) -> Controller:
    sim = Simulation(get_scene("rotor"), values={"speed_rpm": speed_rpm}, timestep=dt)
    return Controller(sim, clock=Clock())


def _rotor_quat(ctl: Controller) -> np.ndarray:
    data = ctl.drawn().data
    body = mujoco.mj_name2id(ctl.sim.model, mujoco.mjtObj.mjOBJ_BODY, "rotor")
    return np.array(data.xquat[body])


def _turns_between_frames(ctl: Controller, frames: int, fps: float = 60.0) -> list[float]:
    """Angles [deg] the drawn rotor turns from one frame to the next."""
    angles, last = [], _rotor_quat(ctl)
    for _ in range(frames):
        ctl.clock.now += 1.0 / fps
        ctl.frame()
        quat = _rotor_quat(ctl)
        angles.append(math.degrees(angle_between(last, quat)))
        last = quat
    return angles


@pytest.mark.parametrize("dt", [1e-6, 1e-5, 1e-4, 1e-3, 3e-3, 1e-2, 2e-2, 5e-2, 0.1])
def test_a_6000_rpm_rotor_at_one_hundredth_turns_at_most_30_degrees_a_frame(dt):
    ctl = _rotor(6000.0, dt)
    ctl.submit(Speed(SPEEDS[0]))
    ctl.frame()
    angles = _turns_between_frames(ctl, 240)  # 4 s of wall time: 0.04 s simulated
    assert ctl.sim.data.time == pytest.approx(0.04, abs=dt + 1e-3)
    # 6000 rpm = 100 turns/s; ×0.01 at 60 frames/s: 6° a frame, every frame
    assert max(angles) <= 30.0
    assert min(angles) > 0.0, "the rotor must be seen turning on every frame"
    assert np.median(angles) == pytest.approx(6.0, rel=0.05)


def test_the_drawn_angle_is_the_exact_angle_at_the_display_time():
    ctl = _rotor(1500.0)  # dt = 10 ms: 90° a step
    ctl.submit(Speed(0.1))
    ctl.frame()
    for _ in range(37):
        ctl.clock.now += 1.0 / 60
        ctl.frame()
        shown = ctl.drawn().data
        w = 1500.0 * 2 * math.pi / 60
        assert shown.time == pytest.approx(ctl.display_time)
        assert ctl.sim.data.time <= ctl.display_time < ctl.sim.data.time + ctl.sim.timestep
        assert shown.qpos[0] == pytest.approx(w * ctl.display_time, rel=1e-9, abs=1e-9)


def test_the_display_never_changes_the_physics():
    """Two sessions on the same clock, one drawing every frame: bit-identical physics,
    identical to a simulation stepped alone the same number of times."""
    drawn, blind = _rotor(3000.0, 1e-3), _rotor(3000.0, 1e-3)
    for ctl in (drawn, blind):
        ctl.submit(Speed(0.37))
        ctl.frame()
    for _ in range(90):
        for ctl in (drawn, blind):
            ctl.clock.now += 1.0 / 60
            ctl.frame()
        drawn.drawn(("sup_R_x", "dyn_R_x"))  # what the arrows ask
    assert drawn.sim.data.time == blind.sim.data.time
    assert np.array_equal(drawn.sim.data.qpos, blind.sim.data.qpos)
    assert np.array_equal(drawn.sim.data.qvel, blind.sim.data.qvel)
    alone = Simulation(get_scene("rotor"), values={"speed_rpm": 3000.0}, timestep=1e-3)
    alone.step(round(drawn.sim.data.time / 1e-3))
    assert np.array_equal(alone.data.qpos, drawn.sim.data.qpos)


def test_forces_are_evaluated_at_the_drawn_state():
    ctl = _rotor(1500.0)
    ctl.submit(Advance(30.0, "deg"))
    ctl.frame()
    snap = ctl.drawn(("sup_R_x",))
    force = snap.support[0]
    physics = ctl.sim.snapshot(("sup_R_x",)).support[0]
    # the rotating bearing force has turned 30° about x from the physics state's
    assert ctl.sim.data.time == 0.0
    turned = math.degrees(math.atan2(force[2], force[1]) - math.atan2(physics[2], physics[1]))
    assert (turned + 180) % 360 - 180 == pytest.approx(30.0, abs=1e-6)


def test_a_step_of_an_angle_turns_the_main_joint_by_that_angle():
    ctl = _rotor(1500.0)  # one physics step is 90°
    assert main_joint(ctl.sim.model, ctl.sim.data) == 0
    before = ctl.drawn().data.qpos[0]
    for _ in range(13):
        ctl.submit(Advance("10", "deg"))
        assert ctl.frame() == []
    assert not ctl.playing
    after = ctl.drawn().data.qpos[0]
    assert math.degrees(after - before) == pytest.approx(130.0, abs=1e-6)
    assert ctl.sim.data.time == pytest.approx(0.01)  # one whole step taken, 40° ahead


def test_a_step_of_time_moves_the_display_time():
    ctl = _rotor(1500.0)
    ctl.submit(Advance(0.025, "s"))
    ctl.frame()
    assert ctl.display_time == pytest.approx(0.025)
    assert ctl.sim.data.time == pytest.approx(0.02)
    for _ in range(30):  # paused: the display stays where the step left it
        ctl.clock.now += 1 / 60
        ctl.frame()
    assert ctl.display_time == pytest.approx(0.025)
    ctl.submit(Play())
    ctl.frame()
    ctl.clock.now += 0.2
    ctl.frame()
    assert ctl.display_time == pytest.approx(0.225, abs=1e-9)


def test_reset_brings_the_display_back():
    ctl = _rotor(1500.0)
    ctl.submit(Advance(45, "deg"))
    ctl.frame()
    ctl.submit(Reset())
    ctl.frame()
    assert ctl.display_time == ctl.sim.data.time == 0.0


@pytest.mark.parametrize(
    "value, unit, needle",
    [
        (-5, "s", "Pas de −5 s refusé : choisissez entre 0 et 10 s."),
        ("abc", "deg", "Pas en angle : un nombre est attendu, reçu « abc »."),
        (1e9, "deg", "Pas de 1×10⁹° refusé : choisissez entre 0 et 3600°."),
        (1, "furlong", "Unité de pas « furlong » inconnue : s ou °."),
        (0.5, "s", "Pas de 0,5 s refusé : il demanderait 50000 pas de calcul"),
    ],
)
def test_bad_steps_are_refused_in_french(value, unit, needle):
    ctl = _rotor(1500.0, 1e-5)
    ctl.submit(Advance(value, unit))
    notices = ctl.frame()
    assert [n.level for n in notices] == ["error"] and needle in notices[0].text
    assert ctl.sim.data.time == 0.0 and ctl.display_time == 0.0


def test_an_angle_step_needs_something_turning():
    ctl = _rotor(0.0)
    ctl.submit(Advance(10, "deg"))
    (notice,) = ctl.frame()
    assert notice.text == "Aucune pièce ne tourne : choisissez un pas en temps (s)."


def test_slow_motion_down_to_one_hundredth():
    ctl = _rotor(1500.0)
    ctl.submit(Speed("0,01".replace(",", ".")))
    assert ctl.frame() == [] and ctl.speed == 0.01
    ctl.submit(Speed(0.005))
    (notice,) = ctl.frame()
    assert notice.text == "Vitesse ×0,005 refusée : choisissez entre ×0,01 et ×4."
    for _ in range(600):
        ctl.clock.now += 1 / 60
        ctl.frame()
    assert ctl.display_time == pytest.approx(0.1, abs=1e-9)


def test_refusals_name_parameters_in_french_words(monkeypatch):
    """A value is checked once, by its parameter: the refusal speaks English to the
    command line and French (its label, decimal comma, the page's unit) to the page."""
    scene = Simulation(get_scene("rotor")).scene
    assert scene is not None
    labelled = dataclasses.replace(
        scene,
        params=tuple(
            dataclasses.replace(p, label="Masse de correction m₁") if p.name == "mass1_g" else p
            for p in scene.params
        ),
    )
    sim = Simulation(get_scene("rotor"))
    monkeypatch.setattr(sim, "scene", labelled)
    with pytest.raises(BadParameter) as err:
        sim.check_value("mass1_g", 250.5)
    assert (
        err.value.french == "Masse de correction m₁ : 250,5 g refusé, choisissez entre 0 et 200 g."
    )
    assert str(err.value) == "parameter 'mass1_g' = 250.5 is out of range; allowed: 0 to 200 g"
    with pytest.raises(BadParameter) as err:
        sim.check_value("speed_rpm", -1)
    speed = labelled.params[0].words
    assert err.value.french == (
        f"{speed} : −1 tr/min refusé, choisissez entre 0 et 6\u202f000 tr/min."
    )
    with pytest.raises(BadParameter) as err:
        sim.check_value("angle1_deg", 200)
    assert str(err.value.french).endswith(": 200° refusé, choisissez entre −180 et 180°.")
    with pytest.raises(BadParameter) as err:
        sim.check_value("angle1_deg", "x" * 5000)  # a crafted message: both cut short
    assert len(str(err.value)) < 300 and len(str(err.value.french)) < 300
    with pytest.raises(UnknownParameter) as err:
        sim.check_value("nope", 1)
    assert str(err.value.french).startswith("Paramètre « nope » inconnu (parmi : ")
    assert "Masse de correction m₁" in str(err.value.french)
    assert dataclasses.replace(labelled.params[0], label="").words == "speed_rpm"


def test_the_divergence_message_is_french():
    text = divergence_message(Diverged(1.25, "bad acceleration (BADQACC)"))
    assert text.startswith("La simulation a divergé à t = 1,25 s (accélérations démesurées).")
    text = divergence_message(Diverged(0.5, "NaN or Inf in the state"))
    assert "(valeurs non numériques dans l'état)" in text and "NaN" not in text


def test_lower_layer_refusals_are_said_in_their_own_french_words():
    """No translation table: a refusal raised with French words shows them; one without
    (an unforeseen English detail) shows a general French sentence, never the English."""
    sim = Simulation(get_scene("compressor"))
    with pytest.raises(BadParameter) as err:
        sim.set_value("L", 0.01)  # shorter than the crank: refused while building
    text = french_message(err.value)
    assert text.startswith("La bielle (L = 0,01 m) doit être plus longue que la manivelle")
    with pytest.raises(BadOption) as err:
        sim.set_integrator("euler2")
    assert french_message(err.value).startswith("Intégrateur « euler2 » inconnu : choisissez")
    text = french_message(BadModel("cannot compile"))
    assert text == "Modification refusée : rien n'a changé." and "compile" not in text
    assert french_message(Diverged(1.25, "BADQACC")).startswith("La simulation a divergé")


# -- the "Affichage" folder ------------------------------------------------------------------
@pytest.fixture
def server():
    import viser
    from conftest import free_port

    srv = viser.ViserServer(host="127.0.0.1", port=free_port(), verbose=False)
    try:
        yield srv
    finally:
        srv.stop()


class Event:
    def __init__(self, target) -> None:
        self.client = object()
        self.target = target


class Camera:
    """viser's camera: setting the position translates the look-at point with it."""

    def __init__(self) -> None:
        self.look_at = np.zeros(3)
        self._position = np.array([0.0, -1.0, 0.5])

    @property
    def position(self) -> np.ndarray:
        return self._position

    @position.setter
    def position(self, value) -> None:
        value = np.asarray(value, dtype=float)
        self.look_at = self.look_at + value - self._position
        self._position = value


def _panel(server, scene: str, **values):
    from sandbox.web.panels.display import DisplayPanel
    from sandbox.web.view3d.renderer import SceneRenderer

    ctl = Controller(Simulation(resolve(scene), values=values), clock=Clock())
    point = (np.array([0.1, 0.0, 0.05]), "P")
    renderer = SceneRenderer(server.scene)
    renderer.draw(picture(ctl.drawn()))
    panel = DisplayPanel(
        server.gui,
        ctl,
        scene=server.scene,
        renderer=renderer,
        camera=Camera(),
        point=lambda: point,
    )
    return ctl, panel


def test_ralenti_and_pas_queue_requests(server):
    from sandbox.web.panels.display import UNIT_TIME

    ctl, panel = _panel(server, "rotor")
    assert panel.slow.options[-1] == "×0,01"
    panel.slow.value = "×0,01"
    panel._on_slow(Event(panel.slow))
    assert ctl.frame() == [] and ctl.speed == 0.01
    assert panel.step_request() == Advance(10.0, "deg")
    ctl.submit(panel.step_request())
    ctl.frame()
    assert ctl.display_time == pytest.approx(math.radians(10) / (1500 * math.pi / 30))
    panel.step_unit.value = UNIT_TIME
    panel.step_value.value = 0.002
    assert panel.step_request() == Advance(0.002, "s")
    ctl.submit(Speed(0.5))
    ctl.frame()
    panel.refresh()
    assert panel.slow.value == "×0,5"
    assert panel.follow is None  # the rotor stays in view


def test_the_camera_follows_the_rolling_cylinder(server):
    ctl, panel = _panel(server, "rolling_cylinder")
    assert panel.follow is not None and panel.camera is not None
    assert not panel.following and not panel.follow.value  # on request (its cost)
    assert ctl.playing  # the page opens rolling
    panel.following = True
    for _ in range(60):
        ctl.clock.now += 1 / 30
        ctl.frame()
    shown = ctl.drawn()
    panel.draw(picture(shown))
    body = panel.body
    assert np.asarray(panel.camera.position) - np.asarray(panel.camera.look_at) == pytest.approx(
        np.array([0.0, -1.0, 0.5])
    )
    assert np.asarray(panel.camera.look_at) == pytest.approx(np.asarray(shown.data.xpos[body]))
    assert shown.data.xpos[body][0] > 0.1  # it rolled away, the view with it


def test_the_masses_are_labelled_with_their_angle_and_p_is_drawn(server):
    ctl, panel = _panel(server, "rotor", mass1_g=30.0, angle1_deg=-90.0)
    panel.draw(picture(ctl.drawn()))
    assert panel.renderer is not None
    labels = panel.renderer.labels
    texts = sorted(text for text, _, _ in labels.values())
    assert texts == ["à -90°", "à 0°"] or all(" : " in t for t in texts), texts
    # they ride on the rotor's frame: no message a frame, and where the masses are
    rotor = mujoco.mj_name2id(ctl.sim.model, mujoco.mjtObj.mjOBJ_BODY, "rotor")
    data = ctl.drawn().data
    for g, (_, label, root) in labels.items():
        assert root == rotor and label.name.startswith(f"/model/body{rotor}/")
        local = np.asarray(label.position)
        world = data.xpos[rotor] + data.xmat[rotor].reshape(3, 3) @ local
        assert world == pytest.approx(data.geom_xpos[g], abs=1e-9)
    panel.refresh()
    assert panel._point is not None
    dot, label = panel._point
    assert dot.visible and np.asarray(dot.position) == pytest.approx([0.1, 0.0, 0.05])


def test_an_angle_step_turns_a_top_on_its_ball_joint():
    sim = Simulation(get_scene("heavy_gyroscope"))
    ctl = Controller(sim, clock=Clock())
    w = float(np.linalg.norm(sim.data.qvel[:3]))
    assert w > 1.0
    ctl.submit(Advance(90, "deg"))
    assert ctl.frame() == []
    assert ctl.display_time == pytest.approx(math.radians(90) / w)


def test_tables_read_the_drawn_state_so_d_in_b0_turns_smoothly_in_slow_motion():
    """At 1500 rpm and dt = 10 ms the physics turns 90° a step: {D} in B0 read on the
    physics state takes four values. Read on the drawn state (what the page's tables
    show), it turns with the drawing: a rotating vector of constant length whose angle
    is the drawn rotor's."""
    ctl = _rotor(1500.0)
    ctl.submit(Speed(SPEEDS[0]))
    ctl.frame()
    names = ("dyn_R_y", "dyn_R_z")
    physics, shown = set(), []
    for _ in range(120):  # 2 s of wall time at ×0.01: 20 ms simulated, two steps
        ctl.clock.now += 1.0 / 60.0
        ctl.frame()
        p = ctl.sim.readouts(names)
        physics.add((round(p["dyn_R_y"], 6), round(p["dyn_R_z"], 6)))
        s = ctl.shown_readouts(names)
        shown.append(complex(s["dyn_R_y"], s["dyn_R_z"]))
    assert len(physics) <= 3  # the physics state moved twice
    assert len({round(abs(z), 6) for z in shown}) == 1  # constant magnitude (steady speed)
    steps = [math.degrees(abs(np.angle(b / a))) for a, b in zip(shown, shown[1:], strict=False)]
    # 1500 rpm = 25 turns/s; ×0.01 at 60 frames/s: 1.5° a frame, every frame
    assert min(steps) > 0.5 and max(steps) < 3.0
    ctl.submit(Pause())
    ctl.frame()
    # paused between two steps: the tables keep what the picture shows
    still = ctl.shown_readouts(names)
    ctl.clock.now += 1.0
    ctl.frame()
    assert ctl.shown_readouts(names) == still
    drawn = ctl.drawn().data
    assert still == pytest.approx(ctl.sim.readouts(names, data=drawn))


@pytest.mark.parametrize(
    ("scene", "order"), [("compressor", "pilon_h2"), ("engine", "shaking_force_h2")]
)
def test_a_closed_loop_drawn_between_two_steps_stays_closed(scene, order):
    """Carried forward along its velocities, a slider-crank opens by 0.2 mm in 0.7 of a
    step: its forces then held the constraint's correction and the revolution simulated
    ahead from it read the second order 3 % off (the engine's first order 14 N instead of
    0). The drawn state is brought back onto the loop (display.close_loops)."""
    from sandbox.physics.display import DisplayState

    physics = Simulation(resolve(scene))
    physics.advance(0.5)
    expected = physics.readouts([order])[order]
    sim = Simulation(resolve(scene))  # another model: the revolutions' cache is not shared
    sim.advance(0.5)
    names = [order, "closure_error", "pilon"]
    drawn = sim.readouts(
        names, data=DisplayState(sim).data(sim.data.time + 0.7 * sim.timestep, names)
    )
    assert drawn["closure_error"] < 1e-9
    assert drawn[order] == pytest.approx(expected, rel=1e-3)
    if scene == "engine":
        first = sim.readouts(
            ["shaking_force_h1"],
            data=DisplayState(sim).data(sim.data.time + 0.7 * sim.timestep, names),
        )
        assert first["shaking_force_h1"] < 1e-3 * expected  # the four cancels the first order
