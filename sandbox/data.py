"""Locate the MJCF scenes and lesson files, in a checkout or in an installed wheel."""

from __future__ import annotations

from pathlib import Path

_PACKAGE = Path(__file__).resolve().parent


def data_dir(kind: str) -> Path:
    """Folder holding ``kind`` ("scenes" or "lessons").

    An installed wheel ships them as ``sandbox/_data/<kind>``; a checkout (editable
    install or tests) uses the top-level folder next to the package.
    """
    for candidate in (_PACKAGE / "_data" / kind, _PACKAGE.parent / kind):
        if candidate.is_dir():
            return candidate
    raise FileNotFoundError(f"cannot find the {kind!r} folder next to {_PACKAGE}")
