"""The preset dropdown of the « Tracé X–Y » and « Étude paramétrique » folders."""

from __future__ import annotations

import viser
from conftest import free_port

from sandbox.web.panels.preset_picker import FREE, PresetPicker


def test_the_picker_lists_the_presets_then_free_choice_and_escapes_its_hint():
    server = viser.ViserServer(port=free_port(), verbose=False)
    try:
        picker = PresetPicker(
            server.gui,
            "Tracé proposé",
            ("Palier A selon ω", "Au cours du temps"),
            first="Au cours du temps",
            hint="Des tracés du cours",
            shown="ω < 10 <b>",
        )
        assert picker.dropdown.options == ("Palier A selon ω", "Au cours du temps", FREE)
        assert picker.dropdown.value == "Au cours du temps"
        assert picker.hint.content == "ω &lt; 10 &lt;b&gt;"  # a scene's text, escaped
        picker.show("La parabole en ω²")
        assert picker.hint.content == "La parabole en ω²"
        picker.free()  # a field changed by hand: no preset any more
        assert (picker.dropdown.value, picker.hint.content) == (FREE, "")
        none = PresetPicker(server.gui, "Étude proposée", (), first=None, hint="")
        assert none.dropdown.options == (FREE,) and none.dropdown.value == FREE
    finally:
        server.stop()
