"""``URDFGeneratorComposite``: several robots in one URDF under a single ``world`` link.

Each robot's links, joints and materials are prefixed with its key (``<key>_<name>``);
its root hangs from ``world`` through its own floating/fixed joint placed at its
:class:`Placement`, or is welded (fixed joint) to a site/body link of another robot.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

from robotwright.errors import GeneratorError, Problem
from robotwright.generators.mjcf import _report
from robotwright.generators.placement import Placement, composite_members
from robotwright.generators.urdf import URDFHumanoidGenerator
from robotwright.generators.urdf_base import WORLD_LINK, URDFGeneratorBase
from robotwright.generators.urdf_writer import _RobotWriter
from robotwright.generators.xmlfmt import prefixed


class URDFGeneratorComposite(URDFGeneratorBase):
    """Several loaded :class:`URDFHumanoidGenerator` robots merged into one URDF.

    Args:
        generators: ``{key: generator}`` (or a list, keyed ``generator0``, ...).
        placements: ``{key: Placement | (x, y, z[, yaw])}``. An attached robot
            (``Placement(parent=..., frame=...)``) is welded to the parent's link of that
            name (a site link or a body link); the pose is relative to that link's frame.
        name: the ``<robot name>``.
    """

    def __init__(
        self,
        generators: Mapping[str, URDFHumanoidGenerator] | Sequence[URDFHumanoidGenerator],
        placements: Mapping[str, Placement | Sequence[float]] | None = None,
        name: str = "scene",
    ) -> None:
        super().__init__()
        self.generators: dict[str, URDFHumanoidGenerator]
        self.placements: dict[str, Placement]
        self.generators, self.placements = composite_members(
            "URDFGeneratorComposite",
            generators,
            placements,
            URDFHumanoidGenerator,
            "a URDFHumanoidGenerator",
        )
        self.name = name

    @property
    def loaded(self) -> bool:
        return all(g.loaded for g in self.generators.values())

    def _load(self, *args: Any, **kwargs: Any) -> None:
        missing = [k for k, g in self.generators.items() if not g.loaded]
        if args or kwargs or missing:
            raise GeneratorError(
                f"URDFGeneratorComposite.load() takes no data; load the held generators "
                f"(not loaded: {missing})"
            )

    def _clean(self) -> None:
        for g in self.generators.values():
            g.clean()

    def _robot_name(self) -> str:
        return self.name

    def mesh_sources(self) -> list[tuple[str, Path]]:
        out: list[tuple[str, Path]] = []
        for g in self.generators.values():
            out.extend(g.mesh_sources())
        return out

    def _generate(
        self,
        add_mujoco_tag: bool = False,
        relative_mesh_path: bool = True,
        *,
        strict: bool = False,
    ) -> None:
        """Write every robot (prefixed with its key) under one ``world`` link."""
        root = self.xml_root
        if add_mujoco_tag:
            mj = ET.SubElement(root, "mujoco")
            ET.SubElement(mj, "compiler", self.mujoco_compiler_attrs())
        ET.SubElement(root, "link", {"name": WORLD_LINK})
        # Parents first, so an attached robot's parent link exists when it is written.
        order = self._order()
        for key in order:
            gen = self.generators[key]
            hrdf = gen.loaded_hrdf
            losses: list[Problem] = []
            writer = _RobotWriter(self, hrdf, key, relative_mesh_path, losses, robot_gen=gen)
            p = self.placements.get(key)
            if p is not None and p.parent is not None:
                parent_link = prefixed(p.parent, p.frame or "")
                names = {el.get("name") for el in root.findall("link")}
                if parent_link not in names:
                    raise GeneratorError(
                        f"robot '{p.parent}' has no site or body named '{p.frame}' to attach "
                        f"'{key}' at"
                    )
                writer.write(root, parent_link, (p.pos, p.quat), fixed_root=True)
            else:
                writer.write(root, WORLD_LINK, None if p is None else (p.pos, p.quat))
            _report(hrdf, "URDF", losses, strict)
        for kind in ("link", "joint", "material"):
            seen: set[str] = set()
            dup = sorted(
                {
                    n
                    for n in (el.get("name", "") for el in root.findall(kind))
                    if n in seen or seen.add(n)  # type: ignore[func-returns-value]
                }
            )
            if dup:
                raise GeneratorError(f"composite URDF: {kind} name(s) used twice: {dup}")

    def _order(self) -> list[str]:
        done: list[str] = []
        pending = list(self.generators)
        while pending:
            progressed = False
            for key in list(pending):
                p = self.placements.get(key)
                if p is None or p.parent is None or p.parent in done:
                    done.append(key)
                    pending.remove(key)
                    progressed = True
            if not progressed:
                raise GeneratorError(f"robots attached in a cycle: {pending}")
        return done


__all__ = ["URDFGeneratorComposite"]
