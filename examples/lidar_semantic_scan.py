"""Semantic LiDAR scan of a small room: per-ray classes from geom names, saved as NPZ + PNG.

Run: python examples/lidar_semantic_scan.py [OUT_DIR]
"""

from __future__ import annotations

import sys
from pathlib import Path

import mujoco
import numpy as np

from robotwright.sensors import (
    LivoxPatternCfg,
    SemanticLidarCfg,
    SemanticLidarSensor,
    scan_to_files,
)

ROOM = """
<mujoco model="room">
  <compiler angle="radian"/>
  <worldbody>
    <geom name="floor" type="plane" size="10 10 0.1"/>
    <geom name="wall_east" type="box" size="0.1 5 1.5" pos="5 0 1.5"/>
    <geom name="wall_north" type="box" size="5 0.1 1.5" pos="0 5 1.5"/>
    <body name="robot" pos="0 0 0.4">
      <freejoint/>
      <geom name="base" type="box" size="0.3 0.15 0.1"/>
      <site name="lidar" pos="0.2 0 0.15"/>
    </body>
    <body name="cracker_box_0" pos="2 1 0.5"><freejoint/><geom type="box" size="0.25 0.2 0.5"/></body>
    <body name="tomato_soup_can_0" pos="1.5 -1.5 0.5"><freejoint/><geom type="cylinder" size="0.2 0.5"/></body>
    <body name="SM_Sofa_1" pos="-2 2 0.3"><geom type="box" size="0.9 0.4 0.3"/></body>
    <body name="dining_table" pos="3 -2 0.7"><geom type="box" size="0.6 0.4 0.03"/></body>
    <body name="plant" pos="-3 -3 0.5"><geom type="capsule" size="0.2 0.3"/></body>
  </worldbody>
</mujoco>
"""


def main(out_dir: Path) -> None:
    model = mujoco.MjModel.from_xml_string(ROOM)
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)

    # Default class mapping (terrain / dynamic_obstacle / valuable), Mid-360-like pattern.
    cfg = SemanticLidarCfg(prim_path="lidar", pattern_cfg=LivoxPatternCfg(), max_distance=40.0)
    lidar = SemanticLidarSensor(cfg, model, data)
    lidar.update()
    distances = lidar.get_distances()  # (1, 20000), inf = miss
    points = lidar.get_pointcloud()  # (1, 20000, 3), NaN = miss
    labels = lidar.get_semantic_labels()  # (1, 20000), 0 = miss/unknown
    hit = lidar.get_hit_mask()
    print(f"{int(hit.sum())} of {lidar.num_rays} rays hit something within {lidar.max_distance} m")
    for class_id, name in enumerate(lidar.class_names):
        pts = points[hit & (labels == class_id)]
        print(f"class {class_id} {name:17s} {len(pts):6d} points")
    print(f"nearest obstacle: {np.nanmin(distances[labels == 2]):.3f} m")

    # One call for files (what `robotwright lidar` does).
    out_dir.mkdir(parents=True, exist_ok=True)
    summary = scan_to_files(
        model, data, "lidar", "mid360", out_dir / "room.npz", out_dir / "room.png"
    )
    counts = ", ".join(f"{name} {n}" for name, n in summary["class_counts"].items())
    print(f"{summary['num_hits']} of {summary['num_rays']} rays hit ({counts})")
    print(f"wrote {summary['npz']} (distances, points, labels, geom ids) and {summary['png']}")


if __name__ == "__main__":
    main(Path(sys.argv[1]) if len(sys.argv) > 1 else Path("lidar_example_out"))
