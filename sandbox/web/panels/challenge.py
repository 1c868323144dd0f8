"""The folder "Défi" of a student's page: the goal of the challenge the teacher started,
the student's tries, and the solution once the teacher stops it.

While a challenge runs, the page is built from the public twin of the student's machine
(:mod:`sandbox.web.loop.secret`): the secret parameters' controls are gone, the readouts that
would give them away are neither shown nor sent, the panels that read the simulation
directly (isolating a solid, the polar diagram, accuracy) are closed. A try is checked
against the course's closed form (:meth:`sandbox.challenges.Attempt.check`), never by the
browser.
"""

from __future__ import annotations

import math
import threading
import time
from collections.abc import Callable, Mapping
from typing import Protocol

import viser

from sandbox.challenges import BALANCED, Attempt, Challenge
from sandbox.physics.spec import Param
from sandbox.web.client.fields import param_unit
from sandbox.web.client.text import html_text, number, with_unit
from sandbox.web.loop.requests import Challenge as StartOrEnd
from sandbox.web.loop.secret import Secret
from sandbox.web.loop.state import SessionState
from sandbox.web.panels.board_table import duration
from sandbox.web.panels.tables import RELATIVE_ZERO

FOLDER = "Défi"
CHECK_BUTTON = "Vérifier l'équilibrage"
ANSWER_BUTTON = "Proposer"
ORDER = -500.0
"""Place of "Défi" on a student's page: above "Simulation"."""


class Page(Protocol):
    """What the panel changes on the student's page while a challenge runs."""

    def restrict(self, secret: Secret) -> None: ...
    def unrestrict(self) -> None: ...


def _words(p: Param | None, name: str, value: float) -> str:
    """ "Masse de correction m₁ : 23,4 g" (the parameter's words and unit)."""
    if p is None:
        return f"{name} : {number(value, 3)}"
    # below the tables' round-off of its range: an angle solved as 8,48×10⁻¹⁴° reads 0°
    floor = RELATIVE_ZERO * max(abs(p.min), abs(p.max))
    return f"{p.label or p.name} : {with_unit(number(value, 3, zero=floor), param_unit(p))}"


def solution_lines(c: Challenge, values: Mapping[str, float], params: Mapping[str, Param]) -> str:
    """The solution of ``c`` for the machine ``values`` (secret included) in French."""
    if c.solution is None:
        return ""
    found = c.solution(values)
    if c.answer is not None:
        (value,) = found.values()
        return f"{c.answer.label} : {with_unit(number(value, 4), c.answer.unit)}"
    return " ; ".join(_words(params.get(n), n, v) for n, v in found.items() if n in params)


def secret_lines(secret: Mapping[str, float], params: Mapping[str, Param]) -> str:
    """What was hidden, in French."""
    return " ; ".join(_words(params.get(n), n, v) for n, v in secret.items())


