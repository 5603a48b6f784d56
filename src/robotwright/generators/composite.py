"""``MJCFGeneratorComposite``: several MJCF generators merged into one scene.

Each held generator is generated with its own prefix (its key in ``generators``), its
top-level sections are merged (``compiler``/``option`` once, identical mesh assets
de-duplicated, ``worldbody``, ``actuator``, ``sensor``, ``contact``, ``equality``,
``tendon``, ...), mesh paths are rebased on their common folder, and the scene is added
once. Beyond hurodes: each robot gets a :class:`Placement` (position + yaw, or a site/
body of another robot to attach at), robots' keyframes merge into scene keyframes, and a
name used twice is a :class:`GeneratorError` before anything is written.
"""

from __future__ import annotations

import os
import warnings
import xml.etree.ElementTree as ET
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

from robotwright._suggest import did_you_mean
from robotwright.errors import ConversionWarning, GeneratorError
from robotwright.generators.mjcf_base import MJCFGeneratorBase, name_clashes
from robotwright.generators.placement import Placement, compose, composite_members, qrot
from robotwright.generators.xmlfmt import fmt_vec, prefixed
from robotwright.hrdf.model import SimulatorConfig

_ORIENTATION_ATTRS = ("axisangle", "euler", "xyaxes", "zaxis")
_QPOS_SIZE = {"free": 7, "ball": 4, "hinge": 1, "slide": 1}
_QVEL_SIZE = {"free": 6, "ball": 3, "hinge": 1, "slide": 1}


def _floats(text: str | None, default: tuple[float, ...]) -> tuple[float, ...]:
    return default if text is None else tuple(float(v) for v in text.split())


def _pose(el: ET.Element) -> tuple[tuple[float, ...], tuple[float, ...]]:
    for attr in _ORIENTATION_ATTRS:
        if el.get(attr) is not None:
            raise GeneratorError(
                f"<{el.tag} name='{el.get('name')}'>: orientation given as '{attr}'; a "
                "composite can only place elements oriented with 'quat'"
            )
    return _floats(el.get("pos"), (0.0, 0.0, 0.0)), _floats(el.get("quat"), (1.0, 0.0, 0.0, 0.0))


def _set_pose(el: ET.Element, pos: tuple[float, ...], quat: tuple[float, ...]) -> None:
    el.set("pos", fmt_vec(pos))
    if el.tag != "light":
        el.set("quat", fmt_vec(quat))


class _Joint:
    """A joint of one robot's tree, in qpos order, with its default value."""

    __slots__ = ("elem", "type", "qpos0", "top")

    def __init__(self, elem: ET.Element, jtype: str, qpos0: list[float], top: bool) -> None:
        self.elem, self.type, self.qpos0, self.top = elem, jtype, qpos0, top


def _joints(worldbody: ET.Element) -> list[_Joint]:
    """Joints in MuJoCo's order (bodies depth first, joints in body order)."""
    out: list[_Joint] = []
    top = set(id(b) for b in worldbody.findall("body"))
    for body in worldbody.iter("body"):
        for el in body:
            if el.tag == "freejoint" or (el.tag == "joint" and el.get("type") == "free"):
                pos, quat = _pose(body)
                out.append(_Joint(el, "free", [*pos, *quat], id(body) in top))
            elif el.tag == "joint":
                jtype = el.get("type", "hinge")
                if jtype == "ball":
                    out.append(_Joint(el, "ball", [1.0, 0.0, 0.0, 0.0], False))
                else:
                    out.append(_Joint(el, jtype, [float(el.get("ref", "0"))], False))
    return out


class _Robot:
    """What the composite keeps of one generated robot while merging."""

    def __init__(self, key: str, prefix: str | None, root: ET.Element) -> None:
        self.key, self.prefix, self.root = key, prefix, root
        self.worldbody = root.find("worldbody")
        self.top = [] if self.worldbody is None else list(self.worldbody)
        self.joints = [] if self.worldbody is None else _joints(self.worldbody)
        actuators = root.find("actuator")
        self.nu = 0 if actuators is None else len(actuators)
        self.keys: dict[str, dict[str, list[float]]] = {}
        self.key_time: dict[str, str] = {}
        keyframe = root.find("keyframe")
        for key in [] if keyframe is None else keyframe.findall("key"):
            name = key.get("name", "")
            if prefix and name.startswith(prefix + "_"):
                name = name[len(prefix) + 1 :]
            self.keys[name] = {
                a: [float(v) for v in key.get(a, "").split()]
                for a in ("qpos", "qvel", "ctrl")
                if key.get(a) is not None
            }
            if key.get("time") is not None:
                self.key_time[name] = key.get("time", "0")
            dropped = [a for a in ("act", "mpos", "mquat") if key.get(a) is not None]
            if dropped:
                warnings.warn(
                    f"composite robot '{self.key}': keyframe '{name}' {dropped} not merged",
                    ConversionWarning,
                    stacklevel=6,
                )

    def key_values(self, name: str) -> dict[str, list[float]] | None:
        """This robot's values for scene key ``name``: its own key of that name, else its
        ``home`` key, else its first key, else ``None`` (use defaults)."""
        if name in self.keys:
            return self.keys[name]
        if "home" in self.keys:
            return self.keys["home"]
        return next(iter(self.keys.values()), None)


