"""Many environments, one sensor: scans follow the simulation, batched engines agree.

Each environment is its own MjData (the robot starts at a different place); after
mj_step the next update() sees the new poses. Uses the warp engine when the optional
extra is installed (pip install 'robotwright[warp]'), else the threaded mj_multiRay one.

Run: python examples/lidar_batched_envs.py
"""

from __future__ import annotations

import math

import mujoco
import numpy as np

from robotwright.sensors import (
    SemanticLidarCfg,
    SemanticLidarSensor,
    SpinningLidarPatternCfg,
    warp_available,
)

SCENE = """
<mujoco>
  <option timestep="0.01"/>
  <worldbody>
    <geom name="ground" type="plane" size="20 20 0.1"/>
    <body name="robot" pos="0 0 0.5">
      <freejoint/>
      <geom name="base" type="box" size="0.3 0.15 0.1" mass="5"/>
      <site name="lidar" pos="0 0 0.2"/>
    </body>
    <body name="sugar_box_0" pos="3 0 0.3"><geom type="box" size="0.3 0.3 0.3"/></body>
    <body name="armchair_0" pos="0 3 0.4"><geom type="ellipsoid" size="0.5 0.4 0.4"/></body>
  </worldbody>
</mujoco>
"""


def main(num_envs: int = 8) -> None:
    model = mujoco.MjModel.from_xml_string(SCENE)
    datas = []
    for e in range(num_envs):
        d = mujoco.MjData(model)
        d.qpos[0] = -1.0 + 0.25 * e  # robots spread along x
        mujoco.mj_forward(model, d)
        datas.append(d)

    engine = "warp" if warp_available() else "mujoco"
    cfg = SemanticLidarCfg(
        prim_path="lidar",
        pattern_cfg=SpinningLidarPatternCfg.vlp16(horizontal_resolution=math.radians(1.0)),
        ray_alignment="yaw",  # rays stay level when the robot tilts
        range_noise_std=0.01,
        engine=engine,
    )
    lidar = SemanticLidarSensor(cfg, model, datas)
    for step in range(3):
        lidar.update()
        dist = lidar.get_distances()  # (num_envs, 16 * 360)
        labels = lidar.get_semantic_labels()
        box_range = np.where(labels == 2, dist, np.inf).min(axis=1)
        print(f"step {step}: nearest sugar box per env [m]: {np.round(box_range, 2)}")
        for d in datas:
            for _ in range(10):
                mujoco.mj_step(model, d)  # the robots fall 0.1 s; the next scan sees it
    print(f"engine={engine}, {lidar.num_envs} envs x {lidar.num_rays} rays")


if __name__ == "__main__":
    main()
