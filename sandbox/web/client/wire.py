"""Sending what moved, one small viser message per change, straight to viser's queue.

viser's handle setters (``node.position = ...``) cast every value through the props'
type hints and compare it with ``np.allclose``: about 40 µs each, and a drawn frame used
to make dozens. The views keep their own last-sent values and call these functions only
for real changes, so here viser's own messages are queued directly (about 8 µs each) and
the handle's cached value is kept in step, so that a later public setter still compares
with what the browser shows. The internals used (in :mod:`.viser_internals`) are checked
once (:data:`FAST`); a viser without them gets the public setters.

Importing this module also caps what browsers may upload (:func:`uploads.install`) and
keeps viser's "a message is waiting" events in their loop (:func:`wakeups.install`): every
page module sends through here, so both are in place before any server exists.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from sandbox.web.client import uploads, viser_internals, wakeups
from sandbox.web.client.patches import internals_present

uploads.install()  # before any viser GUI exists: viser binds its handlers then
wakeups.install()  # before any message buffer exists: each gets its event then


FAST = internals_present(
    viser_internals.has_fast_poses,
    "this viser lacks the internals of the fast path: poses use its setters",
)
"""viser's internals are there: messages are queued directly."""


def _state(node: Any) -> Any:
    """The node's internal state; None for a node without one (a stand-in of the tests),
    which then gets the public setters."""
    return viser_internals.node_state(node) if FAST else None


def set_position(node: Any, xyz: np.ndarray) -> None:
    """Move ``node`` to ``xyz`` [m] in its parent's frame (3 finite numbers)."""
    impl = _state(node)
    if impl is None:
        node.position = xyz
        return
    if impl.removed:  # nothing more is sent for a removed node
        return
    value = (float(xyz[0]), float(xyz[1]), float(xyz[2]))
    impl.position[:] = value
    viser_internals.queue_scene_message(
        impl, viser_internals.messages.SetPositionMessage(impl.name, value)
    )


def set_orientation(node: Any, wxyz: np.ndarray) -> None:
    """Turn ``node`` to the unit quaternion ``wxyz`` in its parent's frame."""
    impl = _state(node)
    if impl is None:
        node.wxyz = wxyz
        return
    if impl.removed:
        return
    value = (float(wxyz[0]), float(wxyz[1]), float(wxyz[2]), float(wxyz[3]))
    impl.wxyz[:] = value
    viser_internals.queue_scene_message(
        impl, viser_internals.messages.SetOrientationMessage(impl.name, value)
    )


def set_props(node: Any, **props: Any) -> None:
    """Set props of ``node`` (arrays already of the prop's dtype and shape) in one message."""
    impl = _state(node)
    if impl is None:
        for name, value in props.items():
            setattr(node, name, value)
        return
    if impl.removed:
        return
    queued = {}
    for name, value in props.items():
        kept = value.copy() if isinstance(value, np.ndarray) else value
        setattr(impl.props, name, kept)
        queued[name] = value.copy() if isinstance(value, np.ndarray) else value
    viser_internals.queue_scene_message(
        impl, viser_internals.messages.SceneNodeUpdateMessage(impl.name, queued)
    )


def sent_marks(client: Any) -> tuple[int, int] | None:
    """(last message queued for a browser, last one its sender has taken), as viser's
    message ids; None when this viser does not tell. A view compares the mark of a frame
    it queued with the second number to know whether that frame went out."""
    return viser_internals.sent_marks(client)
