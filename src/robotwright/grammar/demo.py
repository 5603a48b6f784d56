"""One call for ``robotwright demo``: grow a limb, mount it on a robot, write the files."""

from __future__ import annotations

import math
import warnings
from pathlib import Path

from robotwright._names import file_stem
from robotwright.errors import ConversionWarning
from robotwright.grammar import default_grammar, demo_limb_design
from robotwright.grammar.export import export_design, export_mjcf, export_urdf
from robotwright.grammar.mount import mount_on
from robotwright.hrdf.model import HRDF

# The limb's z axis (its base normal) along the site's -x: worn on the back, pointing
# backwards. Rotation of -90 deg about y, as (w, x, y, z).
BACKWARDS = (math.sqrt(0.5), 0.0, -math.sqrt(0.5), 0.0)


def write_mounted_limb(
    out: str | Path,
    robot: HRDF | None = None,
    *,
    seed: int = 0,
    at: str = "back_mount",
    quat: tuple[float, float, float, float] = BACKWARDS,
) -> dict[str, object]:
    """Write ``out/limb/`` (the design's MJCF, URDF, text, JSON, DOT, picture) and
    ``out/<robot>_with_srl.xml`` / ``.urdf`` (the robot wearing the limb at ``at``).

    Args:
        out: output folder (created).
        robot: host robot; default: the bundled ``mini_humanoid``.
        seed: design seed (same seed, same limb).
        at: body or site of ``robot`` that carries the limb's base.
        quat: limb orientation relative to that frame (w, x, y, z).

    Returns:
        A summary: design hash and text, limb DoF and mass, mounted robot DoF and
        mass, and the paths written.
    """
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    robot = robot if robot is not None else HRDF.from_robot_name("mini_humanoid")
    g = default_grammar()
    design = demo_limb_design(seed)
    from robotwright.grammar.build import build_hrdf

    limb = build_hrdf(g, design)
    both = mount_on(robot, limb, at, quat=quat)
    with warnings.catch_warnings():
        # the limb's folder records these in warnings.txt; the mounted robot repeats them
        warnings.simplefilter("ignore", ConversionWarning)
        limb_dir = export_design(g, design, out / "limb", overwrite=True)
        stem = file_stem(robot.name, "robot")
        xml = out / f"{stem}_with_srl.xml"
        urdf = out / f"{stem}_with_srl.urdf"
        export_mjcf(both, xml)
        export_urdf(both, urdf)
    return {
        "design_hash": design.hash(),
        "design": str(design),
        "limb_dof": limb.dof,
        "limb_mass_kg": limb.total_mass,
        "mounted_on": f"{robot.name}:{at}",
        "robot_dof": both.dof,
        "robot_mass_kg": both.total_mass,
        "files": [str(limb_dir), str(xml), str(urdf)],
    }
