"""Generators: HRDF robots to MJCF and URDF, and multi-robot composites.

>>> from robotwright.generators import MJCFHumanoidGenerator
>>> gen = MJCFHumanoidGenerator.from_robot_name("mini_humanoid")  # doctest: +SKIP
>>> gen.export("out/robot.xml")                                     # doctest: +SKIP
"""

from typing import TYPE_CHECKING

from robotwright._lazy import attach

if TYPE_CHECKING:
    from robotwright.generators.base import GeneratorBase
    from robotwright.generators.composite import MJCFGeneratorComposite
    from robotwright.generators.composite_urdf import URDFGeneratorComposite
    from robotwright.generators.mixin import HRDFMixin
    from robotwright.generators.mjcf import MJCFHumanoidGenerator
    from robotwright.generators.mjcf_base import DEFAULT_SCENE, MJCFGeneratorBase, SceneDefaults
    from robotwright.generators.placement import Placement
    from robotwright.generators.urdf import URDFHumanoidGenerator
    from robotwright.generators.urdf_base import URDFGeneratorBase
    from robotwright.generators.usd import UsdExport, to_usd
    from robotwright.generators.usd_proof import UsdProof, prove_usd

__all__ = [
    "DEFAULT_SCENE",
    "GeneratorBase",
    "HRDFMixin",
    "MJCFGeneratorBase",
    "MJCFGeneratorComposite",
    "MJCFHumanoidGenerator",
    "Placement",
    "SceneDefaults",
    "URDFGeneratorBase",
    "URDFGeneratorComposite",
    "URDFHumanoidGenerator",
    "UsdExport",
    "UsdProof",
    "prove_usd",
    "to_usd",
]

attach(__name__, __file__)
