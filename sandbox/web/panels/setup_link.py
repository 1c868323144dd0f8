"""A page's setup written in its address, so that a teacher can hand it out as a link.

The link is the page's own address followed by a fragment (after ``#``)::

    http://salle-b12:8080/#v=1&speed_rpm=1500&mass1_g=0&open=affichage&hide=mass2_g&lock=speed_rpm&lesson=equilibrage&step=2

A fragment, not a query: browsers never send it in an HTTP request, so proxies, caches
and access logs never see it, and the page itself is the same file for every setup. The
page's script hands it to the server when its websocket opens
(:mod:`sandbox.web.page.link`).

The fragment is untrusted (anyone can type or forward one), so it is read in two steps,
neither of which ever raises:

1. :func:`parse` reads its syntax: at most :data:`MAX_CHARS` characters and
   :data:`MAX_PARTS` parts ``name=value``, names of at most :data:`MAX_NAME` characters
   among ``[A-Za-z0-9_]``, values of at most :data:`MAX_VALUE` characters of UTF-8 without
   control characters; a repeated name keeps its first value.
2. :func:`validate` checks each part against what this page has: the scene's parameters
   (by their CLI names, a contract) and the same checks as the page's controls
   (``Simulation.check_value``, ``check_integrator`` and :func:`sandbox.web.loop.check_speed`,
   ``check_timestep``), the folders that can be opened, the lessons of the scene and
   their number of steps.

Every part refused by either step is kept, with the reason, as an :class:`Ignored`;
:func:`refusal_line` says them all in one French line (the page shows it), and the rest
of the link is applied. :func:`build` writes a :class:`Setup` back as a fragment
(``parse`` then ``validate`` of it gives the same setup back).

Names of the fragment (version 1):

- ``v``: the format's version, 1 (a link without it is read as version 1; another
  version is refused whole);
- a parameter's name (``speed_rpm``): its value, a number written with a point;
- ``speed`` (speed factor ×), ``integrator`` (its CLI name), ``timestep`` (seconds);
- ``open``: folders to open, by their :func:`slug` (``affichage``, ``torseurs``),
  comma-separated;
- ``hide``, ``lock``: controls hidden, or shown but locked, for the student: parameter
  names, ``speed``, ``integrator``, ``timestep``, comma-separated;
- ``lesson``: the lesson's name; ``step``: its step, from 1 (as the page numbers them).
"""

from __future__ import annotations

import math
import re
import unicodedata
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from urllib.parse import quote, unquote

from sandbox.errors import SandboxError
from sandbox.physics.model import check_integrator
from sandbox.physics.readonly import ReadOnlySimulation
from sandbox.physics.spec import Param
from sandbox.web.loop import Refused, check_speed, check_timestep, french_message, shown_value

VERSION = 1
"""The fragment's format (``v=1``); a link of another version is refused whole."""

MAX_CHARS = 2000
"""Longest fragment read [characters]; a longer one is refused whole (a rotor's full
setup takes about 200)."""

MAX_PARTS = 64
"""Most ``name=value`` parts read; the next ones are refused."""

MAX_NAME = 40
"""Longest part name [characters]."""

MAX_VALUE = 200
"""Longest part value [characters, once decoded]."""

MAX_LIST = 32
"""Most items of a comma-separated value (``open``, ``hide``, ``lock``)."""

MAX_NUMBER = 32
"""Longest number [characters]."""

MAX_LISTED = 4
"""Refused parts named in :func:`refusal_line`; the others are counted."""

SETTINGS = ("speed", "integrator", "timestep")
"""Names of the simulation's own settings (the CLI's ``--integrator``, ``--timestep``);
a scene's parameters never take these names, nor those of :data:`RESERVED`."""

RESERVED = ("v", "open", "hide", "lock", "lesson", "step", *SETTINGS)
"""Names that are not a scene parameter."""

