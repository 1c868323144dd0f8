"""``sandbox serve`` (and a bare ``sandbox``): the web sandbox on a scene, a lesson (by
name or file) or an MJCF file, in one process or several sharing the port.
"""

from __future__ import annotations

import os
import sys
from collections.abc import Sequence
from pathlib import Path

from sandbox.cli.options import MAX_WORKERS, check_port_range, own_source, pairs
from sandbox.errors import BadOption, choices, shown
from sandbox.lessons import ANY_SCENE, UnknownLesson, catalogue, is_lesson_file, open_lesson_file
from sandbox.scenes import DEFAULT_SCENE, SCENES

LESSON_PREFIX = "lesson:"
"""``sandbox serve lesson:NAME`` opens the lesson NAME even when a scene has that name."""


def cmd_serve(
    target: str | None,
    host: str,
    port: int,
    sets: Sequence[str],
    workers: int | None = None,
    follow: bool = False,
    public_url: str | None = None,
    motion: str | None = None,
    max_memory: float | None = None,
) -> int:
    """``sandbox serve``: start the web app (blocks until Ctrl-C).

    ``target`` is a scene name, a lesson name (a scene of the same name wins: write
    ``lesson:NAME`` for the lesson), the path of a lesson file (``*.md``, parsed and
    validated here: its errors are one line) or the path of an MJCF file."""
    # viser (a second, 20 MB) only for the web app: 'sandbox --help' stays quick and small
    from sandbox.web.serving.app import serve

    check_port_range(port)
    target = target or DEFAULT_SCENE
    named = target.startswith(LESSON_PREFIX)  # a lesson, even one named like a scene
    name = target.removeprefix(LESSON_PREFIX)
    lesson = None
    scene = None
    if is_lesson_file(name):
        path = Path(name)
        scene = open_lesson_file(path).scene
        lesson = str(path.resolve())  # opened again by each worker process
    # One broken lesson file does not stop the good ones: it is named once here (and listed
    # in the web "Leçon" folder); serving the broken lesson itself is refused with its error.
    good, refused = catalogue()
    for error in refused:
        if lesson is None and (named or name not in SCENES):
            if f"{os.sep}{name}.md:" in f"{os.sep}{error}":
                raise error
        print(f"sandbox: warning: lesson skipped: {error}", file=sys.stderr)
    if lesson is None and named and name not in good:
        raise UnknownLesson(
            f"unknown lesson {shown(name)}; lessons: {choices(good) or 'none'} "
            "(or the path of a lesson file, FILE.md)"
        )
    if lesson is None and (named or name not in SCENES) and name in good:
        lesson = name
        scene = good[name].scene
    if scene is not None:
        target = DEFAULT_SCENE if scene == ANY_SCENE else scene
    if workers is not None and not 1 <= workers <= MAX_WORKERS:
        raise BadOption(f"--workers must be between 1 and {MAX_WORKERS}, got {workers!r}")
    options: dict[str, object] = {"follow": True} if follow else {}
    if motion is not None:
        options["motion"] = motion
    if target not in SCENES:  # the user's own MJCF file: checked, and its size said
        own_source(target, max_memory)
    if max_memory is not None:
        options["max_memory"] = max_memory
    if public_url:
        if not public_url.startswith(("http://", "https://")) or len(public_url) > 200:
            raise BadOption(
                f"--public-url must be an http:// or https:// address, got {public_url[:80]!r}; "
                "e.g. --public-url http://sandbox.lycee.fr"
            )
        options["public_url"] = public_url
    serve(
        target,
        host=host,
        port=port,
        values=pairs(sets),
        lesson=lesson,
        workers=workers,
        **options,
    )
    return 0
