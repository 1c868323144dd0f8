"""The cheap readout path (cached index arrays, vectorised joints, shared per-row arrays)
gives the values of a naive per-body, per-joint computation.

Tolerance: 1e-12 of each torsor's or energy's own scale (components that cancel to
round-off are compared with that scale, not with their own size).
"""

from __future__ import annotations

import mujoco
import numpy as np
import pytest

from sandbox.physics import readouts as R
from sandbox.physics.mechanism import mechanism_bodies
from sandbox.physics.simulation import Simulation
from sandbox.scenes import SCENES, get_scene, resolve

REL = 1e-12
ROUND_OFF = 1e-15
"""Absolute floor: a torsor that is 0 in theory (the free solid of the inertia scene: {D} = 0)
keeps ~1e-17 of round-off, summed in a different order by each path."""

SPRUNG = """
<mujoco>
  <worldbody>
    <body name="a" pos="0 0 1">
      <joint name="h" type="hinge" axis="0 1 0" stiffness="30" springref="0.2"/>
      <geom type="capsule" fromto="0 0 0 0.3 0 0.1" size="0.03" mass="1.2"/>
      <body name="b" pos="0.3 0 0.1">
        <joint name="s" type="slide" axis="1 0 0" stiffness="50"/>
        <geom type="box" size="0.05 0.04 0.03" mass="0.7"/>
        <body name="c" pos="0.1 0 0"><joint type="ball"/>
          <geom type="capsule" fromto="0 0 0 0 0.2 -0.1" size="0.02" mass="0.4"/></body>
      </body>
    </body>
    <body name="slider" pos="0 1 0"><joint name="s0" type="slide" axis="0 1 0.3"/>
      <geom type="sphere" size="0.05" mass="0.3"/></body>
    <body name="ball0" pos="1 0 0"><joint type="ball"/>
      <geom type="capsule" fromto="0 0 0 0.2 0.1 0" size="0.02" mass="0.5"/></body>
    <body name="free" pos="0 0 2"><freejoint/><geom type="box" size=".1 .05 .02" mass="2"/></body>
    <body name="welded" pos="0 0 3"><geom type="sphere" size="0.05" mass="9"/></body>
  </worldbody>
  <actuator><motor joint="h"/><motor joint="s"/><motor joint="s0"/></actuator>
</mujoco>
"""
"""Every joint type hangs from the frame (hinge, slide, ball, free), with springs,
motors, an armature-free chain and a body welded to the world."""


def _naive(model: mujoco.MjModel, data: mujoco.MjData) -> dict[str, float]:
    """The generic readouts body by body and joint by joint, with np.cross."""
    off = model.opt.disableflags & mujoco.mjtDisableBit.mjDSBL_GRAVITY
    g = np.zeros(3) if off else np.array(model.opt.gravity)
    mech = [b for b in range(model.nbody) if model.body_weldid[b] != 0]
    z = np.zeros
    kin_r, kin_m, dyn_r, dyn_m, t, p_acc, p_grav, p_x, v = z(3), z(3), z(3), z(3), 0, 0, 0, 0, 0
    for b in mech:
        m, x = model.body_mass[b], data.xipos[b]
        arm = x - data.subtree_com[model.body_rootid[b]]
        w, al = data.cvel[b, :3], data.cacc[b, :3]
        vg = data.cvel[b, 3:] + np.cross(w, arm)
        ag = data.cacc[b, 3:] + np.cross(al, arm) + np.cross(w, vg) + g
        rot = data.ximat[b].reshape(3, 3)
        inertia = rot @ np.diag(model.body_inertia[b]) @ rot.T
        iw = inertia @ w
        delta = inertia @ al + np.cross(w, iw)
        kin_r, kin_m = kin_r + m * vg, kin_m + iw + np.cross(x, m * vg)
        dyn_r, dyn_m = dyn_r + m * ag, dyn_m + delta + np.cross(x, m * ag)
        t += 0.5 * m * vg @ vg + 0.5 * iw @ w
        p_acc += m * ag @ vg + delta @ w
        p_grav += m * vg @ g
        p_x += data.xfrc_applied[b, :3] @ vg + data.xfrc_applied[b, 3:] @ w
        v -= m * x @ g
    t += 0.5 * model.dof_armature @ data.qvel**2
    p_acc += model.dof_armature @ (data.qvel * data.qacc)
    qv = data.qvel
    p_ext = p_grav + p_x + qv @ (data.qfrc_actuator + data.qfrc_applied + data.qfrc_gravcomp)
    p_int = qv @ (data.qfrc_passive - data.qfrc_gravcomp + data.qfrc_constraint)
    for j in range(model.njnt):
        if int(model.jnt_type[j]) in (mujoco.mjtJoint.mjJNT_HINGE, mujoco.mjtJoint.mjJNT_SLIDE):
            a = model.jnt_qposadr[j]
            v += 0.5 * model.jnt_stiffness[j] * (data.qpos[a] - model.qpos_spring[a]) ** 2
    # The frame's action: joint wrenches of the bodies hanging from it, minus their motors,
    # plus contacts and constraints (cfrc_ext), minus xfrc_applied.
    sup_r, sup_m = z(3), z(3)
    drive = data.qfrc_actuator + data.qfrc_applied - model.dof_armature * data.qacc
    for b in mech:
        c = data.subtree_com[model.body_rootid[b]]
        wrenches = [data.cfrc_ext[b]]
        if model.body_weldid[model.body_parentid[b]] == 0 and model.body_jntnum[b] > 0:
            wrenches.append(data.cfrc_int[b])
        for wr in wrenches:
            sup_r, sup_m = sup_r + wr[3:], sup_m + wr[:3] + np.cross(c, wr[3:])
        f = data.xfrc_applied[b]
        sup_r, sup_m = sup_r - f[:3], sup_m - f[3:] - np.cross(data.xipos[b], f[:3])
        if model.body_weldid[model.body_parentid[b]] != 0:
            continue
        rot = data.xmat[b].reshape(3, 3)
        for j in range(model.body_jntadr[b], model.body_jntadr[b] + model.body_jntnum[b]):
            kind, d = model.jnt_type[j], model.jnt_dofadr[j]
            if kind == mujoco.mjtJoint.mjJNT_HINGE:
                sup_m = sup_m - drive[d] * data.xaxis[j]
            elif kind == mujoco.mjtJoint.mjJNT_SLIDE:
                f = drive[d] * data.xaxis[j]
                sup_r, sup_m = sup_r - f, sup_m - np.cross(data.xanchor[j], f)
            elif kind == mujoco.mjtJoint.mjJNT_BALL:
                sup_m = sup_m - rot @ drive[d : d + 3]
            else:
                f = drive[d : d + 3]
                sup_r = sup_r - f
                sup_m = sup_m - np.cross(data.xpos[b], f) - rot @ drive[d + 3 : d + 6]
    out = {"time": float(data.time), "T": t, "V": v, "P_ext": p_ext, "P_int": p_int}
    out["P_acc"] = p_acc
    for name, (r, m) in {
        "kin": (kin_r, kin_m),
        "dyn": (dyn_r, dyn_m),
        "sup": (sup_r, sup_m),
    }.items():
        for i, c in enumerate("xyz"):
            out[f"{name}_R_{c}"], out[f"{name}_M_{c}"] = float(r[i]), float(m[i])
    return out


