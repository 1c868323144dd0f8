"""The choice among a scene's presets that the « Tracé X–Y » and « Étude paramétrique »
folders open with: a dropdown of the presets' French names plus :data:`FREE`, and under
it the chosen preset's hint (one sentence naming the course's law it shows)."""

from __future__ import annotations

from typing import Any

import viser

from sandbox.web.client.text import html_text

FREE = "Choix libre"
"""The dropdown's last entry: the fields as the user sets them, no preset."""


class PresetPicker:
    """A preset dropdown and its hint, added to ``gui`` where the caller's folder is open.

    Args:
        gui: A viser ``GuiApi``.
        label: The dropdown's French label (« Tracé proposé »).
        presets: The presets' French names, in the scene's order.
        first: The name chosen at the start (None: :data:`FREE`).
        hint: The dropdown's tooltip.
        shown: The hint written under it at the start (plain text, escaped here).
    """

    def __init__(
        self,
        gui: viser.GuiApi,
        label: str,
        presets: tuple[str, ...],
        *,
        first: str | None,
        hint: str,
        shown: str = "",
    ) -> None:
        self.dropdown: viser.GuiDropdownHandle[Any] = gui.add_dropdown(
            label, (*presets, FREE), initial_value=first or FREE, hint=hint
        )
        self.hint = gui.add_markdown(html_text(shown))

    def show(self, words: str) -> None:
        """Write ``words`` (a preset's hint, plain text) under the dropdown."""
        self.hint.content = html_text(words)

    def free(self) -> None:
        """The user changed a field: the form is no preset's any more."""
        self.dropdown.value = FREE  # type: ignore[misc]
        self.hint.content = ""
