"""float64 refinement of curved-primitive hits on the device (the warp pipeline's kernel)."""

from __future__ import annotations

import mujoco
import numpy as np
import pytest

pytestmark = pytest.mark.warp
wp = pytest.importorskip(
    "warp", reason="optional robotwright[warp] extra (warp-lang) not installed"
)
pytest.importorskip(
    "mujoco_warp", reason="optional robotwright[warp] extra (mujoco-warp) not installed"
)

from robotwright.sensors import _warp_kernels  # noqa: E402


@wp.kernel
def _refine_all(
    kind: wp.array(dtype=wp.int32),
    size: wp.array(dtype=wp.vec3d),
    p: wp.array(dtype=wp.vec3d),
    v: wp.array(dtype=wp.vec3d),
    t0: wp.array(dtype=wp.float64),
    out: wp.array(dtype=wp.float64),
):
    i = wp.tid()
    out[i] = _warp_kernels.refine_curved(kind[i], size[i], p[i], v[i], t0[i])


def test_refine_recovers_mujoco_distances_from_perturbed_ones():
    xml = """<mujoco><worldbody>
      <geom name="sph" type="sphere" size="0.4" pos="2 0 0"/>
      <geom name="cap" type="capsule" size="0.2 0.5" pos="0 2 0" euler="0.3 0.2 0"/>
      <geom name="ell" type="ellipsoid" size="0.3 0.5 0.2" pos="-2 0 0" euler="0 0.4 0.1"/>
      <geom name="cyl" type="cylinder" size="0.3 0.4" pos="0 -2 0" euler="0.5 0 0"/>
      <geom name="box" type="box" size="0.3 0.3 0.3" pos="0 0 2"/>
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
    assert set(np.unique(gid[hit])) == {0, 1, 2, 3, 4} and hit.sum() > 500
    g = gid[hit]
    mat = data.geom_xmat[g].reshape(-1, 3, 3)
    # Rays in each hit geom's frame: p = R^T (o - x), v = R^T d (float64, as the kernel's).
    p = np.einsum("kji,kj->ki", mat, origin - data.geom_xpos[g])
    v = np.einsum("kji,kj->ki", mat, dirs[hit])
    noisy = dist[hit] + rng.uniform(-3e-4, 3e-4, g.shape)
    with wp.ScopedDevice("cpu"):
        out = wp.zeros(len(g), dtype=wp.float64)
        wp.launch(
            _refine_all,
            dim=len(g),
            inputs=[
                wp.array(model.geom_type[g].astype(np.int32), dtype=wp.int32),
                wp.array(model.geom_size[g], dtype=wp.vec3d),
                wp.array(p, dtype=wp.vec3d),
                wp.array(v, dtype=wp.vec3d),
                wp.array(noisy, dtype=wp.float64),
            ],
            outputs=[out],
        )
        refined = out.numpy()
    curved = g != 4
    np.testing.assert_allclose(refined[curved], dist[hit][curved], atol=1e-9, rtol=0)
    np.testing.assert_array_equal(refined[~curved], noisy[~curved])  # box hits untouched