def _scale(values: dict[str, float], name: str) -> float:
    """Size of the group a readout belongs to (a torsor, the energies, the powers)."""
    if name[:4] in ("kin_", "dyn_", "sup_"):
        group = [k for k in values if k.startswith(name[:4])]
    elif name.startswith("P_") or name in ("T", "V"):
        group = ["T", "V", "P_ext", "P_int", "P_acc"] if name.startswith("P_") else ["T", "V"]
    else:
        group = [name]
    return max(abs(values[k]) for k in group) + 1e-300


def _assert_same(got: dict[str, float], ref: dict[str, float]) -> None:
    for name in R.GENERIC_NAMES:
        tol = REL * _scale(ref, name) + ROUND_OFF
        assert abs(got[name] - ref[name]) <= tol, (name, got[name], ref[name])


def _random_state(xml: str, seed: int) -> tuple[mujoco.MjModel, mujoco.MjData]:
    model = mujoco.MjModel.from_xml_string(xml)
    data = mujoco.MjData(model)
    rng = np.random.default_rng(seed)
    data.qvel[:] = rng.normal(size=model.nv)
    data.ctrl[:] = rng.normal(size=model.nu)
    mujoco.mj_step(model, data, 50)
    data.xfrc_applied[1:] = rng.normal(size=(model.nbody - 1, 6))
    R.prepare(model, data, ["dyn_R_x"])
    return model, data


@pytest.mark.parametrize("seed", [0, 1])
def test_every_joint_type_springs_motors_and_loads_match_the_naive_sums(seed):
    model, data = _random_state(SPRUNG, seed)
    _assert_same(R.compute(model, data, R.GENERIC_NAMES, {}), _naive(model, data))
    assert R.compute(model, data, R.GENERIC_NAMES) == R.compute(model, data, R.GENERIC_NAMES, {})


@pytest.mark.parametrize("name", sorted(SCENES))
def test_each_scene_matches_the_naive_sums_and_its_readouts_do_not_depend_on_sharing(name):
    """Generic readouts against the naive sums; every scene readout computed alone (fresh
    snapshot) equals the one computed in a full row (shared torsors and caches)."""
    sim = Simulation(resolve(name))
    sim.advance(0.05)
    row = sim.readouts()
    naive = _naive(sim.model, sim.data)
    if sim.scene.mechanism is not None:  # the machine's energies where the model stands in
        from sandbox.physics.snapshot import Snapshot

        sim.scene.mechanism(Snapshot(sim.model, sim.data, sim.values), naive)
    _assert_same(row, naive)
    for readout in sim.scene.readouts:
        assert sim.readouts([readout.name])[readout.name] == row[readout.name], readout.name


def test_model_constant_indices_follow_a_rebuilt_model():
    """The cached structure belongs to one compiled model: a rebuild gets its own."""
    sim = Simulation(get_scene("compressor"))
    first = mechanism_bodies(sim.model)
    sim.set_value("counterweight_mass", 0.1)  # rebuild
    assert mechanism_bodies(sim.model) is not first
    assert not mechanism_bodies(sim.model).flags.writeable
    _assert_same(sim.readouts(), _naive(sim.model, sim.data))


def test_the_compressor_orders_of_a_cached_revolution_are_the_fitted_ones():
    from sandbox.scenes.compressor import cycle as compressor

    sim = Simulation(get_scene("compressor"))
    sim.advance(0.05)
    names = ["pilon_h1", "pilon_h2", "tamis_h1"]
    cached = sim.readouts(names)
    again = sim.readouts(names)
    compressor._ORDERS.clear()
    compressor._REVOLUTIONS.clear()
    fresh = sim.readouts(names)
    assert cached == again == fresh
