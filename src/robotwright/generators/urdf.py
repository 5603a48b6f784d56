"""``URDFHumanoidGenerator``: one HRDF robot (any tree) to URDF.

Mapping:

- A ``world`` link, joined to the root link by a ``floating`` joint (floating base; named
  after the HRDF free joint, else ``floating_base``) or a ``fixed`` joint (fixed base),
  whose origin is the root body's pose.
- Each body -> a link with ``<inertial>`` (mass, centre of mass, the full inertia tensor
  ``R diag R^T`` from ``diag_inertia`` and ``inertial_quat``), a ``<collision>`` for each
  geom that collides (contype or conaffinity non-zero) and a ``<visual>`` (with a
  ``<material>`` of the geom's rgba) for each geom MuJoCo draws (see
  :func:`drawn_by_mujoco`) or that does not collide. A geom that both collides and is
  drawn gives a visual and a collision of the same geometry and origin; the URDF parser
  reads such a pair back as one geom.
- Each joint -> ``revolute`` (hinge with range), ``continuous`` (hinge without range),
  ``prismatic`` (slide); a ball joint -> three revolute/continuous joints about x, y, z
  (a change of meaning: reported). ``<limit>`` carries the range and, from the joint's
  actuator, ``effort`` (peak torque or force range) and ``velocity`` (peak velocity);
  ``<dynamics damping friction>`` from viscous/dynamic friction.
- A body with several joints becomes a chain of links ``<body>_dummy<k>``, one per
  joint; joint anchors (``Joint.pos``) become the joint origins, so the kinematics are
  those of the MJCF model. Each dummy link gets 1e-9 kg and 1e-12 kg m^2 (MuJoCo refuses
  massless moving links and SDFormat/Gazebo drops them); reported.
- A hinge/slide ``ref`` (MJCF: the body is at its ``pos``/``quat`` when q = ref) is baked
  into the joint origin as a motion of -ref about/along the axis, so the URDF joint
  coordinate, its limits and the FK at any q equal MJCF's; URDF has no initial position,
  so its default pose is q = 0, not q = ref (reported).
- Sites and IMUs -> massless links on fixed joints (tool and sensor frames); a site named
  like a body (or the world link) becomes ``<site>_site`` (reported).
- Capsules have no URDF form: each is written as a cylinder plus two end spheres (the
  same shape) and reported; ellipsoids are dropped and reported.

Everything URDF cannot hold (armature, stiffness, springref, actuator types and gains,
geom friction/contact bits/condim/groups, colours of colliding geoms MuJoCo does not draw,
restitution, sensors, ``mjcf_extra``) is listed in one :class:`ConversionWarning` (``strict=True``: raised as
:class:`ConversionError`).
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from typing import Any

from robotwright.errors import Problem
from robotwright.generators.mixin import HRDFMixin
from robotwright.generators.mjcf import _report
from robotwright.generators.mjcf_base import fill_option
from robotwright.generators.urdf_base import (
    WORLD_LINK,
    URDFGeneratorBase,
)
from robotwright.generators.urdf_writer import (
    DUMMY_LINK_INERTIA,
    DUMMY_LINK_MASS,
    MUJOCO_DRAWN_GROUPS,
    _RobotWriter,
    drawn_by_mujoco,
)
from robotwright.hrdf.model import (
    SimulatorConfig,
)


class URDFHumanoidGenerator(HRDFMixin, URDFGeneratorBase):
    """HRDF robot -> URDF. Works for any tree robot, floating or fixed base.

    Example::

        gen = URDFHumanoidGenerator.from_robot_name("arm6")
        gen.export("out/arm6.urdf", add_mujoco_tag=True)

    After ``generate``/``export``, two maps tell readers of the file which links are not
    bodies of the robot: :attr:`dummy_links` (link name -> the body whose joints it
    splits, including anchor links) and :attr:`frame_links` (site/IMU name -> its link
    name; differs from the site name only where it was renamed). A third tells which
    joints stand for a ball joint: :attr:`split_joints` (ball joint name -> its revolute
    joints about the body's x, y and z axes, parent side first, so that a rotation ``R``
    of the ball is ``Rx(a) Ry(b) Rz(c)``). All are empty until a tree is generated and
    are dropped with it.
    """

    dummy_links: dict[str, str]
    frame_links: dict[str, str]
    split_joints: dict[str, tuple[str, str, str]]

    def __init__(self, **kwargs: Any) -> None:
        super().__init__(**kwargs)
        self.dummy_links = {}
        self.frame_links = {}
        self.split_joints = {}

    def _destroy(self) -> None:
        self.dummy_links = {}
        self.frame_links = {}
        self.split_joints = {}

    def _robot_name(self) -> str:
        return self.hrdf.name if self.hrdf is not None else "robot"

    def _generate(
        self,
        add_mujoco_tag: bool = False,
        relative_mesh_path: bool = True,
        *,
        prefix: str | None = None,
        world_link: bool = True,
        strict: bool = False,
    ) -> None:
        """Build the URDF tree.

        Args:
            add_mujoco_tag: add ``<mujoco><compiler .../></mujoco>`` so MuJoCo loads the
                file with its meshes, visual geoms and every link.
            relative_mesh_path: mesh paths relative to the output folder when exporting to
                a file; absolute otherwise.
            prefix: prepended as ``<prefix>_`` to every link, joint and material name
                (not to ``world``).
            world_link: write the ``world`` link (a composite writes it once itself).
            strict: raise :class:`ConversionError` instead of warning about lost values.
        """
        hrdf = self.loaded_hrdf
        losses: list[Problem] = []
        root = self.xml_root
        if add_mujoco_tag:
            mj = ET.SubElement(root, "mujoco")
            ET.SubElement(mj, "compiler", self.mujoco_compiler_attrs())
            # MuJoCo's URDF import reads <option> (with <flag>) and <size> here too.
            sim = hrdf.meta.simulator_config
            if sim is not None and (sim.option or sim.flag):
                option = ET.SubElement(mj, "option")
                fill_option(option, SimulatorConfig(None, None, None, None, sim.option, sim.flag))
            if hrdf.meta.mjcf_size:
                ET.SubElement(
                    mj, "size", {k: str(int(v)) for k, v in sorted(hrdf.meta.mjcf_size.items())}
                )
        else:
            sim = hrdf.meta.simulator_config
            if sim is not None and (sim.option or sim.flag):
                losses.append(
                    Problem(
                        "meta.yaml",
                        "<option> attributes and flags need the <mujoco> tag (add_mujoco_tag)",
                        column="simulator_config.option",
                    )
                )
        if world_link:
            ET.SubElement(root, "link", {"name": WORLD_LINK})
        writer = _RobotWriter(self, hrdf, prefix, relative_mesh_path, losses)
        writer.write(root)
        self.dummy_links = dict(writer.dummy_links)
        self.frame_links = {k: writer.p(v) for k, v in writer.frame_links.items()}
        self.split_joints = dict(writer.split_joints)
        _report(hrdf, "URDF", losses, strict)


__all__ = [
    "DUMMY_LINK_INERTIA",
    "DUMMY_LINK_MASS",
    "MUJOCO_DRAWN_GROUPS",
    "URDFHumanoidGenerator",
    "drawn_by_mujoco",
]
