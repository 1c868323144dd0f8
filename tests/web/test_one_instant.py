"""One screen, one instant, one name (issue 36): what one frame shows in a browser — the
scene's table, the projector overlay, the 3D labels, « Isoler un solide » — is read from
one state and written by one presentation; the follow summary writes it the same way.

A real viser server and session per scene, its frames run by the test with a fake clock
(as tests/web/test_frame_cost.py does).
"""

from __future__ import annotations

import html
import math
import re

import pytest
from conftest import wait_for
from test_frame_cost import Clock, served  # noqa: F401  (the fixture)

from sandbox.physics.simulation import Simulation
from sandbox.scenes import SCENES, get_scene, resolve
from sandbox.web.loop import frame as frame_module
from sandbox.web.loop.requests import Pause, Play, Speed
from sandbox.web.panels.projector import held_line
from sandbox.web.views.browser import ALL_FOLDERS
from sandbox.written import time_words, written

SPAN = re.compile(r'<span data-readout="([^"]+)" data-value="([^"]+)">([^<]*)</span>')


def _panel_frame(session) -> frame_module.Frame:
    """Run frames until one brings readouts and a picture (a panel refresh while the
    mechanism moves), every folder shown; returns that frame, its panels refreshed."""
    session.view.show_folder(ALL_FOLDERS)
    ctl = session.controller
    clock = Clock()
    ctl.clock = clock
    ctl.submit(Play())
    seen: list[frame_module.Frame] = []
    render = session.view.render
    session.view.render = lambda frame: (seen.append(frame), render(frame))
    for _ in range(240):
        assert wait_for(lambda: session.view.draws, timeout=5, poll=0.001)
        clock.now += 1 / 60
        session.run_once(clock.now)
        frame = seen[-1]
        if frame.readouts is not None and frame.picture is not None and len(seen) > 30:
            return frame
    raise AssertionError("no panel refresh with a picture in 4 s of frames")


@pytest.mark.slow  # a server per scene: ~1 s each
@pytest.mark.parametrize("scene", sorted(SCENES))
def test_the_table_the_overlay_and_the_labels_show_one_instant_written_one_way(
    scene,
    served,  # noqa: F811  (the fixture imported above)
    monkeypatch,
):
    from sandbox.physics import isolate

    read: list[object] = []  # the MjData « Isoler un solide » reads
    real = isolate.balance
    monkeypatch.setattr(isolate, "balance", lambda m, d, *a: (read.append(d), real(m, d, *a))[1])
    session = served(scene)
    frame = _panel_frame(session)
    view = session.view
    values = frame.readouts
    assert values is not None and frame.state is not None
    # the table: the exact value of each readout (data-value), and its written text
    table = {name: (float(v), html.unescape(text))
             for name, v, text in SPAN.findall(view.readouts.scene_text.content)}  # fmt: skip
    assert table, "the scene's table is shown"
    for name, (exact, _) in table.items():
        assert exact == pytest.approx(values[name], rel=1e-9, abs=1e-300), name
    infos = {i.name: i for i in session.controller.sim.readout_infos()}
    spec = SCENES[scene]
    zero = {n: spec.zero_for(i.unit) for n, i in infos.items()}
    # the overlay: the same characters as the table for every readout both show
    overlay = html.unescape(re.sub(r"<[^>]+>", "\n", view.projector.overlay.content))
    lines = [line for line in overlay.splitlines() if line]
    if frame.held is not None:  # a fast rotation's numbers, held at one angle: said last
        assert lines[-1] == held_line(values), overlay
        lines = lines[:-1]
    shown = [line.split(" = ", 1)[1] for line in lines if " = " in line]
    assert len(shown) == len(view.projector.names), overlay
    for name, line in zip(view.projector.names, shown, strict=True):
        assert line == str(written(name, values[name], infos[name].unit, zero=zero[name]))
        if name in table:
            assert line.startswith(table[name][1]), (name, line, table[name])
    # the 3D labels: an arrow that is a readout writes its value at that instant
    arrows = view.arrows
    if arrows is not None:
        for k, arrow in enumerate(arrows.arrows):
            if arrow.name in infos and arrow.magnitude:
                value = written(arrow.name, values[arrow.name], arrow.unit, zero=zero[arrow.name])
                assert arrows.labels[k].text == f"{arrow.label} : {value}", arrow.name
    # « Isoler un solide » reads the state the tables read, not the physics ahead of it
    assert read and read[-1] is frame.state.data
    # the status line's t is that instant's time too
    status = view.controls.status.content
    assert status.startswith(f"t = {time_words(float(frame.state.data.time))} s"), status