class MJCFGeneratorComposite(MJCFGeneratorBase):
    """Several MJCF generators merged into one MuJoCo scene.

    It does not load anything: the held generators are loaded beforehand (or later, from
    outside); ``loaded`` is true when all of them are.

    Args:
        generators: ``{key: generator}`` (or a list, keyed ``generator0``, ...). The key is
            each robot's name prefix.
        placements: ``{key: Placement | (x, y, z) | (x, y, z, yaw)}``; robots without one
            stay where their own description puts them.
        simulator_config: ``<option>`` and ground settings; default: the first robot's.

    Example::

        scene = MJCFGeneratorComposite(
            {"a": MJCFHumanoidGenerator.from_robot_name("mini_humanoid"),
             "b": MJCFHumanoidGenerator.from_robot_name("mini_humanoid")},
            placements={"b": Placement(pos=(1.0, 0.0, 0.0), yaw=3.1416)},
        )
        scene.export("scene.xml")
    """

    def __init__(
        self,
        generators: Mapping[str, MJCFGeneratorBase] | Sequence[MJCFGeneratorBase],
        placements: Mapping[str, Placement | Sequence[float]] | None = None,
        simulator_config: SimulatorConfig | None = None,
    ) -> None:
        super().__init__(simulator_config=simulator_config)
        self.generators: dict[str, MJCFGeneratorBase]
        self.placements: dict[str, Placement]
        self.generators, self.placements = composite_members(
            "MJCFGeneratorComposite", generators, placements, MJCFGeneratorBase, "an MJCF generator"
        )
        self._check_attach_cycles()
        self._own_simulator_config = simulator_config

    def _check_attach_cycles(self) -> None:
        for start in self.placements:
            seen = [start]
            p = self.placements.get(start)
            while p is not None and p.parent is not None:
                if p.parent in seen:
                    raise GeneratorError(f"robots attached in a cycle: {seen + [p.parent]}")
                seen.append(p.parent)
                p = self.placements.get(p.parent)

    # -- lifecycle ----------------------------------------------------------------------
    @property
    def loaded(self) -> bool:
        """True when every held generator is loaded."""
        return all(g.loaded for g in self.generators.values())

    def _load(self, *args: Any, **kwargs: Any) -> None:
        if args or kwargs:
            raise GeneratorError(
                "MJCFGeneratorComposite.load() takes no data: load each held generator"
            )
        missing = [k for k, g in self.generators.items() if not g.loaded]
        if missing:
            raise GeneratorError(
                f"MJCFGeneratorComposite: generator(s) {missing} not loaded; load them first"
            )

    def _clean(self) -> None:
        for g in self.generators.values():
            g.clean()

    def _destroy(self) -> None:
        for g in self.generators.values():
            g.destroy()

    def _model_name(self) -> str:
        return "scene"

    def mesh_sources(self) -> list[tuple[str, Path]]:
        out: list[tuple[str, Path]] = []
        for g in self.generators.values():
            out.extend(g.mesh_sources())
        return out

    # -- generation ---------------------------------------------------------------------
    def _generate(
        self,
        prefix: str | None = None,
        add_scene: bool = True,
        relative_mesh_path: bool = True,
        *,
        use_keys_as_prefix: bool = True,
        skybox: bool = True,
    ) -> None:
        """Generate every held robot and merge them.

        Args:
            prefix: prepended to every robot's prefix (``<prefix>_<key>_<name>``).
            add_scene: add the ground, light and sky once.
            relative_mesh_path: mesh paths relative to the output folder when exporting.
            use_keys_as_prefix: prefix each robot's names with its key; with ``False``
                names are kept and any clash is an error.
            skybox: with ``add_scene``, also add the gradient skybox.
        """
        robots: list[_Robot] = []
        for key, gen in self.generators.items():
            child_prefix = prefixed(prefix, key) if use_keys_as_prefix else prefix
            gen._check_names = False
            try:
                gen.generate(prefix=child_prefix, add_scene=False, relative_mesh_path=False)
            finally:
                gen._check_names = True
            robots.append(_Robot(key, child_prefix, gen.xml_root))
        if self._own_simulator_config is None:
            self.simulator_config = self._robots_simulator_config()
        self.add_compiler()
        self.add_option()
        self._merge(robots)
        self._place(robots)
        self._merge_keyframes(robots)
        if add_scene:
            self.add_scene(skybox=skybox)
        clashes = name_clashes(self.xml_root)
        if clashes:
            hint = "" if use_keys_as_prefix else " (use_keys_as_prefix=False keeps names as is)"
            raise GeneratorError(f"composite: names used by more than one element{hint}: {clashes}")
        self._layout_meshes(relative_mesh_path)
        self._order_sections()
        for g in self.generators.values():
            # The merged tree now owns the robots' elements; drop the robots' references.
            g.destroy()

    def _robots_simulator_config(self) -> SimulatorConfig | None:
        """The first robot's simulator settings; a warning names robots whose option
        values (timestep, gravity, integrator, every other ``<option>`` attribute and
        ``<flag>``) differ, since a scene has one of each."""
        configs = [(k, g.simulator_config) for k, g in self.generators.items()]
        chosen = next(((k, c) for k, c in configs if c is not None), None)
        if chosen is None:
            return None

        def option(c: SimulatorConfig) -> tuple[object, ...]:
            others = tuple(sorted((k, str(v)) for k, v in c.option.items()))
            return (c.timestep, tuple(c.gravity or ()), c.integrator, others, c.flag)

        differ = [k for k, c in configs if c is not None and option(c) != option(chosen[1])]
        if differ:
            warnings.warn(
                f"composite: robots {differ} have simulator settings different from "
                f"'{chosen[0]}' ({option(chosen[1])}); the scene uses '{chosen[0]}''s",
                ConversionWarning,
                stacklevel=5,
            )
        return chosen[1]

    def _merge(self, robots: list[_Robot]) -> None:
        mesh_keys: dict[tuple[Any, ...], str] = {}
        for robot in robots:
            renamed: dict[str, str] = {}
            meshdir = robot.root.find("compiler")
            base = meshdir.get("meshdir") if meshdir is not None else None
            for section in robot.root:
                tag = section.tag
                if tag in ("compiler", "option", "keyframe"):
                    continue
                if tag == "asset":
                    asset = self.get_elem("asset")
                    for el in section:
                        if el.tag == "mesh" and el.get("file"):
                            path = el.get("file", "")
                            if base is not None and not os.path.isabs(path):
                                path = os.path.join(base, path)
                            el.set("file", path)
                            k = (
                                path,
                                *[
                                    (a, v)
                                    for a, v in el.attrib.items()
                                    if a not in ("name", "file")
                                ],
                            )
                            kept = mesh_keys.get(k)
                            if kept is not None:
                                if kept != el.get("name"):
                                    renamed[el.get("name", "")] = kept
                                continue
                            mesh_keys[k] = el.get("name", "")
                        asset.append(el)
                    continue
                target = self.get_elem(tag)
                for attr, value in section.attrib.items():
                    target.set(attr, value)
                target.extend(list(section))
            if renamed and robot.worldbody is not None:
                for geom in robot.worldbody.iter("geom"):
                    new = renamed.get(geom.get("mesh", ""))
                    if new is not None:
                        geom.set("mesh", new)

    def _place(self, robots: list[_Robot]) -> None:
        by_key = {r.key: r for r in robots}
        worldbody = self.get_elem("worldbody")
        for robot in robots:
            p = self.placements.get(robot.key)
            if p is None:
                continue
            if p.parent is None:
                for el in robot.top:
                    if (
                        el.get("pos") is None
                        and el.get("quat") is None
                        and el.tag not in ("body", "geom", "site", "camera", "light")
                    ):
                        continue
                    pos, quat = _pose(el)
                    if el.tag == "light":
                        el.set(
                            "dir", fmt_vec(qrot(p.quat, _floats(el.get("dir"), (0.0, 0.0, -1.0))))
                        )
                    _set_pose(el, *compose(p.pos, p.quat, pos, quat))
                continue
            parent = by_key[p.parent]
            target, frame_pos, frame_quat = self._find_frame(parent, p.frame or "")
            base_pos, base_quat = compose(frame_pos, frame_quat, p.pos, p.quat)
            for el in robot.top:
                worldbody.remove(el)
                pos, quat = _pose(el)
                _set_pose(el, *compose(base_pos, base_quat, pos, quat))
                if el.tag == "body":
                    for j in list(el):
                        if j.tag == "freejoint" or (j.tag == "joint" and j.get("type") == "free"):
                            el.remove(j)
                target.append(el)

    @staticmethod
    def _find_frame(
        parent: _Robot, frame: str
    ) -> tuple[ET.Element, tuple[float, ...], tuple[float, ...]]:
        """The body element to attach to and the frame's pose in it."""
        name = prefixed(parent.prefix, frame)
        if parent.worldbody is not None:
            for body in parent.worldbody.iter("body"):
                if body.get("name") == name:
                    return body, (0.0, 0.0, 0.0), (1.0, 0.0, 0.0, 0.0)
                for site in body.findall("site"):
                    if site.get("name") == name:
                        pos, quat = _pose(site)
                        return body, pos, quat
        known = []
        if parent.worldbody is not None:
            known = [
                e.get("name", "") for e in parent.worldbody.iter() if e.tag in ("body", "site")
            ]
            # Users name frames without the robot's prefix (see prefixed()).
            known = [n.removeprefix(f"{parent.prefix}_") if parent.prefix else n for n in known]
        raise GeneratorError(
            f"robot '{parent.key}' has no site or body named '{frame}' to attach at"
            + did_you_mean(frame, known)
        )

    def _merge_keyframes(self, robots: list[_Robot]) -> None:
        names: list[str] = []
        for r in robots:
            for n in r.keys:
                if n not in names:
                    names.append(n)
        if not names:
            return
        order: dict[int, tuple[_Robot, int]] = {}
        for r in robots:
            for k, j in enumerate(r.joints):
                order[id(j.elem)] = (r, k)
        final = []
        for body in self.get_elem("worldbody").iter("body"):
            for el in body:
                if id(el) in order:
                    final.append(order[id(el)])
        section = self.get_elem("keyframe")
        for name in names:
            qpos: list[float] = []
            qvel: list[float] = []
            ctrl: list[float] = []
            values = {r.key: r.key_values(name) for r in robots}
            want_qvel = any(v is not None and "qvel" in v for v in values.values())
            want_ctrl = any(v is not None and "ctrl" in v for v in values.values())
            starts: dict[str, tuple[list[int], list[int]]] = {}
            for r in robots:
                qa, va, qi, vi = [], [], 0, 0
                for j in r.joints:
                    qa.append(qi)
                    va.append(vi)
                    qi += _QPOS_SIZE[j.type]
                    vi += _QVEL_SIZE[j.type]
                starts[r.key] = (qa, va)
                v = values[r.key]
                for attr, size in (("qpos", qi), ("qvel", vi), ("ctrl", r.nu)):
                    if v is not None and attr in v and len(v[attr]) != size:
                        raise GeneratorError(
                            f"robot '{r.key}': keyframe '{name}' {attr} has {len(v[attr])} "
                            f"values, expected {size}"
                        )
            for r, k in final:
                j = r.joints[k]
                v = values[r.key]
                qa, va = starts[r.key]
                if v is not None and "qpos" in v:
                    q = v["qpos"][qa[k] : qa[k] + _QPOS_SIZE[j.type]]
                else:
                    q = list(j.qpos0)
                dq = (
                    v["qvel"][va[k] : va[k] + _QVEL_SIZE[j.type]]
                    if v is not None and "qvel" in v
                    else [0.0] * _QVEL_SIZE[j.type]
                )
                p = self.placements.get(r.key)
                if j.type == "free" and p is not None and p.parent is None:
                    # Key values and qpos0 are world poses of the unplaced robot.
                    pos, quat = compose(p.pos, p.quat, q[:3], q[3:7])
                    q = [*pos, *quat]
                    dq = [*qrot(p.quat, dq[:3]), *dq[3:]]
                qpos.extend(q)
                qvel.extend(dq)
            for r in robots:
                v = values[r.key]
                ctrl.extend(v["ctrl"] if v is not None and "ctrl" in v else [0.0] * r.nu)
            attrs = {"name": name}
            time = next((r.key_time[name] for r in robots if name in r.key_time), None)
            if time is not None:
                attrs["time"] = time
            attrs["qpos"] = fmt_vec(qpos)
            if want_qvel:
                attrs["qvel"] = fmt_vec(qvel)
            if want_ctrl:
                attrs["ctrl"] = fmt_vec(ctrl)
            ET.SubElement(section, "key", attrs)


__all__ = ["MJCFGeneratorComposite", "Placement"]
