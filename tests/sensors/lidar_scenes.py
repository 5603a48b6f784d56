"""Scenes with known geometry and helpers for the LiDAR tests."""

from __future__ import annotations

import math

import mujoco
import numpy as np

from robotwright.sensors import PatternCfg

# Analytic scene: sensor at the origin; sphere (r=0.5) centred 3 m along +x, box
# (half 0.5) 3 m along +y, capsule (r=0.2, vertical) 3 m along -x, cube mesh
# (half 0.5) 3 m along -y, floor 1 m below, a heightfield ramp 2 m above the
# sensor site "up" at x=20.
ANALYTIC_XML = """
<mujoco model="analytic">
  <compiler angle="radian"/>
  <asset>
    <mesh name="cube_mesh" vertex="-.5 -.5 -.5  .5 -.5 -.5  .5 .5 -.5  -.5 .5 -.5
                                   -.5 -.5 .5   .5 -.5 .5   .5 .5 .5   -.5 .5 .5"/>
    <hfield name="ramp" nrow="3" ncol="3" size="1 1 0.4 0.1" elevation="0 0 0 0.5 0.5 0.5 1 1 1"/>
  </asset>
  <worldbody>
    <geom name="floor" type="plane" size="50 50 0.1" pos="0 0 -1"/>
    <body name="robot" pos="0 0 0">
      <geom name="torso" type="box" size="0.1 0.1 0.1"/>
      <site name="lidar_site" pos="0 0 0"/>
      <site name="hf_site" pos="20.3 0.2 2"/>
    </body>
    <body name="ball_body" pos="3 0 0"><geom name="ball" type="sphere" size="0.5"/></body>
    <body name="crate" pos="0 3 0"><geom name="crate_geom" type="box" size="0.5 0.5 0.5"/></body>
    <body name="pillar" pos="-3 0 0"><geom name="pillar_geom" type="capsule" size="0.2 0.5"/></body>
    <body name="mesh_body" pos="0 -3 0"><geom name="cube" type="mesh" mesh="cube_mesh"/></body>
    <geom name="terrain_hf" type="hfield" hfield="ramp" pos="20 0 0"/>
  </worldbody>
</mujoco>
"""


class RaysPattern(PatternCfg):
    """A fixed list of directions (and optional origins) for tests."""

    def __init__(self, directions, origins=None) -> None:
        d = np.asarray(directions, dtype=float)
        self._dirs = d / np.linalg.norm(d, axis=1, keepdims=True)
        self._origins = (
            np.zeros_like(self._dirs) if origins is None else np.asarray(origins, dtype=float)
        )

    def _directions(self, frame: int) -> np.ndarray:
        return self._dirs

    def rays(self, frame: int = 0):
        return self._origins, self._dirs


def geom_id(model: mujoco.MjModel, name: str) -> int:
    return mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_GEOM, name)


def analytic_model() -> mujoco.MjModel:
    return mujoco.MjModel.from_xml_string(ANALYTIC_XML)


def forward(model: mujoco.MjModel, n: int = 1) -> list[mujoco.MjData]:
    datas = [mujoco.MjData(model) for _ in range(n)]
    for d in datas:
        mujoco.mj_forward(model, d)
    return datas


# A cluttered scene with every geom type, named for the default semantic classes, with
# free bodies so each environment can get its own pose.
CLUTTER_XML = """
<mujoco model="clutter">
  <compiler angle="radian"/>
  <option gravity="0 0 -9.81"/>
  <asset>
    <mesh name="SM_Sofa_mesh" vertex="-.6 -.3 0  .6 -.3 0  .6 .3 0  -.6 .3 0  -.6 -.3 .5  .6 -.3 .5  .6 .3 .5  -.6 .3 .5"/>
    <hfield name="bumps" nrow="32" ncol="32" size="4 4 0.6 0.1"/>
  </asset>
  <worldbody>
    <geom name="ground" type="plane" size="30 30 0.1"/>
    <geom name="wall_north" type="box" size="8 0.1 1.5" pos="0 8 1.5"/>
    <geom name="rough_floor" type="hfield" hfield="bumps" pos="-10 0 -0.0001"/>
    <body name="robot" pos="0 0 0.6">
      <freejoint name="robot_root"/>
      <geom name="base" type="box" size="0.3 0.15 0.08" mass="5"/>
      <site name="lidar" pos="0.2 0 0.12"/>
      <body name="leg" pos="0 0 -0.2"><joint name="hip" axis="0 1 0"/><geom name="shin" type="capsule" size="0.03 0.15"/></body>
    </body>
    <body name="cracker_box_0" pos="2.5 0.5 0.3"><freejoint/><geom name="_03_cracker_box" type="box" size="0.1 0.05 0.15"/></body>
    <body name="tomato_soup_can_1" pos="2 -1.5 0.1"><freejoint/><geom type="cylinder" size="0.05 0.1"/></body>
    <body name="sugar_box_2" pos="-2 1.5 0.2"><freejoint/><geom type="ellipsoid" size="0.1 0.2 0.15"/></body>
    <body name="sofa_1" pos="-3 -2 0"><geom name="sofa_seat" type="mesh" mesh="SM_Sofa_mesh"/></body>
    <body name="dining_table" pos="4 -3 0.4"><geom name="top" type="box" size="0.8 0.5 0.03"/>
      <geom name="leg_a" type="cylinder" size="0.03 0.2" pos="0.7 0.4 -0.2"/></body>
    <body name="armchair" pos="-4 3 0.4"><geom type="capsule" size="0.3 0.4" euler="0 1.5707963 0"/></body>
    <body name="lamp" pos="3 3 1"><geom name="lamp_shade" type="sphere" size="0.3"/></body>
  </worldbody>
</mujoco>
"""


def clutter_model() -> mujoco.MjModel:
    model = mujoco.MjModel.from_xml_string(CLUTTER_XML)
    # Bumpy heightfield (MuJoCo keeps data in [0, 1], scaled by the elevation size) with a
    # zero border: its solid sides then stay under the ground plane. (mujoco-warp's
    # heightfield has no side walls; see test_hfield_side_walls_differ.)
    bumps = np.random.default_rng(7).random((32, 32))
    bumps[[0, -1], :] = 0.0
    bumps[:, [0, -1]] = 0.0
    model.hfield_data[:] = bumps.ravel()
    return model


def random_envs(model: mujoco.MjModel, n: int, seed: int = 0) -> list[mujoco.MjData]:
    """``n`` environments with the robot and free objects moved and turned at random."""
    rng = np.random.default_rng(seed)
    datas = forward(model, n)
    for d in datas:
        for j in range(model.njnt):
            if model.jnt_type[j] != mujoco.mjtJoint.mjJNT_FREE:
                continue
            a = model.jnt_qposadr[j]
            d.qpos[a : a + 2] += rng.uniform(-0.5, 0.5, 2)
            yaw = rng.uniform(-math.pi, math.pi)
            d.qpos[a + 3 : a + 7] = [math.cos(yaw / 2), 0.0, 0.0, math.sin(yaw / 2)]
        mujoco.mj_forward(model, d)
    return datas
