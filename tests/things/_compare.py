"""Compare two compiled MuJoCo models: masses, inertia tensors, FK, ranges, actuators."""

from __future__ import annotations

import mujoco
import numpy as np


def inertia_tensors(model: mujoco.MjModel) -> np.ndarray:
    """Body inertia tensors in the body frame (principal axes can be chosen freely)."""
    out = []
    for i in range(model.nbody):
        rot = np.zeros(9)
        mujoco.mju_quat2Mat(rot, model.body_iquat[i])
        rot = rot.reshape(3, 3)
        out.append(rot @ np.diag(model.body_inertia[i]) @ rot.T)
    return np.array(out)


def assert_same_model(a: mujoco.MjModel, b: mujoco.MjModel, seed: int = 0) -> None:
    for field in (
        "nbody",
        "njnt",
        "nq",
        "nv",
        "ngeom",
        "nsite",
        "nu",
        "nsensor",
        "nsensordata",
        "ntendon",
        "neq",
        "nkey",
        "ncam",
        "nlight",
        "nmesh",
    ):
        assert getattr(a, field) == getattr(b, field), field
    np.testing.assert_allclose(a.body_mass, b.body_mass, rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(a.body_ipos, b.body_ipos, atol=1e-9)
    np.testing.assert_allclose(inertia_tensors(a), inertia_tensors(b), rtol=1e-7, atol=1e-10)
    np.testing.assert_array_equal(a.jnt_type, b.jnt_type)
    np.testing.assert_array_equal(a.jnt_limited, b.jnt_limited)
    limited = a.jnt_limited.astype(bool)
    np.testing.assert_allclose(a.jnt_range[limited], b.jnt_range[limited], atol=1e-12)
    np.testing.assert_allclose(a.jnt_axis, b.jnt_axis, atol=1e-12)
    np.testing.assert_allclose(a.geom_size, b.geom_size, atol=1e-9)
    np.testing.assert_array_equal(a.geom_type, b.geom_type)
    np.testing.assert_allclose(a.actuator_gear, b.actuator_gear)
    np.testing.assert_allclose(a.actuator_ctrlrange, b.actuator_ctrlrange)
    np.testing.assert_allclose(a.actuator_gainprm, b.actuator_gainprm)
    np.testing.assert_allclose(a.actuator_biasprm, b.actuator_biasprm)
    np.testing.assert_array_equal(a.actuator_trnid, b.actuator_trnid)
    np.testing.assert_array_equal(a.sensor_type, b.sensor_type)
    np.testing.assert_array_equal(a.sensor_objid, b.sensor_objid)
    assert a.opt.timestep == b.opt.timestep
    np.testing.assert_allclose(a.opt.gravity, b.opt.gravity)
    # forward kinematics at the reference pose and at a random pose
    rng = np.random.default_rng(seed)
    for qpos in (a.qpos0.copy(), a.qpos0 + rng.normal(0.0, 0.3, a.nq)):
        da, db = mujoco.MjData(a), mujoco.MjData(b)
        da.qpos[:] = qpos
        db.qpos[:] = qpos
        mujoco.mj_kinematics(a, da)
        mujoco.mj_kinematics(b, db)
        np.testing.assert_allclose(da.xpos, db.xpos, atol=1e-9)
        np.testing.assert_allclose(da.xquat, db.xquat, atol=1e-9)
        np.testing.assert_allclose(da.geom_xpos, db.geom_xpos, atol=1e-9)
        np.testing.assert_allclose(da.site_xpos, db.site_xpos, atol=1e-9)
