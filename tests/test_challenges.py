"""Challenges: secrets drawn on the sliders' steps, solved by the course's solution and
not by the bare machine, answers checked against the closed form."""

from __future__ import annotations

import math
import random

import pytest

from sandbox import challenges
from sandbox.challenges import BALANCED, CHALLENGES, UnknownChallenge, challenge, for_scene
from sandbox.scenes import get_scene, rotor


def _values(c: challenges.Challenge, seed: int) -> tuple[dict[str, float], dict[str, float]]:
    base = {**get_scene(c.scene).defaults(), **dict(c.fixed)}
    secret = c.draw(base, random.Random(seed))
    return base, {**base, **secret}


@pytest.mark.parametrize("name", sorted(CHALLENGES))
def test_secret_drawn_within_range_on_steps(name: str) -> None:
    c = CHALLENGES[name]
    scene = get_scene(c.scene)
    params = {p.name: p for p in scene.params}
    for seed in range(50):
        _, values = _values(c, seed)
        for d in c.secret:
            x = values[d.name]
            assert d.low - 1e-9 <= abs(x) <= d.high + 1e-9
            assert abs(x / d.step - round(x / d.step)) < 1e-6
            p = params[d.name]  # a value the scene's own slider accepts
            assert p.min <= x <= p.max
        assert set(c.hidden) == {d.name for d in c.secret}
        assert set(c.withheld) <= {r.name for r in scene.readouts}


def test_draws_differ_between_students_and_repeat_with_the_seed() -> None:
    c = CHALLENGES["wheel_balance"]
    base = {**get_scene(c.scene).defaults(), **dict(c.fixed)}
    a = [c.draw(base, random.Random(s)) for s in range(20)]
    assert len({tuple(sorted(x.items())) for x in a}) == 20
    assert c.draw(base, random.Random(3)) == a[3]


def _rounded(scene: str, solution: dict[str, float]) -> dict[str, float]:
    """The solution as a student sets it: on the sliders' steps."""
    steps = {p.name: p.step for p in get_scene(scene).params}
    return {k: round(v / steps[k]) * steps[k] for k, v in solution.items()}


@pytest.mark.parametrize("name", ["rotor_balance", "wheel_balance"])
def test_balance_solved_by_the_course_solution_not_by_the_bare_machine(name: str) -> None:
    c = CHALLENGES[name]
    assert c.solution is not None
    for seed in range(30):
        _, values = _values(c, seed)
        assert not c.solved(values)
        assert c.residual(values) == pytest.approx(1.0)
        fixed = {**values, **_rounded(c.scene, c.solution(values))}
        assert c.solved(fixed), (seed, c.residual(fixed))
        assert c.residual(fixed) < 0.02  # the slider steps leave under 2 %
        # half the correction leaves about half the forces: not solved
        half = {**values, **_rounded(c.scene, c.solution(values))}
        for k in half:
            if k.startswith("mass"):
                half[k] = values.get(k, 0.0) + 0.5 * (half[k] - values.get(k, 0.0))
        assert not c.solved(half)
        assert 0.3 < c.residual(half) < 0.7


def test_rotor_balance_threshold_is_five_percent() -> None:
    c = CHALLENGES["rotor_balance"]
    _, values = _values(c, 1)
    sol = c.solution(values)  # type: ignore[misc]
    # scale the exact correction: the residual is the missing fraction
    for scale, solved in ((0.96, True), (0.94, False)):
        v = {**values, **sol}
        v["mass1_g"] *= scale
        v["mass2_g"] *= scale
        assert c.residual(v) == pytest.approx(1 - scale, abs=1e-6)
        assert c.solved(v) is solved
    assert BALANCED == 0.05


def test_speed_answer_is_the_closed_form_speed() -> None:
    c = CHALLENGES["rotor_speed"]
    assert c.answer is not None
    for seed in range(30):
        _, values = _values(c, seed)
        exact = c.answer.exact(values)
        assert 1500.0 <= exact <= 5500.0
        # at that speed, the course's bearing A carries 100 N
        assert rotor.reference({**values, "speed_rpm": exact})["bearing_A"] == pytest.approx(100.0)
        assert c.solved(values, exact * 1.02)
        assert c.solved(values, exact * 0.975)
        assert not c.solved(values, exact * 1.04)
        assert not c.solved(values, None)
        assert not c.solved(values, math.nan)
        assert not c.solved(values, math.inf)


def test_unknown_challenge_names_the_valid_ones() -> None:
    with pytest.raises(UnknownChallenge, match="rotor_balance, rotor_speed, wheel_balance"):
        challenge("rotor_balanse")
    assert [c.name for c in for_scene("rotor")] == ["rotor_balance", "rotor_speed"]
    assert for_scene("engine") == []


def test_an_attempt_counts_tries_and_dates_the_first_success() -> None:
    """Course 7.2 for the rotor: the correction masses of the solution bring both bearing
    forces to round-off; the first try on the bare machine reads 100 % left."""
    attempt = challenges.start("rotor_balance", "run", get_scene("rotor").defaults(), 100.0,
                               random.Random(4))  # fmt: skip
    public = {**get_scene("rotor").defaults(), "speed_rpm": 1500.0}
    assert not attempt.check(public, 110.0)
    assert attempt.tries == 1 and attempt.last == pytest.approx(1.0)
    solved = {**public, **attempt.challenge.solution(attempt.values(public))}
    assert attempt.check(solved, 160.0) and attempt.solved_after == pytest.approx(60.0)
    assert attempt.check(public, 170.0)  # once solved, solved: no more tries counted
    assert attempt.tries == 2 and attempt.solved_after == pytest.approx(60.0)


def test_an_answer_attempt_takes_three_percent() -> None:
    attempt = challenges.start("rotor_speed", "run", get_scene("rotor").defaults(), 0.0,
                               random.Random(7))  # fmt: skip
    public = get_scene("rotor").defaults()
    exact = challenges.speed_for_force(attempt.values(public))
    assert not attempt.check(public, 1.0, answer=exact * 1.05)
    assert attempt.last == pytest.approx(0.05, rel=1e-6)
    assert not attempt.check(public, 2.0, answer=math.nan) and attempt.last == math.inf
    assert attempt.check(public, 3.0, answer=exact * 0.98) and attempt.tries == 3
    with pytest.raises(UnknownChallenge, match="valid challenges: rotor_balance"):
        challenges.start("rotor_mystery", "run", public, 0.0)
