"""Students' progress through a lesson: step, start values, success, hints shown; a check
that live values make impossible to compute is kept and shown once, in French, with
``file:line``."""

from __future__ import annotations

import logging
from collections.abc import Mapping

from sandbox.lessons.checks import Check
from sandbox.lessons.evaluation import CheckError
from sandbox.lessons.model import Lesson, Step

MISSING_FRAMES = 5
"""Refreshes a check may wait for a readout it names before this is reported."""

log = logging.getLogger("sandbox.lessons")  # the package's logger, as before the split

_REPORTED: set[tuple[str, str]] = set()
"""Check errors already logged by this process (each is logged once)."""
MAX_REPORTED = 1000
"""Most distinct check errors logged by one process."""


class Progress:
    """Where a student is in a lesson: step, start values, success, hints shown.

    Pure state (no UI): the web panel asks it what to apply and what to show.

    Attributes:
        error: Why the step's check cannot be computed (French, ending with ``file:line``),
            None while it can. Set by the first failure of the step and kept until the
            student changes step; a later evaluation that succeeds still counts.
    """

    def __init__(self, lesson: Lesson) -> None:
        self.lesson = lesson
        self.index = 0
        self.initial: dict[str, float] | None = None
        self.passed: set[int] = set()
        self.hints_shown = 0
        self.error: str | None = None
        self._missing = 0

    @property
    def step(self) -> Step:
        return self.lesson.steps[self.index]

    def go(self, index: int) -> Step:
        """Enter step ``index`` (clamped); the caller applies its presets."""
        self.index = min(max(index, 0), len(self.lesson.steps) - 1)
        self.initial = None
        self.hints_shown = 0
        self.error = None
        self._missing = 0
        return self.step

    def ready(self, current: Mapping[str, float]) -> bool:
        """True once the step's presets are in force in the parameter values ``current``."""
        return all(current.get(n) == v for n, v in self.step.preset)

    def observe(self, readouts: Mapping[str, float], params: Mapping[str, float]) -> bool | None:
        """Feed the readouts shown now; returns the check's result (None: no check, not
        ready yet, or the check cannot be computed: see :attr:`error`)."""
        check = self.step.check
        if self.initial is None and not self.ready(params):
            return None
        if check is not None:
            missing = [n for n in (*check.names, *check.initial) if n not in readouts]
            if missing:  # a frame with fewer readouts (the lesson was just opened)
                self._missing += 1
                if self._missing >= MISSING_FRAMES:
                    name = missing[0]
                    self._report(
                        check,
                        CheckError(f"no readout {name!r}", f"grandeur « {name} » absente"),
                    )
                return None
            self._missing = 0
        if self.initial is None:
            self.initial = dict(readouts)
        if check is None:
            return None
        try:
            ok = check.evaluate(readouts, self.initial)
        except CheckError as exc:
            self._report(check, exc)
            return None
        if ok:
            self.passed.add(self.index)
        return ok

    def _report(self, check: Check, exc: CheckError) -> None:
        if self.error is not None:
            return
        where = check.where or f"{self.lesson.path.name}:{self.step.line}"
        self.error = f"{exc.french} ({where})"
        key = (where, str(exc))
        if key not in _REPORTED and len(_REPORTED) < MAX_REPORTED:
            _REPORTED.add(key)
            log.warning("lesson check %s (%s) cannot be computed: %s", where, check.source, exc)

    def next_hint(self) -> str | None:
        """Reveal one more hint (None when all are shown)."""
        if self.hints_shown >= len(self.step.hints):
            return None
        self.hints_shown += 1
        return self.step.hints[self.hints_shown - 1]
