"""Model of the rolling cylinder: slope, radius, inertia, eccentric mass and friction in
the MJCF, the race's tube and sphere, the start at the static penetration, and the end of a
run past the plane's far end."""

from __future__ import annotations

import math

import mujoco
import numpy as np

from sandbox.errors import BadParameter
from sandbox.french import number
from sandbox.physics.spec import Values
from sandbox.scenes.rolling_cylinder.course import axis_inertia


def edit(spec: mujoco.MjSpec, v: Values) -> None:
    """Slope, radius, length, inertia (solid or hollow), eccentric mass, friction."""
    if v["inner_radius"] >= v["R"]:
        raise BadParameter(
            f"inner_radius = {v['inner_radius']:g} m must be smaller than R = {v['R']:g} m; "
            "lower inner_radius",
            french=f"Le rayon intérieur r = {number(v['inner_radius'])} m doit rester plus petit "
            f"que le rayon R = {number(v['R'])} m : diminuez r.",
        )
    alpha = math.radians(v["slope_deg"])
    slope = spec.body("slope")
    slope.quat = [math.cos(alpha / 2), 0, math.sin(alpha / 2), 0]  # x down the slope
    plane = spec.geom("plane")  # infinite for collisions; drawn by "deck" below
    plane.rgba = [0, 0, 0, 0]
    spec.pair("contact").friction[:2] = [v["mu"], v["mu"]]
    deck = spec.geom("deck")
    deck.size = [v["plane_length"] / 2, max(v["length"], 0.5), 0.005]
    deck.pos = [v["plane_length"] / 2 - 0.5, 0, -0.005]
    R, h, m = v["R"], v["length"], v["mass"]
    cyl = spec.geom("cylinder")
    cyl.size = [R, h / 2, 0]
    body = spec.body("cylinder")
    body.pos = [0, 0, R]
    i_axis = axis_inertia(v)
    i_across = m * (3 * (R * R + v["inner_radius"] ** 2) + h * h) / 12
    body.explicitinertial = True
    body.mass, body.ipos = m, [0, 0, 0]
    body.fullinertia = [i_across, i_axis, i_across, 0, 0, 0]
    stripe = spec.geom("stripe")
    stripe.pos = [0, 0, 0.6 * R]
    stripe.size = [0.02 * R + 0.002, h / 2 + 0.001, 0.4 * R]
    ecc = spec.body("eccentric")
    ecc.pos = [0, 0, v["eccentric_radius"]]
    m_e = v["eccentric_mass"]
    ecc.explicitinertial = True
    ecc.mass = max(m_e, 1e-9)
    tiny = max(m_e * 1e-6, 1e-10)
    ecc.fullinertia = [tiny, tiny, tiny, 0, 0, 0]
    spec.geom("eccentric").rgba = [0.8, 0.1, 0.1, 1.0 if m_e > 0 else 0.0]
    spec.geom("eccentric").size = [max(0.012, 0.1 * R), 0, 0]
    if v["race"] >= 0.5:
        deck.size = [v["plane_length"] / 2, 3 * (h + 2 * R), 0.005]
        _add_racers(spec, v)


RACERS = (("hollow", 0.35), ("sphere", -0.35))
"""Race companions and their offset along the axis, in multiples of (length + 2R)."""


def _add_racers(spec: mujoco.MjSpec, v: Values) -> None:
    """A thin tube (I = m R²) and a solid sphere (I = 2/5 m R²) beside the cylinder."""
    R, h, m = v["R"], v["length"], v["mass"]
    for name, side in RACERS:
        y = side * (h + 2 * R) * 2.5
        body = spec.body("slope").add_body(name=name, pos=[0, y, R])
        for axis, kind, jname in (([1, 0, 0], "slide", "x"), ([0, 0, 1], "slide", "z"),
                                  ([0, 1, 0], "hinge", "spin")):  # fmt: skip
            joint = body.add_joint(name=f"{jname}_{name}", axis=axis)
            joint.type = (
                mujoco.mjtJoint.mjJNT_SLIDE if kind == "slide" else mujoco.mjtJoint.mjJNT_HINGE
            )
        body.explicitinertial = True
        body.mass = m
        if name == "hollow":
            i_axis, i_across = m * R * R, m * (6 * R * R + h * h) / 12
            geom = body.add_geom(name=name, type=mujoco.mjtGeom.mjGEOM_CYLINDER, size=[R, h / 2, 0])
            geom.alt.type = mujoco.mjtOrientation.mjORIENTATION_QUAT
            geom.quat = [math.cos(math.pi / 4), math.sin(math.pi / 4), 0, 0]
            geom.rgba = [0.3, 0.5, 0.85, 1]
        else:
            i_axis = i_across = 0.4 * m * R * R
            geom = body.add_geom(name=name, type=mujoco.mjtGeom.mjGEOM_SPHERE, size=[R, 0, 0])
            geom.rgba = [0.3, 0.75, 0.4, 1]
        body.ipos, body.iquat = [0, 0, 0], [1, 0, 0, 0]
        body.inertia = [i_across, i_axis, i_across]
        pair = spec.add_pair(name=f"contact_{name}", geomname1="plane", geomname2=name)
        pair.friction = [v["mu"], v["mu"], 0, 0, 0]  # solref, solimp... from the pair default
        stripe = body.add_geom(type=mujoco.mjtGeom.mjGEOM_BOX, pos=[0, 0, 0.6 * R],
                               size=[0.02 * R + 0.002, 0.3 * R, 0.4 * R])  # fmt: skip
        stripe.rgba = [0.2, 0.2, 0.2, 1]
        stripe.mass = 0


def initial_state(model: mujoco.MjModel, data: mujoco.MjData, v: Values) -> None:
    """On the plane, rolling at v0 (ω = v0 / R), eccentric mass straight up; racers alike."""
    data.qpos[:] = 0.0
    for k in range(model.nv // 3):
        data.qvel[3 * k : 3 * k + 3] = [v["v0"], 0.0, v["v0"] / v["R"]]
    _settle(model, data)


def _settle(model: mujoco.MjModel, data: mujoco.MjData) -> None:
    """Sink every body to its static penetration (a few µm), where the contact carries it.

    Started just touching, the cylinder would fall onto the plane while N builds up from
    0, slip meanwhile (μ N is small), and keep that slip (~3 mm/s near μ_min): friction
    barely corrects a slip velocity (solreffriction, below). Bisection on each z so that
    its acceleration across the plane is 0.
    """
    z = np.arange(1, model.nv, 3)  # the z slide of each body (x, z, spin)
    lo, hi = np.full(len(z), -0.01), np.zeros(len(z))  # pushed out at lo, falling at hi
    for _ in range(40):
        data.qpos[z] = 0.5 * (lo + hi)
        mujoco.mj_forward(model, data)
        out = data.qacc[z] > 0
        lo = np.where(out, data.qpos[z], lo)
        hi = np.where(out, hi, data.qpos[z])
    data.qpos[z] = 0.5 * (lo + hi)
    mujoco.mj_forward(model, data)
    data.qacc_warmstart[:] = data.qacc


def past_the_plane(model: mujoco.MjModel, data: mujoco.MjData, v: Values) -> bool:
    """Whether the run is over: every rolling body's centre past the plane's far end (in a
    race, the last one too). The web page then starts the descent again."""
    end = v["plane_length"] - 0.5
    for name in ("x", *(f"x_{racer}" for racer, _ in RACERS)):
        j = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, name)
        if j >= 0 and float(data.qpos[model.jnt_qposadr[j]]) <= end:
            return False
    return True
