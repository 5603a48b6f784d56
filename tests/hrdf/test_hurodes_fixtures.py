"""The hurodes-written fixtures (tools/fetch_test_data.py) hold the robot they claim to:
hurodes' folder, our MJCF of it and hurodes' own export compile to the source G1's
masses, inertias, joints, motors and poses at random configurations."""

from __future__ import annotations

import json
import warnings
from pathlib import Path

import mujoco
import numpy as np
import pytest

from robotwright.generators import MJCFHumanoidGenerator

pytestmark = [pytest.mark.hurodes, pytest.mark.realdata]


def _poses(m: mujoco.MjModel, qpos: np.ndarray) -> dict[str, np.ndarray]:
    """World position and orientation (w, x, y, z) of every named body at ``qpos``."""
    d = mujoco.MjData(m)
    d.qpos[:] = qpos
    mujoco.mj_kinematics(m, d)
    return {m.body(i).name: np.concatenate([d.xpos[i], d.xquat[i]]) for i in range(1, m.nbody)}


def _compare(model: mujoco.MjModel, src: mujoco.MjModel, rng: np.random.Generator) -> None:
    assert (model.nbody, model.njnt, model.nq, model.nv, model.nu) == (
        src.nbody, src.njnt, src.nq, src.nv, src.nu,
    )  # fmt: skip
    for i in range(1, src.nbody):
        j = model.body(src.body(i).name).id
        for field in ("body_mass", "body_inertia", "body_ipos"):
            np.testing.assert_allclose(
                getattr(model, field)[j], getattr(src, field)[i], rtol=1e-9, atol=1e-12
            )
    by_joint = {src.joint(src.actuator_trnid[a, 0]).name: a for a in range(src.nu)}
    for a in range(model.nu):
        b = by_joint[model.joint(model.actuator_trnid[a, 0]).name]
        np.testing.assert_array_equal(model.actuator_ctrlrange[a], src.actuator_ctrlrange[b])
    # The same joint values (source order, by joint name) give the same body poses.
    for _ in range(5):
        q_src = src.qpos0.copy()
        q_src[:3] = rng.uniform(-1, 1, 3)
        quat = rng.normal(size=4)
        q_src[3:7] = quat / np.linalg.norm(quat)
        q = model.qpos0.copy()
        q[:7] = q_src[:7]
        for k in range(1, src.njnt):
            lo, hi = src.jnt_range[k]
            value = rng.uniform(lo, hi)
            q_src[src.jnt_qposadr[k]] = value
            q[model.jnt_qposadr[model.joint(src.joint(k).name).id]] = value
        ours, theirs = _poses(model, q), _poses(src, q_src)
        for name, pose in theirs.items():
            np.testing.assert_allclose(ours[name][:3], pose[:3], atol=1e-9, err_msg=name)
            sign = 1.0 if np.dot(ours[name][3:], pose[3:]) >= 0 else -1.0
            np.testing.assert_allclose(sign * ours[name][3:], pose[3:], atol=1e-9, err_msg=name)


def test_g1_fixture_compiles_to_the_source_robot(g1_hrdf_dir: Path, g1_source_mjcf: Path) -> None:
    src = mujoco.MjModel.from_xml_path(str(g1_source_mjcf))
    assert src.nu == 29 and src.njnt == 30  # the 29-motor G1 with a floating base
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # hurodes' folder has no peak velocities
        ours = MJCFHumanoidGenerator.from_hrdf_path(g1_hrdf_dir).to_model()
    _compare(ours, src, np.random.default_rng(12))
    hurodes_export = mujoco.MjModel.from_xml_path(str(g1_hrdf_dir / "exported" / "robot.xml"))
    _compare(hurodes_export, src, np.random.default_rng(13))
    meshes = sorted(p.stem for p in (g1_hrdf_dir / "meshes").iterdir())
    assert meshes == sorted(src.mesh(i).name for i in range(src.nmesh))


def test_fixtures_record_hurodes_version(g1_hrdf_dir: Path) -> None:
    """The cache stamp names the hurodes version that wrote the folders."""
    path = g1_hrdf_dir.parent / ".hurodes-fixtures.json"
    if not path.is_file():
        pytest.skip(
            f"{g1_hrdf_dir.parent} was not made by tools/fetch_test_data.py (no {path.name})"
        )
    stamp = json.loads(path.read_text())
    assert stamp["hurodes"] == "0.1.9" and len(stamp["inputs_sha256"]) == 64
