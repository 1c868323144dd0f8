"""The web layer: viser app, sessions, renderer and panels (it shows; it computes no physics).

Sub-packages by role, lowest first; each imports only its own and those before it
(tests/test_layers.py checks it): :mod:`.client` (safe text, French controls, viser
patches) -> :mod:`.view3d` (the 3D view) -> :mod:`.loop` (one browser's simulation loop,
no viser) -> :mod:`.panels` (the page's folders) -> :mod:`.video` -> :mod:`.page` (viser's
client in French, access, layout) -> :mod:`.views` (what one browser sees) ->
:mod:`.serving` (servers, class, follow mode, workers) -> :mod:`.replay`.

A scene named by a user is resolved by :func:`sandbox.scenes.resolve` where the name
arrives (the server's start, follow mode, a study).
"""
