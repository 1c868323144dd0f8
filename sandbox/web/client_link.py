"""(placeholder: filled by the issue-24 work)"""

from __future__ import annotations


def html() -> str:
    """Elements added to the head of viser's page (none yet)."""
    return ""