_NAME = re.compile(r"[A-Za-z][A-Za-z0-9_]*")
_NUMBER = re.compile(r"[+-]?(\d+\.?\d*|\.\d+)([eE][+-]?\d{1,3})?")
_CONTROL = re.compile(r"[\x00-\x1f\x7f-\x9f\u2028\u2029]")


@dataclass(frozen=True)
class Ignored:
    """A part of a link that was not applied.

    Attributes:
        part: The part as the link wrote it (untrusted: shown through
            :func:`sandbox.web.loop.shown_value`).
        why: Why, in French.
    """

    part: str
    why: str


@dataclass(frozen=True)
class Setup:
    """What a link sets, every part checked.

    Attributes:
        settings: (name, value) in the link's order: a parameter's value, ``speed``,
            ``timestep`` (floats) or ``integrator`` (its CLI name).
        open: Folders opened (their :func:`slug`).
        hide: Controls hidden for the student (names as in ``settings``).
        lock: Controls shown but locked (never also in ``hide``).
        lesson: Lesson opened (None: the page's own).
        step: Step of that lesson, from 1 (None: its first).
    """

    settings: tuple[tuple[str, float | str], ...] = ()
    open: tuple[str, ...] = ()
    hide: tuple[str, ...] = ()
    lock: tuple[str, ...] = ()
    lesson: str | None = None
    step: int | None = None

    @property
    def empty(self) -> bool:
        """True when the link sets nothing."""
        return self == Setup()


@dataclass(frozen=True)
class Page:
    """What a page offers, against which a link is checked.

    Attributes:
        params: The scene's parameters by name (none for an MJCF file).
        check: Checks a setting (parameter, ``speed``, ``integrator``, ``timestep``) as
            the page's control does: returns the value to apply, raises a
            :class:`~sandbox.errors.SandboxError` with a French message otherwise.
        folders: Folders that can be opened: slug -> French label.
        lessons: Lessons of the scene: name -> number of steps.
        lesson: The lesson the page opens by itself (``sandbox serve LESSON``), if any.
    """

    params: Mapping[str, Param]
    check: Callable[[str, object], float | str]
    folders: Mapping[str, str] = field(default_factory=dict)
    lessons: Mapping[str, int] = field(default_factory=dict)
    lesson: str | None = None

    @property
    def controls(self) -> tuple[str, ...]:
        """Names that ``hide`` and ``lock`` accept."""
        return (*self.params, *SETTINGS)


def slug(label: str) -> str:
    """A folder's label as a link names it: lower case, no accents, words joined by
    ``-`` ("Réglages avancés" -> ``reglages-avances``). The page's script computes the
    same (:mod:`sandbox.web.page.link`)."""
    text = re.sub(r"[\u0300-\u036f]", "", unicodedata.normalize("NFD", label)).lower()
    return re.sub(r"[^a-z0-9]+", "-", text).strip("-")


def page_of(
    sim: ReadOnlySimulation,
    *,
    folders: Sequence[str] = (),
    lessons: Mapping[str, int] | None = None,
    lesson: str | None = None,
) -> Page:
    """The :class:`Page` of a session: its simulation's parameters and checks.

    Args:
        sim: The session's simulation.
        folders: Labels of the folders a link may open.
        lessons: Lessons of the scene (name -> number of steps).
        lesson: The lesson the page opens by itself.
    """
    scene = sim.scene
    params = {p.name: p for p in scene.params} if scene is not None else {}

    def check(name: str, value: object) -> float | str:
        if name == "speed":
            return check_speed(value)
        if name == "integrator":
            check_integrator(value)
            return str(value)
        if name == "timestep":
            return check_timestep(sim, value)
        return sim.check_value(name, value)  # a dropdown's index: a whole value

    return Page(
        params=params,
        check=check,
        folders={slug(f): f for f in folders},
        lessons=dict(lessons or {}),
        lesson=lesson,
    )


