"""Compiled-model equivalence: ours vs hurodes' export (G1), and our URDF vs our MJCF."""

from __future__ import annotations

import dataclasses
import warnings

import mujoco
import numpy as np
import pytest

from robotwright.errors import ConversionWarning
from robotwright.generators import MJCFHumanoidGenerator, URDFHumanoidGenerator
from robotwright.hrdf.model import HRDF
from robotwright.parsers.reference import mujoco_diagonalises_inertia_exactly

pytestmark = pytest.mark.filterwarnings("ignore::UserWarning")


def _random_qpos(m: mujoco.MjModel, rng: np.random.Generator) -> np.ndarray:
    q = m.qpos0.copy()
    for j in range(m.njnt):
        a = m.jnt_qposadr[j]
        t = m.jnt_type[j]
        if t == mujoco.mjtJoint.mjJNT_FREE:
            q[a : a + 3] = rng.normal(size=3)
            v = rng.normal(size=4)
            q[a + 3 : a + 7] = v / np.linalg.norm(v)
        elif t == mujoco.mjtJoint.mjJNT_BALL:
            v = rng.normal(size=4)
            q[a : a + 4] = v / np.linalg.norm(v)
        else:
            lo, hi = m.jnt_range[j] if m.jnt_limited[j] else (-3.0, 3.0)
            q[a] = rng.uniform(lo, hi)
    return q


def _same_quat(a: np.ndarray, b: np.ndarray) -> float:
    return float(min(np.abs(a - b).max(), np.abs(a + b).max()))


@pytest.mark.hurodes
def test_g1_matches_hurodes_export(g1_hrdf_dir):
    ref_path = g1_hrdf_dir / "exported" / "robot.xml"
    if not ref_path.is_file():
        pytest.skip(f"hurodes export absent: {ref_path}")
    ours = MJCFHumanoidGenerator.from_hrdf_path(g1_hrdf_dir).to_model()
    ref = mujoco.MjModel.from_xml_path(str(ref_path))
    assert (ours.nbody, ours.njnt, ours.nq, ours.nv, ours.nu) == (
        ref.nbody, ref.njnt, ref.nq, ref.nv, ref.nu,
    )  # fmt: skip
    for i in range(1, ref.nbody):
        name = ref.body(i).name
        j = ours.body(name).id
        for field in (
            "body_mass",
            "body_inertia",
            "body_ipos",
            "body_iquat",
            "body_pos",
            "body_quat",
        ):
            np.testing.assert_allclose(getattr(ours, field)[j], getattr(ref, field)[i], atol=1e-12, err_msg=f"{field} {name}")  # fmt: skip
        assert ours.body(ours.body_parentid[j]).name == ref.body(ref.body_parentid[i]).name
    for i in range(ref.njnt):
        name = ref.joint(i).name
        j = ours.joint(name).id if name else 0
        assert ours.jnt_type[j] == ref.jnt_type[i]
        assert ours.jnt_limited[j] == ref.jnt_limited[i]
        np.testing.assert_array_equal(ours.jnt_axis[j], ref.jnt_axis[i])
        np.testing.assert_array_equal(ours.jnt_range[j], ref.jnt_range[i])
        np.testing.assert_array_equal(ours.jnt_pos[j], ref.jnt_pos[i])
    for field in ("dof_armature", "dof_damping", "dof_frictionloss"):
        np.testing.assert_array_equal(getattr(ours, field), getattr(ref, field))
    for i in range(ref.nu):
        assert (
            ours.joint(ours.actuator_trnid[i, 0]).name == ref.joint(ref.actuator_trnid[i, 0]).name
        )
    np.testing.assert_array_equal(ours.actuator_ctrlrange, ref.actuator_ctrlrange)
    np.testing.assert_array_equal(ours.actuator_ctrllimited, ref.actuator_ctrllimited)
    np.testing.assert_array_equal(ours.actuator_gainprm, ref.actuator_gainprm)
    np.testing.assert_array_equal(ours.geom_size, ref.geom_size)
    np.testing.assert_array_equal(ours.geom_friction, ref.geom_friction)
    np.testing.assert_array_equal(ours.geom_contype, ref.geom_contype)

    rng = np.random.default_rng(0)
    da, db = mujoco.MjData(ours), mujoco.MjData(ref)
    names = [ref.body(i).name for i in range(1, ref.nbody)]
    idx_o = [ours.body(n).id for n in names]
    idx_r = list(range(1, ref.nbody))
    for _ in range(50):
        q = _random_qpos(ref, rng)
        da.qpos[:] = q
        db.qpos[:] = q
        mujoco.mj_kinematics(ours, da)
        mujoco.mj_kinematics(ref, db)
        np.testing.assert_allclose(da.xpos[idx_o], db.xpos[idx_r], atol=1e-9)
        np.testing.assert_allclose(da.xquat[idx_o], db.xquat[idx_r], atol=1e-9)


