"""Challenges ("Défis"): a mystery drawn for each student, and the course's closed form
that tells when they have solved it.

A teacher starts a challenge for the class; each student's simulation gets its own
secret values (a rotor's defect, a wheel's unbalance), drawn here, that the student's
page never shows: the secret parameters have no control, the readouts that would give
them away (:attr:`Challenge.withheld`) are not sent. The student balances the machine
(a *balance* challenge: solved when the course's bearing forces at the current speed
have fallen below :data:`BALANCED` of what the bare machine carries) or types a number
(an *answer* challenge, within :attr:`Answer.tolerance` of the exact value).

This module is pure: it draws, checks and solves from parameter values with the scenes'
closed forms (no simulation, no web), so that checking a try costs microseconds and the
solution shown at the end is the course's.
"""

from __future__ import annotations

import math
import random
from collections.abc import Callable, Mapping
from dataclasses import dataclass

from sandbox.errors import SandboxError
from sandbox.scenes import rotor, wheel_balancer

Values = Mapping[str, float]

BALANCED = 0.05
"""A balance challenge is solved when the larger bearing force is at most this fraction
of the bare machine's larger one at the same speed (the course's solution set on the
sliders' steps leaves at most 1.5 %: 2000 draws of each balance challenge)."""


class UnknownChallenge(SandboxError):
    """A challenge name that is not in :data:`CHALLENGES`."""


@dataclass(frozen=True)
class Draw:
    """A secret parameter drawn uniformly on its slider's steps.

    Attributes:
        name: The scene's parameter name.
        low: Smallest magnitude drawn (in the parameter's unit).
        high: Largest magnitude drawn.
        step: The drawn value is a whole number of steps.
        signed: Draw the sign too (a magnitude in [low, high], either sign).
        shown: The value the page's picture is built with (its public twin), whatever
            was drawn: 0 draws no defect, a tilt of 0 a straight disk.
    """

    name: str
    low: float
    high: float
    step: float
    signed: bool = False
    shown: float = 0.0

    def value(self, rng: random.Random) -> float:
        steps = int(round((self.high - self.low) / self.step))
        x = self.low + self.step * rng.randint(0, steps)
        x = round(x / self.step) * self.step
        return -x if self.signed and rng.random() < 0.5 else x


@dataclass(frozen=True)
class Answer:
    """The number an answer challenge asks for.

    Attributes:
        label: What the student types, in French.
        unit: The unit it is typed in (the scene's unit words).
        exact: The exact answer [unit] from the full values (secret included).
        tolerance: Relative gap accepted.
    """

    label: str
    unit: str
    exact: Callable[[Values], float]
    tolerance: float = 0.03


