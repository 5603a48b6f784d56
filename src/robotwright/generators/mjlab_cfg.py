"""An mjlab ``EntityCfg`` for a robot, written as a Python module beside its MJCF.

``write_entity_cfg(hrdf, "robots/go2_entity.py")`` writes the robot alone (no floor,
light or sky: mjlab's scene adds terrain) as ``robots/go2_entity.xml``, meshes copied
beside it, and a module holding::

    ROBOT_CFG = EntityCfg(
        spec_fn=get_spec,                      # the MJCF beside the module
        init_state=EntityCfg.InitialStateCfg(pos=..., joint_pos={...}, joint_vel={".*": 0.0}),
        articulation=EntityArticulationInfoCfg(actuators=(XmlActuatorCfg(target_names_expr=(".*",)),)),
    )

The actuators are the MJCF's own (the robot's, or those ``--actuators`` and
``--actuator-gain`` gave a URDF), wrapped by mjlab's ``XmlActuatorCfg`` so that no gain
is written twice; the initial state is that of the Isaac Lab writer
(:func:`~robotwright.generators.isaaclab_cfg.initial_state`: the user's joint positions,
a free base raised to stand on z = 0). Names are Python string literals and escaped
regular expressions; nothing from the robot file is evaluated. The module imports only
mjlab, MuJoCo and ``pathlib``.
"""

from __future__ import annotations

import re
import warnings
from collections.abc import Sequence
from pathlib import Path

import mujoco

from robotwright.errors import RobotSetupWarning
from robotwright.generators.isaaclab_cfg import (
    cfg_number,
    initial_state,
    module_docstring,
    module_outputs,
    setup_warnings,
    write_module_beside,
)
from robotwright.hrdf.model import HRDF

__all__ = ["entity_cfg_source", "write_entity_cfg"]


def entity_cfg_source(
    hrdf: HRDF,
    model: mujoco.MjModel,
    xml_name: str,
    joint_pos: Sequence[tuple[str, float]] = (),
) -> str:
    """The module's text for the robot whose MJCF (compiled: ``model``) is ``xml_name``
    beside it; ``joint_pos``: ``(fnmatch pattern, position)`` pairs, first match wins."""
    pos, positions, clamped = initial_state(model, joint_pos)
    doc = [
        f"mjlab EntityCfg of the robot {hrdf.name!r}, written by robotwright.",
        "",
        f"The MJCF beside this file holds the robot and its {model.nu} actuator(s); mjlab's",
        "XmlActuatorCfg drives them with the gains written there.",
    ]
    lines = [
        module_docstring(doc, clamped),
        "",
        "from pathlib import Path",
        "",
        "import mujoco",
        "from mjlab.actuator import XmlActuatorCfg",
        "from mjlab.entity import EntityArticulationInfoCfg, EntityCfg",
        "",
        f"XML_PATH = str(Path(__file__).with_name({xml_name!r}))",
        "",
        "",
        "def get_spec() -> mujoco.MjSpec:",
        "    return mujoco.MjSpec.from_file(XML_PATH)",
        "",
        "",
        "ROBOT_CFG = EntityCfg(",
        "    spec_fn=get_spec,",
        "    init_state=EntityCfg.InitialStateCfg(",
        f"        pos=({', '.join(cfg_number(v) for v in pos)}),",
        "        joint_pos={",
    ]
    lines += [f"            {re.escape(n)!r}: {cfg_number(q)}," for n, q in positions.items()]
    lines += ["        },", "        joint_vel={'.*': 0.0},", "    ),"]
    if model.nu:
        lines += [
            "    articulation=EntityArticulationInfoCfg(",
            "        actuators=(XmlActuatorCfg(target_names_expr=('.*',)),),",
            "    ),",
        ]
    lines += [")", ""]
    return "\n".join(lines)


def write_entity_cfg(
    hrdf: HRDF,
    output: str | Path,
    *,
    overwrite: bool = False,
    joint_pos: Sequence[tuple[str, float]] = (),
) -> tuple[Path, Path]:
    """Write ``<output>`` (the module) and the robot's MJCF beside it, named after the
    module (``robots/go2_entity.py`` and ``robots/go2_entity.xml``, meshes under
    ``robots/meshes/``), both through the output gate. Each
    :func:`~robotwright.generators.isaaclab_cfg.setup_warnings` line is a
    :class:`~robotwright.errors.RobotSetupWarning`.

    Returns:
        (module path, MJCF path).
    """
    from robotwright.generators.mjcf import MJCFHumanoidGenerator

    out, xml = module_outputs(output, ".xml", overwrite)
    MJCFHumanoidGenerator.from_hrdf(hrdf).export(xml, copy_meshes=True, add_scene=False)

    def text() -> str:  # the initial state from MuJoCo's compile of the file written
        model = mujoco.MjModel.from_xml_path(str(xml))
        return entity_cfg_source(hrdf, model, xml.name, joint_pos)

    write_module_beside(out, xml, text)
    for line in setup_warnings(hrdf):
        warnings.warn(line, RobotSetupWarning, stacklevel=2)
    return out, xml