class ChallengePanel:
    """The student's "Défi" folder (hidden until the teacher starts a challenge).

    Args:
        gui: The student's ``GuiApi``.
        controller: Their session's controller (the secret goes to its loop).
        page: Their page (:class:`~sandbox.web.views.browser.WebView`), restricted while it runs.
        clock: Wall clock [s].
        announce: Shows a notice (title, text) on the page wherever it is scrolled: a
            challenge's start announces itself.
    """

    def __init__(
        self,
        gui: viser.GuiApi,
        controller: SessionState,
        page: Page,
        *,
        clock: Callable[[], float] = time.time,
        announce: Callable[[str, str], None] | None = None,
    ) -> None:
        self.gui = gui
        self.announce = announce
        self.controller = controller
        self.page = page
        self.clock = clock
        scene = controller.sim.scene
        self.params = {p.name: p for p in (scene.params if scene is not None else ())}
        self.attempt: Attempt | None = None
        self.ended = False
        self._lock = threading.Lock()
        with gui.add_folder(FOLDER, order=ORDER, visible=False) as self.folder:
            self.goal = gui.add_markdown("")
            self.answer = gui.add_number(
                "Votre réponse", initial_value=0.0, step=1.0, min=0.0, max=100000.0
            )
            self.button = gui.add_button(CHECK_BUTTON)
            self.feedback = gui.add_markdown("")
        self.button.on_click(self._clicked)

    # -- from the class board (its thread) ------------------------------------------------
    def begin(self, attempt: Attempt) -> None:
        """Start ``attempt`` on this page: the secret to the simulation, the page
        restricted, the goal shown."""
        c = attempt.challenge
        secret = Secret(attempt)
        with self._lock:
            self.attempt, self.ended = attempt, False
        self.page.restrict(secret)
        self.controller.submit(StartOrEnd(secret))
        self.goal.content = f"**{html_text(c.title)}**\n\n{html_text(c.goal)}"
        asks = c.answer is not None
        self.answer.visible = asks
        if c.answer is not None:
            self.answer.label = f"{c.answer.label} [{c.answer.unit}]"
            self.answer.hint = "Tapez votre valeur, puis « Proposer »"
        self.button.label = ANSWER_BUTTON if asks else CHECK_BUTTON
        self.button.hint = (
            "Vérifie votre réponse (à 3 % près)"
            if asks
            else f"Vérifie que les paliers ne portent plus que {round(100 * BALANCED)} % de "
            "l'effort de départ"
        )
        self.button.visible = True
        self.button.disabled = False
        self.feedback.content = "Aucun essai pour l'instant."
        self.folder.visible = True
        self.folder.expand_by_default = True
        if self.announce is not None:
            self.announce(
                "Défi lancé",
                f"«\u00a0{c.title}\u00a0» : votre défi est en haut du panneau, dans "
                f"«\u00a0{FOLDER}\u00a0».",
            )

    def end(self) -> None:
        """The teacher stopped it: the solution and what was hidden shown, the page whole
        again (the secret controls show their values)."""
        with self._lock:
            attempt, self.ended = self.attempt, True
        if attempt is None:
            return
        self.controller.submit(StartOrEnd(None))
        self.page.unrestrict()
        values = attempt.values(self._values())
        c = attempt.challenge
        result = (
            f"Réussi en {duration(attempt.solved_after)}."
            if attempt.solved
            else "Pas résolu cette fois."
        )
        self.button.visible = False
        self.answer.visible = False
        self.feedback.content = (
            f"**Défi terminé.** {result}\n\n"
            f"Solution : {html_text(solution_lines(c, values, self.params))}.\n\n"
            f"Ce qui était caché : {html_text(secret_lines(attempt.secret, self.params))}."
        )

    # -- the student's tries (viser's thread) ---------------------------------------------
    def _values(self) -> dict[str, float]:
        sim = self.controller.sim
        with sim.lock:
            return dict(sim.values)

    def _clicked(self, _: object) -> None:
        with self._lock:
            attempt = None if self.ended else self.attempt
        if attempt is None:
            return
        c = attempt.challenge
        answer: float | None = None
        if c.answer is not None:
            try:
                answer = float(self.answer.value)
            except (TypeError, ValueError):
                answer = math.nan
        with self._lock:
            solved = attempt.check(self._values(), self.clock(), answer)
        self.feedback.content = self._verdict(attempt, solved)

    def _verdict(self, attempt: Attempt, solved: bool) -> str:
        n = attempt.tries
        tries = f"{n} essai{'s' if n > 1 else ''}"
        if solved:
            return f"**Réussi** en {duration(attempt.solved_after)}, {tries}. Bravo !"
        if attempt.challenge.answer is not None:
            return f"Essai {n} : pas encore, ce n'est pas la bonne valeur (à 3 % près)."
        left = attempt.last
        if math.isfinite(left):
            return (
                f"Essai {n} : pas encore. L'effort du palier le plus chargé vaut "
                f"{round(100 * left)} % de l'effort maximal de départ (objectif : "
                f"{round(100 * BALANCED)} % au plus)."
            )
        return f"Essai {n} : pas encore."

    def state(self) -> tuple[str, int, float]:
        """(challenge name, tries, seconds to solve or NaN) for the class board."""
        with self._lock:
            attempt = self.attempt
            if attempt is None:
                return "", 0, math.nan
            return attempt.challenge.name, attempt.tries, attempt.solved_after
