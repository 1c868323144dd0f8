"""Folder "Affichage": slow motion, a "Pas" of an angle or a time, a camera that follows
the moving object, the arrows' scale; and what the 3D view marks besides the geoms (the
typed reduction point P, the rotor's masses labelled with their angle).

Callbacks queue requests (speed, "Pas") or set a flag the loop thread reads (follow,
arrow scale); :meth:`DisplayPanel.draw` runs on every drawn frame, :meth:`refresh` at the
panel rate.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from typing import TYPE_CHECKING, Any

import mujoco
import numpy as np

from sandbox.physics.display import main_joint
from sandbox.physics.picture import Picture
from sandbox.web.client.text import number
from sandbox.web.loop import SPEEDS
from sandbox.web.loop.requests import Advance, Speed
from sandbox.web.loop.state import SessionState
from sandbox.web.view3d.arrows import USER_SCALES, ArrowLayer
from sandbox.web.view3d.geoms import MARKER, mechanism_size
from sandbox.web.view3d.renderer import SceneRenderer

if TYPE_CHECKING:
    import viser

FOLDER = "Affichage"

SLOW_MOTION = (1.0, 0.5, 0.2, 0.1, 0.05, 0.02, 0.01)
"""Speed factors offered by "Ralenti" (×0.01 turns a 6000 rpm rotor 6° a frame)."""

UNIT_ANGLE, UNIT_TIME = "degrés", "secondes"
STEP_UNITS = {UNIT_ANGLE: "deg", UNIT_TIME: "s"}

STEP_BUTTON = "Avancer d'un pas"

FOLLOW_LABEL = "Suivre l'objet"

Point = Callable[[], tuple[np.ndarray, str]]
"""The reduction point chosen in the torsors' folder: world position [m] and name."""


def speed_label(speed: float) -> str:
    """A "Ralenti" choice as the page writes it ("×0,01", "×1 (temps réel)")."""
    return "×1 (temps réel)" if speed == 1.0 else f"×{number(speed, 3)}"


def followed_body(model: mujoco.MjModel, *, slides: bool = True) -> int:
    """The body a camera can follow: the one with the most translation joints (a free
    joint counts three, a slide one), the first such; -1 if none (a mechanism on fixed
    pivots stays in view).

    Args:
        model: Compiled model.
        slides: Count slide joints (a registered scene whose motion leaves the view, such
            as a cylinder rolling on slides x and z); False: free joints only.
    """
    best, most = -1, 0
    for b in range(model.nbody):
        count = 0
        for j in range(int(model.body_jntadr[b]), int(model.body_jntadr[b] + model.body_jntnum[b])):
            kind = int(model.jnt_type[j])
            if kind == int(mujoco.mjtJoint.mjJNT_FREE):
                count += 3
            elif slides and kind == int(mujoco.mjtJoint.mjJNT_SLIDE):
                count += 1
        if count > most:
            best, most = b, count
    return best


def marker_angle(model: mujoco.MjModel, geom: int) -> float | None:
    """Angle [deg] of a geom about the hinge of its body, measured in the body's frame
    from the axis after the hinge's (y for a hinge along x, z for y, x for z) towards the
    next one: the rotor's "angle from y1 towards z1". None when its body has no hinge."""
    body = int(model.geom_bodyid[geom])
    if int(model.body_jntnum[body]) != 1:
        return None
    j = int(model.body_jntadr[body])
    if int(model.jnt_type[j]) != int(mujoco.mjtJoint.mjJNT_HINGE):
        return None
    i = int(np.argmax(np.abs(model.jnt_axis[j])))
    pos = np.asarray(model.geom_pos[geom], dtype=float)
    u, v = pos[(i + 1) % 3], pos[(i + 2) % 3]
    if math.hypot(u, v) < 1e-9:
        return None
    return math.degrees(math.atan2(v, u))


def markers(model: mujoco.MjModel) -> list[int]:
    """Geoms the view labels with their angle: visible spheres on a hinged body (point
    masses such as a rotor's defect and correction masses)."""
    out = []
    for g in range(model.ngeom):
        if int(model.geom_type[g]) != int(mujoco.mjtGeom.mjGEOM_SPHERE):
            continue
        if float(model.geom_rgba[g][3]) <= 0 or int(model.geom_group[g]) >= 3:
            continue
        if marker_angle(model, g) is not None:
            out.append(g)
    return out