def _urdf_vs_mjcf(
    hrdf: HRDF, tmp_path, n: int = 20, site_links: dict[str, str] | None = None
) -> None:
    """Our URDF (MuJoCo tag) loaded by MuJoCo vs our MJCF: masses, inertias, and the
    pose of every body and site at ``n`` random configurations (joints set by name, so
    hinge/slide ``ref`` offsets must be applied by the URDF). ``site_links``: site name ->
    link name where the URDF renamed the site's link."""
    site_links = site_links or {}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ConversionWarning)
        mj = MJCFHumanoidGenerator.from_hrdf(hrdf).to_model()
        path = tmp_path / f"{hrdf.name}.urdf"
        URDFHumanoidGenerator.from_hrdf(hrdf).export(path, add_mujoco_tag=True)
    ur = mujoco.MjModel.from_xml_path(str(path))
    assert ur.body_mass.sum() == pytest.approx(mj.body_mass.sum(), abs=1e-6)
    assert ur.nq == mj.nq
    # Inertia tensors about the centre of mass, in the world frame at MJCF's qpos0 (the
    # same joint values in the URDF, whose own zero differs where a joint has a ref).
    da, db = mujoco.MjData(mj), mujoco.MjData(ur)

    def set_q(q: np.ndarray) -> None:
        da.qpos[:] = q
        for jid in range(mj.njnt):
            name = mj.joint(jid).name
            uj = ur.joint(name).id if name else 0
            size = {0: 7, 1: 4}.get(int(mj.jnt_type[jid]), 1)
            a, b = mj.jnt_qposadr[jid], ur.jnt_qposadr[uj]
            db.qpos[b : b + size] = q[a : a + size]
        mujoco.mj_kinematics(mj, da)
        mujoco.mj_kinematics(ur, db)

    set_q(mj.qpos0)
    # MuJoCo 3.11 compiles the URDF's full inertia tensors with principal axes up to
    # ~1e-6 rad off (a tensor rebuilt from them is off by up to ~1e-6 of its size,
    # e.g. 3.7e-8 on the G1's torso); 4.x's are exact to rounding.
    exact = mujoco_diagonalises_inertia_exactly()
    for b in hrdf.bodies:
        i, j = mj.body(b.name).id, ur.body(b.name).id
        ta = da.ximat[i].reshape(3, 3) @ np.diag(mj.body_inertia[i]) @ da.ximat[i].reshape(3, 3).T
        tb = db.ximat[j].reshape(3, 3) @ np.diag(ur.body_inertia[j]) @ db.ximat[j].reshape(3, 3).T
        atol = 1e-9 if exact else max(1e-9, 1e-6 * float(np.abs(tb).max()))
        np.testing.assert_allclose(ta, tb, atol=atol, err_msg=b.name)
        np.testing.assert_allclose(da.xipos[i], db.xipos[j], atol=1e-9)
    rng = np.random.default_rng(1)
    for _ in range(n):
        set_q(_random_qpos(mj, rng))
        for body in hrdf.bodies:
            i, j = mj.body(body.name).id, ur.body(body.name).id
            # Each body's link frame is its MJCF body frame (also with joint anchors off
            # the body origin, and with joint refs).
            np.testing.assert_allclose(da.xpos[i], db.xpos[j], atol=1e-6, err_msg=body.name)
            np.testing.assert_allclose(da.xipos[i], db.xipos[j], atol=1e-6)
            assert _same_quat(da.xquat[i], db.xquat[j]) < 1e-6, body.name
        for s in range(mj.nsite):
            link = site_links.get(mj.site(s).name, mj.site(s).name)
            np.testing.assert_allclose(da.site_xpos[s], db.xpos[ur.body(link).id], atol=1e-6)
            np.testing.assert_allclose(
                da.site_xmat[s], db.xmat[ur.body(link).id], atol=1e-6, err_msg=link
            )


