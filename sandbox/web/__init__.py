"""The web layer: viser app, sessions, renderer and panels (it shows; it computes no physics).

Sub-packages by role, lowest first; each imports only its own and those before it
(tests/test_layers.py checks it): :mod:`.client` (safe text, French controls, viser
patches) -> :mod:`.view3d` (the 3D view) -> :mod:`.loop` (one browser's simulation loop,
no viser) -> :mod:`.panels` (the page's folders) -> :mod:`.video` -> :mod:`.page` (viser's
client in French, access, layout) -> :mod:`.views` (what one browser sees) ->
:mod:`.serving` (servers, class, follow mode, workers) -> :mod:`.replay`.

It serves scenes by name, so it loads the registry, which passes itself down to physics
(:func:`sandbox.physics.model.register_scenes`).
"""

import sandbox.scenes  # noqa: F401
