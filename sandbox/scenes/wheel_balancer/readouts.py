"""What the wheel balancer measures: its two bearing forces, the clips it computes from them,
and on the lab bench the accelerometers on the bearings; the readouts and arrows that show
them.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import mujoco
import numpy as np

from sandbox.mechanics.two_planes import clips_from_bearings, split_across_axis, to_complex
from sandbox.mechanics.vectors import cross
from sandbox.physics.page import Arrow, Bearing
from sandbox.physics.snapshot import Snapshot
from sandbox.physics.spec import SceneReadout
from sandbox.physics.torsors import dynamic_torsor
from sandbox.scenes import bearings
from sandbox.scenes.wheel_balancer.params import CLIP_RADIUS, X_A, X_B, X_INNER, X_OUTER, soft

WHEEL_BODIES = ("wheel", "rim", "tyre")


def _shaft_action(s: Snapshot) -> tuple[np.ndarray, np.ndarray]:
    """Action (R, M_O) of the bearings on the turning wheel: the frame's action on rigid
    bearings; on soft ones, the housing's, i.e. the wheel's dynamic torsor {D}."""
    if not soft(s.values):
        return s.support
    cached = s.cache.get("wheel_dyn")
    if cached is None:
        bodies = [s.body_id(b) for b in WHEEL_BODIES]
        cached = dynamic_torsor(s.model, s.data, bodies, kin=s.kinematics)
        s.cache["wheel_dyn"] = cached
    return cached


def _bearing_points(s: Snapshot) -> tuple[np.ndarray, np.ndarray]:
    sites = s.data.site_xpos
    return (
        sites[mujoco.mj_name2id(s.model, mujoco.mjtObj.mjOBJ_SITE, "sensor_A")],
        sites[mujoco.mj_name2id(s.model, mujoco.mjtObj.mjOBJ_SITE, "sensor_B")],
    )


def _bearings(s: Snapshot) -> tuple[np.ndarray, np.ndarray]:
    """Forces F_A, F_B [N] of the bearings on the wheel, world components."""
    cached = s.cache.get("wheel_bearings")
    if cached is None:
        cached = split_across_axis(*_shaft_action(s), *_bearing_points(s))
        s.cache["wheel_bearings"] = cached
    return cached


def _rotor_frame(s: Snapshot, v: np.ndarray) -> complex:
    """World vector v across the axis as y1 + i z1 components in the wheel frame."""
    rot = s.data.xmat[s.body_id("wheel")].reshape(3, 3)
    return to_complex(rot[:, 1:].T @ v)


MIN_OMEGA = 1.0
"""Below this speed [rad/s] (10 tr/min) the machine does not compute clips (nan); nor on
the soft bench (``supports`` = 1), where its fixed-bearing formula does not hold: the
influence-coefficient method is what that bench offers."""


def machine_clips(s: Snapshot) -> dict[str, float]:
    """What the machine displays, from its measured bearing forces and speed only."""
    cached = s.cache.get("wheel_clips")
    if cached is None:
        w = s.joint_qvel("spin")
        if not abs(w) >= MIN_OMEGA or soft(s.values):  # a soft bench: the machine's
            # formula assumes fixed bearings (issue 21: 96 g for a wheel needing 22 g)
            cached = dict.fromkeys(
                ("clip_inner_g", "clip_inner_deg", "clip_outer_g", "clip_outer_deg"), math.nan
            )
        else:
            f_a, f_b = _bearings(s)
            # P: forces the wheel applies to the bearings (sensors), rotor frame
            p_a, p_b = _rotor_frame(s, -f_a), _rotor_frame(s, -f_b)
            clips = clips_from_bearings(
                p_a,
                p_b,
                x_a=X_A,
                x_b=X_B,
                omega=abs(w),
                x_inner=X_INNER,
                x_outer=X_OUTER,
                radius_inner=CLIP_RADIUS,
                radius_outer=CLIP_RADIUS,
            )
            cached = clips.__dict__.copy()
        s.cache["wheel_clips"] = cached
    return cached


def accelerometer(s: Snapshot, site: str) -> complex:
    """Acceleration [m/s²] of the housing at a bearing, across the axis, in the wheel frame
    (its modulus: amplitude; its argument: phase from the valve)."""
    kin = s.kinematics
    b = s.body_id("cradle")
    p = s.data.site_xpos[mujoco.mj_name2id(s.model, mujoco.mjtObj.mjOBJ_SITE, site)]
    arm = p - s.data.xipos[b]
    w = kin.omega[b]
    a = kin.a_g[b] + cross(kin.alpha[b], arm) + cross(w, cross(w, arm))
    return _rotor_frame(s, a)


def phase(v: complex) -> float:
    """Argument of ``v`` [deg] in [0, 360), counted from the valve (0 for a zero ``v``)."""
    if v == 0:
        return 0.0
    return math.degrees(math.atan2(v.imag, v.real)) % 360.0


def _readout(
    name: str, unit: str, doc: str, fn: Callable[[Snapshot], float], label: str, hint: str
) -> SceneReadout:
    return SceneReadout(name, unit, doc, fn, label=label, hint=hint)


_X0, _Y0, _PLANE = (1.0, 0.0, 0.0), (0.0, 1.0, 0.0), ("y₀", "z₀")
BEARINGS = (
    Bearing("A", "Palier A", lambda s: _bearings(s)[0], _X0, _Y0, _PLANE),
    Bearing("B", "Palier B", lambda s: _bearings(s)[1], _X0, _Y0, _PLANE),
)
"""The machine's bearings: A inside (bearing_inner), B next to the wheel (bearing_outer)."""