@dataclass(frozen=True)
class Challenge:
    """One challenge of the registry.

    Attributes:
        name: Identifier (English, used in CSV exports).
        scene: The scene it runs in.
        title: French title on the board and in the student's page.
        goal: French instruction shown to the student.
        secret: The parameters drawn for each student (never shown to them).
        fixed: Parameters set for everyone (values).
        withheld: Readouts the student's page does not receive while it runs.
        answer: For an answer challenge, the number asked; None for a balance challenge.
        bare: For a balance challenge, the values of the unbalanced machine.
        forces: For a balance challenge, the course's bearing forces [N] of values.
        solution: The values (or the answer) that solve it, shown when it ends.
        accept: Optional test a drawn secret must pass (drawn again otherwise).
    """

    name: str
    scene: str
    title: str
    goal: str
    secret: tuple[Draw, ...]
    fixed: tuple[tuple[str, float], ...] = ()
    withheld: tuple[str, ...] = ()
    answer: Answer | None = None
    bare: Callable[[Values], Values] | None = None
    forces: Callable[[Values], tuple[float, float]] | None = None
    solution: Callable[[Values], dict[str, float]] | None = None
    accept: Callable[[Values], bool] | None = None

    @property
    def hidden(self) -> tuple[str, ...]:
        """Parameters the student's page shows no control for."""
        return tuple(d.name for d in self.secret)

    def draw(self, defaults: Values, rng: random.Random, tries: int = 1000) -> dict[str, float]:
        """The secret values of one student (drawn again until :attr:`accept` passes).

        Args:
            defaults: The scene's values the secret goes with (for :attr:`accept`).
            rng: The random source (the server uses one seeded by the system).
            tries: Draws before giving up (a registry error, never a student's).
        """
        for _ in range(tries):
            secret = {d.name: d.value(rng) for d in self.secret}
            if self.accept is None or self.accept({**defaults, **dict(self.fixed), **secret}):
                return secret
        raise RuntimeError(f"challenge {self.name!r}: no accepted draw in {tries} tries")

    def public(self) -> dict[str, float]:
        """The secret parameters' stand-ins the picture is built with
        (:func:`sandbox.physics.picture.picture`'s ``shown`` twin)."""
        return {d.name: d.shown for d in self.secret}

    def solved(self, values: Values, answer: float | None = None) -> bool:
        """Whether ``values`` (the student's, secret included) or ``answer`` solve it."""
        if self.answer is not None:
            if answer is None or not math.isfinite(answer):
                return False
            exact = self.answer.exact(values)
            return abs(answer - exact) <= self.answer.tolerance * abs(exact)
        assert self.forces is not None and self.bare is not None
        return self.residual(values) <= BALANCED

    def residual(self, values: Values) -> float:
        """For a balance challenge, the larger bearing force as a fraction of the bare
        machine's larger one (1 at the start, 0 balanced; each bearing's own ratio would
        be unbounded where the static and couple unbalances nearly cancel at a bearing);
        NaN for an answer challenge."""
        if self.forces is None or self.bare is None:
            return math.nan
        before = max(self.forces(self.bare(values)))
        return max(self.forces(values)) / before if before > 0 else 0.0


# -- the registry -------------------------------------------------------------------------
def _rotor_forces(v: Values) -> tuple[float, float]:
    ref = rotor.reference(v)
    return ref["bearing_A"], ref["bearing_B"]


def _rotor_bare(v: Values) -> Values:
    return {**v, "mass1_g": 0.0, "mass2_g": 0.0}


def _wheel_forces(v: Values) -> tuple[float, float]:
    ref = wheel_balancer.reference(v)
    return ref["bearing_inner"], ref["bearing_outer"]


TARGET_FORCE = 100.0
"""Force of bearing A the torsor challenge asks the speed of [N]."""


def speed_for_force(v: Values, force: float = TARGET_FORCE) -> float:
    """Speed [tr/min] at which bearing A of the rotor ``v`` carries ``force`` [N]: the
    forces grow as ω² (course 7.2), so one closed-form evaluation gives it."""
    at = {**v, "speed_rpm": 1000.0}
    return 1000.0 * math.sqrt(force / rotor.reference(at)["bearing_A"])


def _speed_in_range(v: Values) -> bool:
    return 1500.0 <= speed_for_force(v) <= 5500.0


ROTOR_WITHHELD = ("static_unbalance", "products_EF", "F_rot", "M_rot")
"""The rotor's readouts that give its defect away: the unbalances, and the rotating
resultant and moment (F_rot = m ω² Y, M_rot = ω² √(E² + F²))."""

