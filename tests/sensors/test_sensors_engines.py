"""The warp engine agrees with the mj_multiRay reference (marked ``warp``)."""

from __future__ import annotations

import numpy as np
import pytest
from lidar_scenes import RaysPattern, forward, random_envs

from robotwright.sensors import (
    LivoxPatternCfg,
    SemanticLidarCfg,
    SemanticLidarSensor,
    SpinningLidarPatternCfg,
)

pytestmark = pytest.mark.warp
pytest.importorskip(
    "mujoco_warp", reason="optional robotwright[warp] extra (mujoco-warp) not installed"
)
pytest.importorskip("warp", reason="optional robotwright[warp] extra (warp-lang) not installed")


def _scan(model, datas, engine, pattern, **kw):
    cfg = SemanticLidarCfg(
        prim_path=kw.pop("prim_path", "lidar"),
        pattern_cfg=pattern,
        engine=engine,
        return_mesh_ids=True,
        device="cpu",
        **kw,
    )
    s = SemanticLidarSensor(cfg, model, datas)
    s.update()
    return s


@pytest.mark.parametrize(
    "pattern", [LivoxPatternCfg(num_rays=20000), SpinningLidarPatternCfg.vlp16()]
)
def test_engines_agree_on_clutter(clutter_model, pattern):
    datas = random_envs(clutter_model, 3, seed=1)
    ref = _scan(clutter_model, datas, "mujoco", pattern, max_distance=30.0)
    wrp = _scan(clutter_model, datas, "warp", pattern, max_distance=30.0)
    ids_ref, ids_w = ref.get_mesh_ids(), wrp.get_mesh_ids()
    same = ids_ref == ids_w
    assert same.mean() >= 0.999, f"only {same.mean():.5f} of the geom ids agree"
    both = same & (ids_ref >= 0)
    assert both.sum() > 0.1 * ids_ref.size
    np.testing.assert_allclose(
        wrp.get_distances()[both], ref.get_distances()[both], atol=1e-5, rtol=0
    )
    np.testing.assert_array_equal(ref.get_semantic_labels()[same], wrp.get_semantic_labels()[same])
    # The ids that differ are grazing rays where two surfaces are within float32 precision.
    diff = ~same & (ids_ref >= 0) & (ids_w >= 0)
    if diff.any():
        assert np.abs(wrp.data.distances[diff] - ref.data.distances[diff]).max() < 1e-4


def test_warp_analytic_distances(analytic_model):
    axes = [(1, 0, 0), (0, 1, 0), (-1, 0, 0), (0, -1, 0), (0, 0, -1), (0, 0, 1)]
    s = _scan(
        analytic_model,
        forward(analytic_model, 2),
        "warp",
        RaysPattern(axes),
        prim_path="lidar_site",
    )
    np.testing.assert_allclose(
        s.get_distances()[:, :5], [[2.5, 2.5, 2.8, 2.5, 1.0]] * 2, atol=1e-5, rtol=0
    )
    assert (s.get_distances()[:, 5] == 100.0).all() and not s.get_hit_mask()[:, 5].any()
    hf = _scan(
        analytic_model,
        forward(analytic_model),
        "warp",
        RaysPattern([(0, 0, -1)]),
        prim_path="hf_site",
    )
    np.testing.assert_allclose(hf.get_distances()[0, 0], 2.0 - 0.4 * 0.8 / 2, atol=1e-5)


def test_warp_grid_pattern(analytic_model):
    from robotwright.sensors import GridPatternCfg

    s = _scan(
        analytic_model,
        forward(analytic_model),
        "warp",
        GridPatternCfg(resolution=0.25, size=(1.0, 0.5)),
        prim_path="lidar_site",
        offset_pos=(10.0, 10.0, 0.0),
    )
    np.testing.assert_allclose(s.get_distances(), 1.0, atol=1e-5)


def test_hfield_side_walls_differ():
    """Known difference: MuJoCo's heightfield is a solid prism; mujoco-warp's is its top only."""
    import mujoco

    xml = """<mujoco><asset><hfield name="h" nrow="3" ncol="3" size="1 1 0.5 0.2"
             elevation="1 1 1 1 1 1 1 1 1"/></asset><worldbody><site name="s" pos="-3 0 0.25"/>
             <geom name="hf" type="hfield" hfield="h"/></worldbody></mujoco>"""
    model = mujoco.MjModel.from_xml_string(xml)
    model.hfield_data[:] = 1.0
    datas = forward(model)
    # Horizontal ray into the side of the block: x=-1 is 2 m away.
    ref = _scan(model, datas, "mujoco", RaysPattern([(1, 0, 0), (1, 0, -0.2)]), prim_path="s")
    wrp = _scan(model, datas, "warp", RaysPattern([(1, 0, 0), (1, 0, -0.2)]), prim_path="s")
    np.testing.assert_allclose(ref.get_distances()[0, 0], 2.0, atol=1e-9)
    assert not wrp.get_hit_mask()[0, 0]  # documented limitation of the warp engine


def test_mujoco_warp_data_input_matches_host_envs(clutter_model):
    """Worlds simulated with mujoco-warp are scanned in place (no host MjData)."""
    import mujoco_warp as mjw
    import warp as wp

    host = random_envs(clutter_model, 3, seed=2)
    with wp.ScopedDevice("cpu"):
        mw = mjw.put_model(clutter_model)
        dw = mjw.put_data(clutter_model, host[0], nworld=3)
        dw.qpos.assign(np.stack([d.qpos for d in host]).astype(np.float32))
        mjw.kinematics(mw, dw)
    pattern = LivoxPatternCfg(num_rays=5000)
    on_device = _scan(clutter_model, dw, "warp", pattern, max_distance=30.0)
    ref = _scan(clutter_model, host, "mujoco", pattern, max_distance=30.0)
    np.testing.assert_allclose(on_device.data.pos_w, ref.data.pos_w, atol=1e-5)
    same = on_device.get_mesh_ids() == ref.get_mesh_ids()
    assert same.mean() >= 0.999
    both = same & (ref.get_mesh_ids() >= 0)
    np.testing.assert_allclose(
        on_device.get_distances()[both], ref.get_distances()[both], atol=1e-5, rtol=0
    )
    with pytest.raises(Exception, match="set engine='warp'"):
        _scan(clutter_model, dw, "mujoco", pattern)