@pytest.mark.slow  # a server: ~1 s
def test_in_slow_motion_the_status_line_reads_the_drawn_instant_not_the_physics(
    served,  # noqa: F811  (the fixture imported above)
):
    """At ×0,05 a rotor stepped every 10 ms is drawn between its steps: the status
    line's t is the instant the tables show, not the physics step ahead of it."""
    session = served("rotor")
    ctl = session.controller
    ctl.submit(Speed(0.05))
    frames = 0
    while True:
        frame = _panel_frame(session)
        assert frame.state is not None
        drawn, physics = float(frame.state.data.time), float(ctl.sim.data.time)
        frames += 1
        if abs(drawn - physics) > 1e-4 or frames > 20:
            break
    assert drawn != pytest.approx(physics, abs=1e-4), "the drawn instant is between steps"
    status = session.view.controls.status.content
    assert status.startswith(f"t = {time_words(drawn)} s"), (status, drawn, physics)


def _follow_frame(sim: Simulation):
    """The --follow broadcast of ``sim``'s present state: its view after one frame (the
    summary written, the shared labels relabelled) and that frame's readouts."""
    import viser
    from conftest import free_port

    from sandbox.web.loop import Controller
    from sandbox.web.serving.follow import BroadcastView

    server = viser.ViserServer(port=free_port(), verbose=False)
    try:
        view = BroadcastView(server, Controller(sim))
        values = sim.readouts(view.asked)
        frame = frame_module.Frame(
            now=0.0, time=float(sim.data.time), generation=0, model_id=id(sim.model),
            playing=True, diverged=None, readouts=values,
        )  # fmt: skip
        view._summarise(frame)
        if view.arrows is not None:
            view.arrows.relabel(values)
    finally:
        server.stop()
    return view, values


def test_the_follow_summary_writes_theta_modulo_a_turn_after_a_minute():
    """In --follow, the students' table read the crank angle θ as 973 638°, then
    1,452×10⁶° after a minute at 3000 tr/min: it wrote the readouts its own way. It is
    written as the page writes it: in [0, 360°)."""
    sim = Simulation(get_scene("compressor"))
    sim.advance(60.0)
    view, values = _follow_frame(sim)
    assert values["theta"] > 16000.0  # unwrapped: 50 turns a second for a minute
    row = next(line for line in view.summary.splitlines() if "θ" in line)
    degrees = float(row.split("|")[2].strip().removesuffix("°").replace(",", "."))
    assert 0.0 <= degrees < 360.0
    assert degrees == pytest.approx(math.degrees(values["theta"]) % 360.0, abs=0.01)
    assert "t = 60,00\u00a0s" in view.summary


@pytest.mark.slow  # a viser server per scene: ~0.5 s each
@pytest.mark.parametrize("scene", sorted(SCENES))
def test_the_follow_summary_and_the_broadcast_labels_write_the_frames_values(scene):
    """In --follow, the students' summary and the shared 3D labels write the very values
    of the frame they come with, as the page's table writes them."""
    sim = Simulation(resolve(scene))
    sim.advance(0.37)
    view, values = _follow_frame(sim)
    infos = {i.name: i for i in sim.readout_infos()}
    spec = SCENES[scene]
    rows = [line.split("|") for line in view.summary.splitlines() if line.startswith("|")]
    shown = {cells[1].strip(): cells[2].strip() for cells in rows[2:]}
    assert len(shown) == len(view.names) > 0
    for name in view.names:
        info = infos[name]
        expected = str(written(name, values[name], info.unit, zero=spec.zero_for(info.unit)))
        assert shown[view.labels[name]] == expected, name
    arrows = view.arrows
    if arrows is not None:
        for k, arrow in enumerate(arrows.arrows):
            if arrow.name in infos and arrow.magnitude:
                unit = arrow.unit
                value = written(arrow.name, values[arrow.name], unit, zero=spec.zero_for(unit))
                assert arrows.labels[k].text == f"{arrow.label} : {value}", arrow.name