CHALLENGES: dict[str, Challenge] = {
    c.name: c
    for c in (
        Challenge(
            name="rotor_balance",
            scene="rotor",
            title="Rotor mystère à équilibrer",
            goal="Le défaut du rotor est caché. Réglez les deux masses de correction pour que "
            "les efforts des paliers A et B tombent sous 5 % de leur valeur de départ.",
            secret=(
                Draw("defect_mass_g", 10.0, 60.0, 1.0, shown=1.0),
                Draw("skew_deg", 0.5, 4.0, 0.1, True),
            ),
            fixed=(("speed_rpm", 1500.0),),
            withheld=ROTOR_WITHHELD,
            bare=_rotor_bare,
            forces=_rotor_forces,
            solution=rotor.balancing_solution,
        ),
        Challenge(
            name="wheel_balance",
            scene="wheel_balancer",
            title="Roue mystère à équilibrer",
            goal="Le balourd de la roue est caché et la machine n'affiche pas les masselottes. "
            "Placez-les pour que les deux paliers ne portent plus que 5 % de leur effort de "
            "départ.",
            secret=(
                Draw("defect_mass_g", 10.0, 80.0, 0.5),
                Draw("defect_angle_deg", 0.0, 359.0, 1.0),
                Draw("skew_deg", 0.1, 0.8, 0.01, True),
                Draw("skew_angle_deg", 0.0, 359.0, 1.0),
            ),
            fixed=(("supports", 0.0), ("mystery", 0.0)),
            withheld=("clip_inner_g", "clip_inner_deg", "clip_outer_g", "clip_outer_deg"),
            bare=wheel_balancer.bare,
            forces=_wheel_forces,
            solution=wheel_balancer.machine_solution,
        ),
        Challenge(
            name="rotor_speed",
            scene="rotor",
            title="À quelle vitesse le palier A porte-t-il 100 N ?",
            goal="Le défaut du rotor est caché. Trouvez la vitesse de rotation à laquelle "
            "l'effort du palier A vaut 100 N, puis proposez-la.",
            secret=(
                Draw("defect_mass_g", 10.0, 120.0, 1.0, shown=1.0),
                Draw("skew_deg", 0.0, 3.0, 0.1, True),
            ),
            withheld=ROTOR_WITHHELD,
            answer=Answer("Vitesse ω pour 100 N au palier A", "tr/min", speed_for_force),
            accept=_speed_in_range,
            solution=lambda v: {"speed_rpm": speed_for_force(v)},
        ),
    )
}
"""Every challenge, by name."""


def challenge(name: str) -> Challenge:
    """The challenge called ``name``.

    Raises:
        UnknownChallenge: naming the valid ones.
    """
    try:
        return CHALLENGES[name]
    except KeyError:
        raise UnknownChallenge(
            f"unknown challenge {name!r}; valid challenges: {', '.join(sorted(CHALLENGES))}"
        ) from None


def for_scene(scene: str) -> list[Challenge]:
    """The challenges a scene offers, in the registry's order."""
    return [c for c in CHALLENGES.values() if c.scene == scene]


@dataclass
class Attempt:
    """One student's run of a challenge: their secret and their tries.

    Attributes:
        challenge: The challenge.
        run: Identifier of the class's run (a new start is a new run).
        secret: The values drawn for this student.
        started: When it started for them (wall clock [s]).
        tries: Checks asked so far ("Vérifier", or an answer proposed).
        solved_after: Seconds from the start to the first try that solved it (NaN: not
            solved).
        last: The last try's gap (residual fraction, or relative gap of the answer).
    """

    challenge: Challenge
    run: str
    secret: dict[str, float]
    started: float
    tries: int = 0
    solved_after: float = math.nan
    last: float = math.nan

    @property
    def solved(self) -> bool:
        """True once a try solved it."""
        return math.isfinite(self.solved_after)

    def values(self, public: Values) -> dict[str, float]:
        """The full values of the student's machine: theirs, the fixed ones, the secret."""
        return {**public, **dict(self.challenge.fixed), **self.secret}

    def check(self, public: Values, now: float, answer: float | None = None) -> bool:
        """One try with the student's values (``public``) or ``answer``: counted, and the
        first success dates the solution. A try after success changes nothing."""
        if self.solved:
            return True
        values = self.values(public)
        self.tries += 1
        c = self.challenge
        if c.answer is not None:
            exact = c.answer.exact(values)
            self.last = (
                abs(answer - exact) / abs(exact)
                if answer is not None and math.isfinite(answer) and exact
                else math.inf
            )
        else:
            self.last = c.residual(values)
        if c.solved(values, answer):
            self.solved_after = max(now - self.started, 0.0)
        return self.solved


def start(
    name: str, run: str, defaults: Values, now: float, rng: random.Random | None = None
) -> Attempt:
    """A student's attempt at challenge ``name`` (their secret drawn with ``rng``, the
    system's random source by default).

    Raises:
        UnknownChallenge: naming the valid ones.
    """
    c = challenge(name)
    source = rng if rng is not None else random.SystemRandom()
    return Attempt(c, run, c.draw({**defaults, **dict(c.fixed)}, source), now)