def marker_text(model: mujoco.MjModel, geom: int, words: Mapping[str, str]) -> str:
    """The label of a marker: the scene's words for it, then its angle ("m₁ : 180°")."""
    angle = marker_angle(model, geom)
    shown = f"{number(angle if angle is not None else math.nan, 3)}°"
    name = mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_GEOM, geom) or ""
    said = words.get(name, "")
    return f"{said} : {shown}" if said else f"à {shown}"


class DisplayPanel:
    """Folder "Affichage" of a live session, and the marks it adds to the 3D view.

    Args:
        gui: A viser ``GuiApi`` (``client.gui``).
        controller: The session's controller (speed and "Pas" requests go to its queue).
        scene: The client's ``SceneApi`` for the point P (None: not drawn).
        renderer: The view's renderer, which carries the masses' labels on the moving
            geoms (None: no labels).
        camera: The client's camera, moved by "Suivre l'objet" (None: no such box).
        arrows: The view's arrow layer, whose lengths "Échelle des flèches" scales.
        point: The reduction point chosen in the torsors' folder (drawn when typed: P).
    """

    def __init__(
        self,
        gui: viser.GuiApi,
        controller: SessionState,
        *,
        scene: viser.SceneApi | None = None,
        renderer: SceneRenderer | None = None,
        camera: viser.CameraHandle | None = None,
        arrows: ArrowLayer | None = None,
        point: Point | None = None,
    ) -> None:
        self.controller = controller
        self.scene = scene
        self.renderer = renderer
        self.camera = camera
        self.arrows = arrows
        self.point = point
        sim = controller.sim
        model = sim.model
        spec = sim.scene
        self.words: Mapping[str, str] = spec.page.names.markers if spec is not None else {}
        self.size = mechanism_size(model, sim.data)
        # A registered scene says whether its motion leaves the view; any file's free
        # body can. The camera follows it on request (each browser's camera moved every
        # frame costs the class its frame rate: Scene.page.leaves_view).
        leaves = spec is None or spec.page.leaves_view
        self.body = (
            followed_body(model, slides=spec is not None) if camera is not None and leaves else -1
        )
        self.following = False
        submit = controller.submit
        turning = main_joint(model, sim.data) is not None
        with gui.add_folder(FOLDER, expand_by_default=False) as self.folder:
            self.slow = gui.add_dropdown(
                "Ralenti",
                tuple(speed_label(s) for s in SLOW_MOTION if SPEEDS[0] <= s <= SPEEDS[1]),
                initial_value=speed_label(1.0),
                hint="Ralentit le mouvement affiché : à ×0,01, une seconde à l'écran montre "
                "un centième de seconde simulée (un rotor à 6000 tr/min y tourne lentement)",
            )
            self.slow.on_update(self._on_slow)
            self.step_value = gui.add_number(
                "Pas",
                10.0 if turning else 0.01,
                min=0.0,
                step=0.001,
                hint="Longueur d'un pas : un angle de la pièce qui tourne le plus vite, "
                "ou une durée simulée",
            )
            self.step_unit = gui.add_dropdown(
                "Unité du pas",
                (UNIT_ANGLE, UNIT_TIME) if turning else (UNIT_TIME, UNIT_ANGLE),
                initial_value=UNIT_ANGLE if turning else UNIT_TIME,
                hint="Degrés : la manivelle ou le rotor tourne de cet angle ; secondes : "
                "le temps simulé avance de cette durée",
            )
            self.step = gui.add_button(
                STEP_BUTTON, hint="Met en pause et avance le mouvement d'un pas"
            )
            self.step.on_click(lambda _: submit(self.step_request()))
            self.follow: viser.GuiCheckboxHandle | None = None
            if self.body >= 0:
                self.follow = gui.add_checkbox(
                    FOLLOW_LABEL,
                    self.following,
                    hint="La caméra accompagne le solide qui se déplace (il reste au "
                    "centre de la vue)",
                )
                self.follow.on_update(self._on_follow)
            self.scale: viser.GuiSliderHandle[float] | None = None
            if arrows is not None:
                self.scale = gui.add_slider(
                    "Échelle des flèches",
                    min=USER_SCALES[0],
                    max=USER_SCALES[1],
                    step=0.05,
                    initial_value=1.0,
                    hint="Multiplie la longueur des flèches (leur longueur s'adapte déjà "
                    "pour rester dans la vue ; l'étiquette donne la valeur)",
                )
                self.scale.on_update(self._on_scale)
        self._speed_shown = 1.0
        self._marks: dict[int, str] = {}  # geom -> words of its label
        self._marks_model: mujoco.MjModel | None = None
        self._point: tuple[viser.SceneNodeHandle, viser.LabelHandle] | None = None

    # -- callbacks (viser's thread) ------------------------------------------------------
    def step_request(self) -> Advance:
        """The command of one "Pas" as the folder sets it (the time bar's "Pas" may use
        it too)."""
        unit = STEP_UNITS.get(str(self.step_unit.value), str(self.step_unit.value))
        return Advance(self.step_value.value, unit)

    def _on_slow(self, event: viser.GuiEvent[Any]) -> None:
        if event.client is None or self.slow.disabled:  # locked by a shared link
            return
        choices = {speed_label(s): s for s in SLOW_MOTION}
        value = event.target.value
        self.controller.submit(Speed(choices.get(value, value)))

    def _on_follow(self, event: viser.GuiEvent[Any]) -> None:
        if event.client is not None:
            self.following = bool(event.target.value)

    def _on_scale(self, event: viser.GuiEvent[Any]) -> None:
        if event.client is not None and self.arrows is not None:
            try:
                self.arrows.set_scale(float(event.target.value))
            except (TypeError, ValueError):
                return

    # -- loop thread ---------------------------------------------------------------------
    def draw(self, picture: Picture) -> None:
        """On every drawn frame: the camera follows the object; on a new model, the
        masses' labels (which ride on the rotor: no message a frame)."""
        if self.following and self.camera is not None and 0 <= self.body < len(picture.body_xpos):
            self._follow(np.asarray(picture.body_xpos[self.body], dtype=float))
        if self._marks_model is not picture.model:
            self._rebuild_marks(picture.model)

    def _follow(self, target: np.ndarray) -> None:
        camera = self.camera
        if camera is None or not np.isfinite(target).all():
            return
        try:
            delta = target - np.asarray(camera.look_at, dtype=float)
            if float(np.linalg.norm(delta)) > 1e-4 * self.size:
                camera.position = np.asarray(camera.position, dtype=float) + delta
        except (AssertionError, ValueError):  # the browser has not sent its camera yet
            return

    def _rebuild_marks(self, model: mujoco.MjModel) -> None:
        self._marks_model = model
        if self.renderer is None:
            return
        self._marks = {g: marker_text(model, g, self.words) for g in markers(model)}
        self.renderer.label_geoms(self._marks)

    def refresh(self) -> None:
        """At the panel rate: "Ralenti" shows the speed in force; the typed point P."""
        speed = float(self.controller.speed)
        if speed != self._speed_shown:
            self._speed_shown = speed
            label = speed_label(speed)
            if label in self.slow.options and self.slow.value != label:
                self.slow.value = label  # type: ignore[misc]
        self._draw_point()

    def _draw_point(self) -> None:
        if self.point is None or self.scene is None:
            return
        try:
            xyz, name = self.point()
        except Exception:  # a panel being rebuilt: try again next refresh
            return
        show = name == "P" and bool(np.isfinite(xyz).all())
        if self._point is None:
            if not show:
                return
            radius = MARKER * self.size
            self._point = (
                self.scene.add_icosphere("/marks/P", radius=radius, color=(20, 20, 20)),
                self.scene.add_label(
                    "/marks/P_label", "P", anchor="bottom-left", font_screen_scale=1.0
                ),
            )
        dot, label = self._point
        if show:
            dot.position = xyz
            label.position = xyz + np.array([0.0, 0.0, 1.5 * MARKER * self.size])
        if dot.visible != show:
            dot.visible = label.visible = show