# -- reading -----------------------------------------------------------------------------
def parse(fragment: object) -> tuple[list[tuple[str, str]], list[Ignored]]:
    """The ``name=value`` parts of a fragment (with or without its ``#``), decoded, and
    the parts refused for their syntax (never raises).

    Returns:
        The parts kept, in order (each name once), and those refused.
    """
    if not isinstance(fragment, str):
        return [], [Ignored(shown_value(fragment), "lien illisible")]
    text = fragment[1:] if fragment.startswith("#") else fragment
    if len(text) > MAX_CHARS:
        return [], [Ignored(text[:20], f"lien entier, plus de {MAX_CHARS} caractères")]
    kept: list[tuple[str, str]] = []
    ignored: list[Ignored] = []
    seen: set[str] = set()
    parts = [p for p in text.split("&") if p]
    for part in parts[MAX_PARTS:]:
        ignored.append(Ignored(part, f"au-delà de {MAX_PARTS} réglages"))
    for part in parts[:MAX_PARTS]:
        raw_name, equal, raw_value = part.partition("=")
        try:
            name = unquote(raw_name, errors="strict")
            value = unquote(raw_value, errors="strict")
        except UnicodeDecodeError:
            ignored.append(Ignored(part, "caractères illisibles"))
            continue
        if not equal:
            ignored.append(Ignored(part, "pas de la forme nom=valeur"))
        elif len(name) > MAX_NAME or not _NAME.fullmatch(name):
            ignored.append(Ignored(part, "nom de réglage invalide"))
        elif len(value) > MAX_VALUE or _CONTROL.search(value):
            ignored.append(Ignored(part, "valeur trop longue ou illisible"))
        elif name in seen:
            ignored.append(Ignored(part, "réglage en double, le premier est gardé"))
        else:
            seen.add(name)
            kept.append((name, value))
    return kept, ignored


def validate(parts: Sequence[tuple[str, str]], page: Page) -> tuple[Setup, list[Ignored]]:
    """The :class:`Setup` of parsed parts, each checked against ``page``; the parts
    refused, with their French reason (never raises)."""
    ignored: list[Ignored] = []
    found = dict(parts)
    version = found.get("v", str(VERSION))
    if version != str(VERSION):
        return Setup(), [Ignored(f"v={version}", f"version de lien inconnue (seule {VERSION})")]
    settings: list[tuple[str, float | str]] = []
    for name, value in parts:
        if name in RESERVED and name not in SETTINGS:
            continue
        if name not in page.params and name not in SETTINGS:
            ignored.append(Ignored(f"{name}={value}", _unknown(page)))
            continue
        try:
            settings.append((name, _setting(page, name, value)))
        except SandboxError as exc:
            ignored.append(Ignored(f"{name}={value}", _reason(exc)))
    opened = _names(found, "open", page.folders, "dossier inconnu", ignored)
    hide = _names(found, "hide", page.controls, "réglage inconnu", ignored)
    lock = _names(found, "lock", page.controls, "réglage inconnu", ignored)
    lesson, step = _lesson(found, page, ignored)
    setup = Setup(
        settings=tuple(settings),
        open=opened,
        hide=hide,
        lock=tuple(n for n in lock if n not in hide),
        lesson=lesson,
        step=step,
    )
    return setup, ignored


def read(fragment: object, page: Page) -> tuple[Setup, list[Ignored]]:
    """:func:`parse` then :func:`validate` (never raises)."""
    parts, ignored = parse(fragment)
    setup, refused = validate(parts, page)
    return setup, ignored + refused


def _setting(page: Page, name: str, value: str) -> float | str:
    """A setting's checked value (SandboxError with the French reason otherwise)."""
    if name == "integrator":
        return page.check(name, value)
    if len(value) > MAX_NUMBER or not _NUMBER.fullmatch(value):
        raise Refused("un nombre écrit avec un point est attendu")
    number = float(value)
    if not math.isfinite(number):
        raise Refused("un nombre fini est attendu")
    return page.check(name, number)


