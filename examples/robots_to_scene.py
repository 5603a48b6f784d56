"""Load a hurodes-style HRDF robot, convert it both ways, and build a two-robot scene.

Run: python examples/robots_to_scene.py [OUT_DIR]   (default ./robots_to_scene)

1. load the bundled humanoid (any HRDF folder works: ``HRDF.from_dir(path)``);
2. export MJCF and URDF with the seed-000 generators;
3. parse the URDF back into HRDF and check that MuJoCo sees the same robot;
4. place the humanoid and the bundled arm in one scene and simulate one second.
"""

from __future__ import annotations

import sys
import warnings
from pathlib import Path

import mujoco
import numpy as np

from robotwright.errors import ConversionWarning
from robotwright.generators import MJCFHumanoidGenerator, URDFHumanoidGenerator
from robotwright.hrdf import HRDF
from robotwright.parsers import urdf_to_hrdf
from robotwright.tasks import compose_scene


def main(out_dir: str = "robots_to_scene") -> None:
    out = Path(out_dir)
    humanoid = HRDF.from_robot_name("mini_humanoid")
    print(
        f"{humanoid.name}: {len(humanoid.bodies)} bodies, {humanoid.dof} DoF, {humanoid.total_mass:.2f} kg"
    )

    with warnings.catch_warnings(record=True) as notes:
        warnings.simplefilter("always", ConversionWarning)
        MJCFHumanoidGenerator.from_hrdf(humanoid).export(out / "humanoid.xml")
        URDFHumanoidGenerator.from_hrdf(humanoid).export(out / "humanoid.urdf", add_mujoco_tag=True)
    print(
        f"wrote humanoid.xml and humanoid.urdf ({len(notes)} conversion note(s): values URDF cannot hold)"
    )

    back = urdf_to_hrdf(out / "humanoid.urdf")
    a = mujoco.MjModel.from_xml_path(str(out / "humanoid.xml"))
    b = MJCFHumanoidGenerator.from_hrdf(back).to_model()
    print(
        f"URDF -> HRDF -> MJCF: total mass {b.body_mass.sum():.6f} kg (MJCF: {a.body_mass.sum():.6f} kg)"
    )

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ConversionWarning)  # same notes as above
        scene = compose_scene(
            {"h": humanoid, "arm": "arm6"},
            out / "scene.xml",
            placements={"h": (0.0, 0.0, 0.0, 0.0), "arm": (1.0, 0.0, 0.0, np.pi)},
        )
    model = mujoco.MjModel.from_xml_path(str(scene))
    data = mujoco.MjData(model)
    steps = int(1.0 / model.opt.timestep)
    for _ in range(steps):
        mujoco.mj_step(model, data)
    print(
        f"scene.xml: {model.nbody - 1} bodies, {model.nu} actuators; simulated {steps} steps, "
        f"humanoid pelvis height {data.body('h_pelvis').xpos[2]:.3f} m"
    )


if __name__ == "__main__":
    main(*sys.argv[1:])
