"""The seams of sandbox.web.loop made public by its split: the timestep refusal shared by
pacing and the checks, and the scheduler's view of a session."""

from __future__ import annotations

import pytest

from sandbox.physics.simulation import Simulation
from sandbox.web.loop import Controller, Refused, Scheduler, Session, check_timestep
from sandbox.web.loop.refusals import max_timestep, timestep_range
from sandbox.web.loop.scheduler import Turns


def test_the_timestep_refusal_gives_the_range_in_french():
    sim = Simulation("rotor")
    words = timestep_range(sim, 0.5)
    assert words.startswith("Pas de temps dt = 0,5 s refusé : choisissez un pas entre 1×10⁻⁶ s")
    assert words.endswith(" s.") and "0,5" not in words.split("entre")[1]
    assert max_timestep(sim) > 0
    with pytest.raises(Refused) as err:
        check_timestep(sim, 0.5)
    assert str(err.value) == words
    assert timestep_range(sim, "abc").startswith("Pas de temps dt = abc s refusé")


class Blank:
    draws = False

    def wants(self, now: float) -> None:
        return None

    def render(self, frame: object) -> None:
        pass

    def notify(self, notice: object) -> None:
        pass


def test_a_session_is_what_the_scheduler_runs_and_says_when_it_stops():
    scheduler = Scheduler(threaded=False)
    session = Session(Controller(Simulation("rotor")), Blank(), scheduler=scheduler)
    turns: Turns = session
    assert not turns.stopping
    session.request_stop()
    assert turns.stopping