def _reason(exc: SandboxError) -> str:
    """A refusal's French message without its final period (it sits in a list)."""
    return french_message(exc).strip().rstrip(".")


def _unknown(page: Page) -> str:
    return "paramètre inconnu de cette scène" if page.params else "ce modèle n'a pas de paramètre"


def _names(
    found: Mapping[str, str],
    key: str,
    known: Mapping[str, str] | Sequence[str],
    why: str,
    ignored: list[Ignored],
) -> tuple[str, ...]:
    """The known items of the comma-separated value of ``key`` (each once)."""
    value = found.get(key)
    if value is None:
        return ()
    items = [item for item in value.split(",") if item]
    out: list[str] = []
    for item in items[MAX_LIST:]:
        ignored.append(Ignored(f"{key}={item}", f"au-delà de {MAX_LIST} noms"))
    for item in items[:MAX_LIST]:
        name = slug(item) if key == "open" else item
        if name not in known:
            ignored.append(Ignored(f"{key}={item}", why))
        elif name not in out:
            out.append(name)
    return tuple(out)


def _lesson(
    found: Mapping[str, str], page: Page, ignored: list[Ignored]
) -> tuple[str | None, int | None]:
    lesson = found.get("lesson")
    if lesson is not None and lesson not in page.lessons:
        ignored.append(Ignored(f"lesson={lesson}", "leçon inconnue pour cette scène"))
        lesson = None
    raw = found.get("step")
    if raw is None:
        return lesson, None
    followed = lesson or page.lesson
    if followed is None or followed not in page.lessons:
        ignored.append(Ignored(f"step={raw}", "aucune leçon ouverte"))
        return lesson, None
    count = page.lessons[followed]
    if not (raw.isascii() and raw.isdigit() and len(raw) <= 3 and 1 <= int(raw) <= count):
        ignored.append(Ignored(f"step={raw}", f"étape de 1 à {count} attendue"))
        return lesson, None
    return lesson, int(raw)


def refusal_line(ignored: Sequence[Ignored]) -> str:
    """The refused parts of a link in one French line ("" when none): the first
    :data:`MAX_LISTED`, quoted and cut short, then how many others."""
    if not ignored:
        return ""
    shown = [f"« {shown_value(i.part, 40)} » ({i.why})" for i in ignored[:MAX_LISTED]]
    more = len(ignored) - MAX_LISTED
    tail = f" ; et {more} autre{'s' if more > 1 else ''}" if more > 0 else ""
    what = "Partie du lien ignorée" if len(ignored) == 1 else "Parties du lien ignorées"
    return f"{what} : {' ; '.join(shown)}{tail}. Le reste du lien est appliqué."


# -- writing -----------------------------------------------------------------------------
def number_text(value: float) -> str:
    """A number as a link writes it: the shortest text that reads back as the same float,
    with a point (``1500``, ``0.25``, ``2e-05``)."""
    text = repr(float(value))
    return text[:-2] if text.endswith(".0") else text


def build(setup: Setup) -> str:
    """The fragment of ``setup`` (without its ``#``), starting with ``v=1``."""
    parts = [f"v={VERSION}"]
    for name, value in setup.settings:
        shown = value if isinstance(value, str) else number_text(value)
        parts.append(f"{name}={_quote(shown)}")
    for key, items in (("open", setup.open), ("hide", setup.hide), ("lock", setup.lock)):
        if items:
            parts.append(f"{key}={','.join(_quote(i) for i in items)}")
    if setup.lesson is not None:
        parts.append(f"lesson={_quote(setup.lesson)}")
    if setup.step is not None:
        parts.append(f"step={setup.step}")
    return "&".join(parts)


def link(base: str, setup: Setup) -> str:
    """The address of ``setup`` on the page ``base`` (its origin and path)."""
    return f"{base.partition('#')[0]}#{build(setup)}"


def _quote(text: str) -> str:
    return quote(text, safe="-._~")