READOUTS = (
    _readout(
        "omega", "rad/s", "Rotation speed of the wheel.",
        lambda s: s.joint_qvel("spin"),
        "Vitesse de rotation mesurée ω",
        "Vitesse de rotation de la roue mesurée par la machine.",
    ),
    _readout(
        "bearing_inner", "N", "Force of bearing A (inside the machine), across the axis.",
        lambda s: float(np.linalg.norm(_bearings(s)[0])),
        "Effort du palier intérieur A",
        "Norme de l'effort du palier A, au fond de la machine, sur l'arbre de la roue.",
    ),
    _readout(
        "bearing_outer", "N", "Force of bearing B (next to the wheel), across the axis.",
        lambda s: float(np.linalg.norm(_bearings(s)[1])),
        "Effort du palier extérieur B",
        "Norme de l'effort du palier B, près de la roue, sur l'arbre de la roue.",
    ),
    _readout(
        "clip_inner_g", "g",
        "Inner clip the machine asks for, from its bearing forces (NaN on the soft bench).",
        lambda s: machine_clips(s)["clip_inner_g"],
        "Masselotte intérieure demandée",
        "Masse que la machine demande de sertir sur le bord intérieur de la jante ; « — » sur "
        "le banc à paliers souples, où son calcul pour paliers fixes ne vaut plus.",
    ),
    _readout(
        "clip_inner_deg", "deg", "Angle of the inner clip the machine asks for, from the valve.",
        lambda s: machine_clips(s)["clip_inner_deg"],
        "Angle intérieur demandé",
        "Angle, compté depuis la valve, où la machine demande la masselotte intérieure.",
    ),
    _readout(
        "clip_outer_g", "g",
        "Outer clip the machine asks for, from its bearing forces (NaN on the soft bench).",
        lambda s: machine_clips(s)["clip_outer_g"],
        "Masselotte extérieure demandée",
        "Masse que la machine demande de sertir sur le bord extérieur de la jante ; « — » sur "
        "le banc à paliers souples, où son calcul pour paliers fixes ne vaut plus.",
    ),
    _readout(
        "clip_outer_deg", "deg", "Angle of the outer clip the machine asks for, from the valve.",
        lambda s: machine_clips(s)["clip_outer_deg"],
        "Angle extérieur demandé",
        "Angle, compté depuis la valve, où la machine demande la masselotte extérieure.",
    ),
    _readout(
        "accel_inner", "m/s²", "Vibration amplitude of the housing at bearing A (soft supports).",
        lambda s: abs(accelerometer(s, "sensor_A")),
        "Accélération du palier A",
        "Amplitude de l'accélération du logement du palier A, nulle sur paliers rigides.",
    ),
    _readout(
        "accel_inner_deg", "deg", "Phase of the housing's acceleration at A, from the valve.",
        lambda s: phase(accelerometer(s, "sensor_A")),
        "Phase de l'accélération en A",
        "Direction de l'accélération du palier A comptée depuis la valve, comme la lit un "
        "tachymètre synchronisé.",
    ),
    _readout(
        "accel_outer", "m/s²", "Vibration amplitude of the housing at bearing B (soft supports).",
        lambda s: abs(accelerometer(s, "sensor_B")),
        "Accélération du palier B",
        "Amplitude de l'accélération du logement du palier B, nulle sur paliers rigides.",
    ),
    _readout(
        "accel_outer_deg", "deg", "Phase of the housing's acceleration at B, from the valve.",
        lambda s: phase(accelerometer(s, "sensor_B")),
        "Phase de l'accélération en B",
        "Direction de l'accélération du palier B comptée depuis la valve, comme la lit un "
        "tachymètre synchronisé.",
    ),
    *bearings.readouts(BEARINGS),
)  # fmt: skip

ARROWS = (
    Arrow(
        "bearing_inner",
        "Palier A",
        (40, 110, 230),
        lambda s: (_bearing_points(s)[0].copy(), _bearings(s)[0]),
        scale=2e-2,
        unit="N",
        point="A",
        hint="Effort du palier intérieur A sur l'arbre de la roue (bleu).",
    ),
    Arrow(
        "bearing_outer",
        "Palier B",
        (230, 80, 40),
        lambda s: (_bearing_points(s)[1].copy(), _bearings(s)[1]),
        scale=2e-2,
        unit="N",
        point="B",
        hint="Effort du palier extérieur B sur l'arbre de la roue (orange).",
    ),
)
