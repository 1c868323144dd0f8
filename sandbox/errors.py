"""Error hierarchy: every message names the problem, the bad value (!r) and the fix."""

from __future__ import annotations

from collections.abc import Iterable


class SandboxError(Exception):
    """Base class of every error the sandbox reports to a user (CLI exit code 2).

    The message speaks English to the command line; ``french`` is the same refusal in the
    web page's words, written where the check is made (None: the page says a general
    refusal and the server logs the English).
    """

    exit_code = 2

    def __init__(self, *args: object, french: str | None = None) -> None:
        super().__init__(*args)
        self.french = french


class UnknownScene(SandboxError):
    """A scene name that is neither registered nor an existing MJCF file."""


class UnknownParameter(SandboxError):
    """A parameter name the scene does not declare."""


class BadParameter(SandboxError):
    """A parameter value that is not a number or lies outside its range."""


class BadOption(SandboxError):
    """A simulation option (duration, timestep, integrator, rate, output) that cannot be used."""


class BadModel(SandboxError):
    """An MJCF file that cannot be read or compiled."""


class Diverged(SandboxError):
    """The simulation blew up (NaN/Inf or MuJoCo's BADQACC warning): exit code 3."""

    exit_code = 3

    def __init__(self, time: float, detail: str) -> None:
        self.time = time
        super().__init__(
            f"simulation diverged at t = {time:.6g} s ({detail}); "
            "try a smaller --timestep or another --integrator (rk4 or implicitfast)"
        )


INTERRUPTED = 130
"""Exit code of a command stopped by Ctrl-C (128 + SIGINT), as shells report it."""


def choices(names: Iterable[str]) -> str:
    """Format valid names for an error message: 'a, b, c'."""
    return ", ".join(sorted(names))


SHOWN_CHARS = 60
"""Longest repr of a user's value quoted in a message (a 5,000-character name is cut)."""


def shown(value: object, limit: int = SHOWN_CHARS) -> str:
    """``repr`` of a user's text (str of anything else, e.g. a Path) for a one-line message.

    Control characters come out escaped ('\\n', '\\x00'); beyond ``limit`` characters
    the repr is cut and says how long the text was: ``'aaaa...' (5000 characters)``.
    """
    text = value if isinstance(value, str) else str(value)
    quoted = repr(text)
    if len(quoted) <= limit:
        return quoted
    return f"{quoted[: limit - 4]}...{quoted[0]} ({len(text)} characters)"


def one_line(message: str) -> str:
    """A message on one line: line breaks become spaces, blank lines vanish."""
    return " ".join(part.strip() for part in message.splitlines() if part.strip())