@pytest.mark.hurodes
def test_g1_urdf_matches_mjcf(g1_hrdf_dir, tmp_path):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        hrdf = HRDF.from_dir(g1_hrdf_dir)
    _urdf_vs_mjcf(hrdf, tmp_path)


@pytest.mark.parametrize("name", ["mini_humanoid", "arm6"])
def test_bundled_urdf_matches_mjcf(name, tmp_path):
    _urdf_vs_mjcf(HRDF.from_robot_name(name), tmp_path)


def test_multi_joint_bodies_anchors_and_slides_urdf_matches_mjcf(synth_urdf_safe, tmp_path):
    _urdf_vs_mjcf(synth_urdf_safe, tmp_path, n=50)


def test_fixed_base_urdf_matches_mjcf(synth_fixed, tmp_path):
    _urdf_vs_mjcf(synth_fixed, tmp_path)


def test_root_with_hinge_joints_urdf_matches_mjcf(synth_fixed, tmp_path):
    import dataclasses

    from robotwright.hrdf.model import Joint

    root_joints = [
        Joint("turn", "base", "hinge", (0.0, 0.0, 0.1), (0.0, 0.0, 1.0), (-2.0, 2.0)),
        Joint("lift", "base", "slide", (0.0, 0.0, 0.0), (0.0, 0.0, 1.0), (0.0, 0.3)),
    ]
    h = dataclasses.replace(synth_fixed, joints=root_joints + synth_fixed.joints)
    _urdf_vs_mjcf(h, tmp_path, n=30)


def _with_refs(hrdf: HRDF) -> HRDF:
    refs = {"j1a": 0.4, "j1b": -0.9, "j2": 0.05, "j3": -0.7}
    joints = [dataclasses.replace(j, ref=refs.get(j.name or "", 0.0)) for j in hrdf.joints]
    return dataclasses.replace(hrdf, joints=joints)


def test_joint_ref_baked_into_urdf_origin_matches_mjcf(synth_urdf_safe, tmp_path):
    """MJCF places a body at its pos/quat when q = ref; the URDF origin carries the motion
    by -ref, so both give the same FK at every q (hinges, a slide, several joints on one
    body, anchors off the body origin)."""
    hrdf = _with_refs(synth_urdf_safe)
    mj = MJCFHumanoidGenerator.from_hrdf(hrdf).to_model()
    assert mj.qpos0[mj.joint("j1a").qposadr[0]] == pytest.approx(0.4)  # refs reach MuJoCo
    _urdf_vs_mjcf(hrdf, tmp_path, n=50)
    with pytest.warns(ConversionWarning, match=r"joint 'j2': ref 0.05 baked into the joint"):
        URDFHumanoidGenerator.from_hrdf(hrdf).generate()


def test_joint_ref_fixed_base(synth_fixed, tmp_path):
    _urdf_vs_mjcf(_with_refs(synth_fixed), tmp_path)


def test_site_named_like_a_body_becomes_suffixed_link(synth_urdf_safe, tmp_path):
    site = dataclasses.replace(synth_urdf_safe.sites[0], name="link1")
    hrdf = dataclasses.replace(synth_urdf_safe, sites=[site], sensors=[])
    with pytest.warns(ConversionWarning, match=r"'link1' -> 'link1_site'"):
        URDFHumanoidGenerator.from_hrdf(hrdf).generate()
    _urdf_vs_mjcf(hrdf, tmp_path, site_links={"link1": "link1_site"})
