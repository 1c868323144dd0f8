"""The web layer: viser app, sessions, renderer and panels (it shows; it computes no physics).

It serves scenes by name, so it loads the registry, which passes itself down to physics
(:func:`sandbox.physics.model.register_scenes`).
"""

import sandbox.scenes  # noqa: F401
