"""float64 refinement of curved-primitive hits (used by the warp engine)."""

from __future__ import annotations

import mujoco
import numpy as np

from robotwright.sensors.raycast import refine_curved_hits


def test_refine_recovers_mujoco_distances_from_perturbed_ones():
    xml = """<mujoco><worldbody>
      <geom name="sph" type="sphere" size="0.4" pos="2 0 0"/>
      <geom name="cap" type="capsule" size="0.2 0.5" pos="0 2 0" euler="0.3 0.2 0"/>
      <geom name="ell" type="ellipsoid" size="0.3 0.5 0.2" pos="-2 0 0" euler="0 0.4 0.1"/>
      <geom name="cyl" type="cylinder" size="0.3 0.4" pos="0 -2 0" euler="0.5 0 0"/>
    </worldbody></mujoco>"""
    model = mujoco.MjModel.from_xml_string(xml)
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    rng = np.random.default_rng(0)
    dirs = rng.normal(size=(20000, 3))
    dirs /= np.linalg.norm(dirs, axis=1, keepdims=True)
    origin = np.array([0.0, 0.0, 0.0])
    gid = np.empty(len(dirs), dtype=np.int32)
    dist = np.empty(len(dirs))
    mujoco.mj_multiRay(
        model, data, origin, dirs.ravel(), None, 1, -1, gid, dist, None, len(dirs), 100.0
    )
    hit = gid >= 0
    assert set(np.unique(gid[hit])) == {0, 1, 2, 3} and hit.sum() > 500
    noisy = dist + np.where(hit, rng.uniform(-3e-4, 3e-4, dist.shape), 0.0)
    out = noisy[None].copy()
    refine_curved_hits(
        model,
        data.geom_xpos[None],
        data.geom_xmat[None],
        np.zeros((len(dirs), 3)),
        dirs,
        np.eye(3)[None],
        np.zeros((1, 3)),
        out,
        gid[None].copy(),
    )
    np.testing.assert_allclose(out[0, hit], dist[hit], atol=1e-9, rtol=0)
    np.testing.assert_array_equal(out[0, ~hit], noisy[~hit])  # misses untouched
