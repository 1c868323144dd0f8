"""What a control shows: French labels and tooltips, numbers typed the French way, and
controls that always show the value in force.

A control tells the truth when it shows what the simulation really uses, whoever changed
it last: the user, a lesson preset, a refusal that put the old value back, the teacher's
settings. :class:`Mirror` compares the control itself with the value in force on every
panel refresh, so no change can slip between two refreshes (a preset undoing a value the
user typed a moment before left the slider on the typed value and, viser's copy of the
control holding that value, retyping it sent nothing).
"""

from __future__ import annotations

import functools
import math
import re
import threading
import time
from collections.abc import Callable
from typing import Any

import viser

from sandbox.physics.model import INTEGRATOR_WORDS
from sandbox.physics.spec import Param
from sandbox.web.client.text import number

GRACE = 0.4
"""Seconds a control the user just changed may differ from the value in force (their
request is on its way to the simulation loop)."""


def param_unit(p: Param) -> str:
    """A parameter's unit as the page writes it (the scene's own display unit if any)."""
    return p.display_unit


def param_label(p: Param) -> str:
    """A parameter's label: its French words (else its name) and its unit."""
    unit = param_unit(p)
    words = p.label or p.name
    return f"{words} [{unit}]" if unit else words


def param_hint(p: Param) -> str:
    """A parameter's tooltip: its French sentence (else its doc) and its range."""
    unit = f" {param_unit(p)}" if p.unit else ""
    base = (p.hint or p.doc).rstrip(".")
    return f"{base} (de {number(p.min)} à {number(p.max)}{unit})."


def advanced(p: Param) -> bool:
    """True for a rarely changed parameter (shown in a folded folder)."""
    return p.advanced


def typed(p: Param) -> bool:
    """True when a parameter is typed in a number box (engineering notation) rather
    than slid: its range spans decades (``log``), or it is a rarely changed one."""
    return p.log or advanced(p)


def choices(p: Param) -> tuple[str, ...]:
    """French names of the values 0, 1, 2... of a parameter picking an option (else ())."""
    return tuple(str(c) for c in p.choices)


def integrator_name(label: object) -> object:
    """The contract name behind a dropdown label (anything else passes unchanged: the
    session refuses it, in French)."""
    for name, words in INTEGRATOR_WORDS.items():
        if label == words:
            return name
    return label


_SUPERSCRIPTS = str.maketrans("⁻⁰¹²³⁴⁵⁶⁷⁸⁹", "-0123456789")
_POWER = re.compile(r"^\s*([-+−]?[\d.]+)\s*[x×·*]\s*10\s*\^?\s*([-+−]?\d+)\s*$")


def parse_number(text: object) -> float | object:
    """A number typed the French way (``0,0002``, ``2×10⁻⁴``, ``2e-4``, ``1 500``), as a
    float; anything else comes back unchanged (the session refuses it, in French)."""
    if not isinstance(text, str) or len(text) > 64:
        return text
    clean = text.translate(_SUPERSCRIPTS).replace("\u202f", "").replace("\xa0", "")
    clean = clean.replace(" ", "").replace(",", ".").replace("−", "-")
    match = _POWER.match(clean)
    try:
        if match:
            value = float(match.group(1)) * 10.0 ** int(match.group(2))
        else:
            value = float(clean)
    except (ValueError, OverflowError):
        return text
    return value if math.isfinite(value) else text


@functools.lru_cache(maxsize=4096)
def engineering(value: float) -> str:
    """A parameter in a number box: four digits, decimal comma, ×10ⁿ when tiny or huge
    (``0,0002``, ``1,2×10⁻⁷``), never ``0.00000`` (kept: every control is compared with
    the value in force ten times a second, and parameters seldom change)."""
    return number(value, 4)


TYPING = 1.5
"""Seconds a value outside a control's range waits before it is applied (and refused):
the browser sends a number box's value at every key, so typing « 0,01 » sent 0 first,
whose refusal put the old value back under the user's fingers (« 1.01 »)."""


def _outside(handle: object, value: object) -> bool:
    """True when ``value`` is a number outside ``handle``'s own bounds (a number box whose
    first digits are being typed); False without bounds or for anything else."""
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        return False
    low, high = getattr(handle, "min", None), getattr(handle, "max", None)
    return (isinstance(low, (int, float)) and value < low) or (
        isinstance(high, (int, float)) and value > high
    )


def on_user(handle: viser.GuiInputHandle[Any], action: Callable[[Any], None]) -> None:
    """Run ``action(value)`` when the user (not the server) changes ``handle``; never
    while it is disabled (a control a shared link locked or hid: only a crafted message
    can change it, and the next refresh puts it back). A value outside the control's own
    range is applied only if no other comes within :data:`TYPING` seconds (the first
    digits of a number being typed are never refused under the user's fingers)."""
    waiting: list[threading.Timer] = []
    lock = threading.Lock()

    @handle.on_update
    def _(event: viser.GuiEvent[Any]) -> None:
        if event.client is None or handle.disabled:
            return
        value = event.target.value
        with lock:
            for timer in waiting:
                timer.cancel()
            waiting.clear()
            if _outside(handle, value):
                timer = threading.Timer(TYPING, action, args=(value,))
                timer.daemon = True
                waiting.append(timer)
                timer.start()
                return
        action(value)


def set_value(handle: viser.GuiInputHandle[Any], value: object) -> None:
    """Show ``value`` in an input (sent to the browser).

    viser declares ``value`` as a property on one base class and as a plain field on
    the props class it also inherits, which mypy reads as read-only: assigned here once.
    """
    handle.value = value  # type: ignore[misc]


class Mirror:
    """Keeps one control equal to the value in force.

    Args:
        handle: The viser input.
        read: The value in force, as the control shows it.
        busy: True while requests wait for the simulation loop (the control may be ahead
            of the simulation: it is left alone until they are applied).
        clock: Wall clock [s] comparable with viser's ``update_timestamp`` (``time.time``).
    """

    def __init__(
        self,
        handle: viser.GuiInputHandle[Any],
        read: Callable[[], object],
        *,
        busy: Callable[[], bool] = lambda: False,
        clock: Callable[[], float] = time.time,
    ) -> None:
        self.handle = handle
        self.read = read
        self.busy = busy
        self.clock = clock
        self._own = handle.update_timestamp  # the last value the server itself showed
        self._hidden = False

    def refresh(self, *, force: bool = False) -> bool:
        """Show the value in force unless the user changed the control just now and
        their request is not applied yet (``force``: after a refusal, at once).

        A value the user had typed and the server then replaced is also redrawn: viser's
        number box remembers the typed text, and typing that same text again would send
        nothing (the box is hidden for one refresh, which builds it anew).

        Returns:
            True when the control was changed.
        """
        if self._hidden:
            self._hidden = False
            self.handle.visible = True
        truth = self.read()
        if _same(self.handle.value, truth):
            return False
        by_user = self.handle.update_timestamp != self._own
        if not force:
            if self.busy() or (by_user and self.clock() - self.handle.update_timestamp < GRACE):
                return False
        set_value(self.handle, truth)
        self._own = self.handle.update_timestamp
        if by_user and self.handle.visible:
            self.handle.visible = False
            self._hidden = True
        return True


def _same(shown: object, truth: object) -> bool:
    if isinstance(shown, float | int) and isinstance(truth, float | int):
        return float(shown) == float(truth) or (shown != shown and truth != truth)
    return shown == truth