@pytest.mark.slow  # a server: ~1 s
def test_a_fast_rotation_is_read_at_one_angle_in_every_view_and_live_when_paused(
    served,  # noqa: F811  (the fixture imported above)
):
    """The compressor at 3000 tr/min turns 50 times a second: while it plays, the table,
    the overlay and the labels write the state at θ = 60° every turn (the same numbers
    at each refresh, the overlay saying so); paused, they write the drawn instant."""
    session = served("compressor")
    first = _panel_frame(session)
    view = session.view
    assert first.held is not None and first.state is not None
    overlay = view.projector.overlay.content
    assert html.unescape("(relevé à θ = 60°, à chaque tour)") in html.unescape(overlay)
    labels = [label.text for label in view.arrows.labels]
    clock = session.controller.clock
    later: list[frame_module.Frame] = []
    times: list[float] = []  # the instant each refresh wrote (the status line's t)
    render = session.view.render

    def seen(frame: frame_module.Frame) -> None:
        later.append(frame)
        render(frame)
        if frame.readouts is not None:
            times.append(float(view.controls.status.content.split(" ")[2].replace(",", ".")))

    session.view.render = seen
    while len(times) < 3:  # three refreshes, turns apart
        assert wait_for(lambda: session.view.draws, timeout=5, poll=0.001)
        clock.now += 1 / 60
        session.run_once(clock.now)
    refreshed = [f for f in later if f.readouts is not None]
    assert times[-1] >= times[0] + 0.1  # turns later (the status line writes 10 ms)
    # the arrows stay at the held angle too, the poses move on
    drawn = [f.picture for f in later if f.picture is not None]
    assert len(drawn) >= 10
    for pic in drawn:
        assert pic.magnitudes.tolist() == first.held.magnitudes.tolist()
    assert len({pic.poses.tobytes() for pic in drawn}) > 5
    for frame in refreshed:
        assert frame.readouts["pilon"] == first.readouts["pilon"]
    assert view.projector.overlay.content == overlay
    assert [label.text for label in view.arrows.labels] == labels
    pilon = written("pilon", first.readouts["pilon"], "N")
    assert any(text.endswith(str(pilon)) for text in labels), labels
    # paused: the drawn instant, written live
    session.controller.submit(Pause())
    later.clear()
    while sum(f.readouts is not None for f in later) < 2:
        clock.now += 1 / 60
        session.run_once(clock.now)
    paused = [f for f in later if f.readouts is not None][-1]
    assert paused.held is None
    assert "à chaque tour" not in view.projector.overlay.content


def test_the_follow_summary_of_a_fast_rotation_writes_its_held_instant_and_angle():
    """The followers' table writes a held frame as the page does: the held instant's
    time, the values at θ = 60° and the line that says so."""
    import viser
    from conftest import free_port

    from sandbox.physics.picture import picture
    from sandbox.physics.strobe import Held
    from sandbox.web.loop import Controller
    from sandbox.web.serving.follow import BroadcastView

    sim = Simulation(get_scene("compressor"))
    sim.advance(1.0)
    server = viser.ViserServer(port=free_port(), verbose=False)
    try:
        view = BroadcastView(server, Controller(sim))
        held = Held(sim).snapshot(float(sim.data.time))
        assert held is not None
        values = sim.readouts([*view.asked, "theta"], snapshot=held)
        frame = frame_module.Frame(
            now=0.0, time=float(sim.data.time), generation=0, model_id=id(sim.model),
            playing=True, diverged=None, readouts=values, state=held,
            held=picture(held, SCENES["compressor"].page.arrows),
        )  # fmt: skip
        view._summarise(frame)
    finally:
        server.stop()
    assert view.summary.endswith(held_line(values)) and "θ = 60°" in held_line(values)
    assert f"t = {time_words(float(held.data.time))}" in view.summary
    assert float(held.data.time) < float(sim.data.time)
