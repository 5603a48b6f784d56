"""``MJCFHumanoidGenerator``: one HRDF robot (any tree: humanoid, arm, quadruped) to MJCF.

Mapping (HRDF record -> MJCF element), all values written exactly (see ``xmlfmt``):

- ``Body`` -> ``<body name pos quat>`` with ``<inertial pos quat mass diaginertia>``.
- ``Joint`` -> ``<joint>`` (several per body, in table order); the root's ``free`` joint
  -> ``<freejoint/>`` (unnamed when the HRDF has no name, like hurodes). ``range=None``
  writes no range (unlimited). ``dynamic_friction`` -> ``frictionloss``,
  ``viscous_friction`` -> ``damping``; ``armature``, ``stiffness``, ``springref``,
  ``ref`` when non-zero; margin, actuatorfrcrange, actuatorgravcomp, solreflimit,
  solimplimit, solreffriction, solimpfriction, user where not MuJoCo's default (a free
  joint with any of them is a ``<joint type="free">``). Body ``gravcomp``, ``user``;
  site, sensor and actuator ``user``; ``meta.mjcf_size`` -> ``<size nuser_*>``.
- ``Actuator`` -> ``<motor>``/``<position>``/``<velocity>`` in HRDF order. A motor's
  control range is ``ctrl_range``, else ``[-peak_torque, peak_torque]`` (hurodes);
  ``p_gain`` -> ``kp``, ``d_gain`` -> ``kv``; ``force_range`` -> ``forcerange`` (for
  position/velocity actuators ``peak_torque`` gives the force range when none is set).
- ``MeshGeom``/``SimpleGeom`` -> ``<geom>`` with contype/conaffinity, condim, group,
  friction (static, torsional, rolling), rgba, and solref, solimp, margin, gap,
  priority, solmix, user where not MuJoCo's default; meshes become ``<mesh>`` assets (with
  scale). ``Site`` -> ``<site>``; ``Sensor`` -> its sensor element.
- ``meta.imu_config_list`` -> a site per IMU plus ``framequat``/``gyro``/
  ``accelerometer`` sensors named ``<imu>_quat``/``<imu>_angvel``/``<imu>_linacc``.
- ``meta.simulator_config`` -> ``<option>`` (with its ``option`` attributes and
  ``<flag>`` switches) and the scene; ``mjcf_extra`` sections
  (tendon, equality, contact, keyframe, ...) are merged in, names prefixed.

What MJCF cannot hold (restitution, a static friction that differs from the dynamic one,
gains of torque motors, peak velocities) is reported in one :class:`ConversionWarning`,
or raised as :class:`ConversionError` with ``strict=True``.
"""

from __future__ import annotations

import math
import os
import warnings
import xml.etree.ElementTree as ET

from robotwright._inputs import MJCF_MAX_BODY_DEPTH
from robotwright.errors import (
    ConversionError,
    ConversionWarning,
    GeneratorError,
    Problem,
    strict_failures,
)
from robotwright.generators.mixin import HRDFMixin
from robotwright.generators.mjcf_base import MJCFGeneratorBase, name_clashes, prefix_tree
from robotwright.generators.xmlfmt import fmt_float, fmt_vec, prefixed
from robotwright.hrdf.model import (
    HRDF,
    MUJOCO_SOLIMP,
    MUJOCO_SOLREF,
    WORLD,
    Actuator,
    Geom,
    Joint,
    SimpleGeom,
)
from robotwright.hrdf.validate import check_extra

#: IMU quantity -> (MuJoCo sensor, how it names its object).
IMU_SENSORS: dict[str, str] = {"quat": "framequat", "angvel": "gyro", "linacc": "accelerometer"}
#: Number of meaningful size values per primitive / site type.
SIZE_COUNT: dict[str, int] = {
    "sphere": 1, "capsule": 2, "cylinder": 2, "box": 3, "ellipsoid": 3,
}  # fmt: skip
_IDENTITY = (1.0, 0.0, 0.0, 0.0)


def imu_sites(hrdf: HRDF) -> list[tuple[str, bool]]:
    """``(site name, new)`` for each IMU of ``meta.imu_config_list``.

    An IMU placed exactly at an HRDF site (same body, position and orientation) uses that
    site (``new`` is false). Otherwise it gets a new site named after its hurodes device
    name, else ``imu`` (``imu<i>`` when there are several unnamed IMUs), with ``_<n>``
    appended when the name is already a site.
    """
    imus = hrdf.meta.imu_config_list or []
    unnamed = sum(1 for imu in imus if imu.name is None)
    taken = {s.name for s in hrdf.sites}
    out: list[tuple[str, bool]] = []
    for i, imu in enumerate(imus):
        match = next(
            (
                s.name
                for s in hrdf.sites
                if s.body == imu.body_name
                and tuple(s.pos) == tuple(imu.position)
                and tuple(s.quat) == tuple(imu.orientation)
            ),
            None,
        )
        if match is not None:
            out.append((match, False))
            continue
        base = imu.name if imu.name is not None else ("imu" if unnamed == 1 else f"imu{i}")
        name, n = base, 1
        while name in taken:
            name = f"{base}_{n}"
            n += 1
        taken.add(name)
        out.append((name, True))
    return out


def _is_file(path: str, listings: dict[str, set[str] | None]) -> bool:
    """``os.path.isfile(path)`` through one listing per folder (a robot's meshes share one
    or a few folders: one ``scandir`` instead of a ``stat`` per file)."""
    folder, _, name = path.rpartition(os.sep)
    if folder not in listings:
        try:
            # DirEntry.is_file follows symbolic links, as os.path.isfile does.
            listings[folder] = {e.name for e in os.scandir(folder or os.sep) if e.is_file()}
        except OSError:
            listings[folder] = None
    names = listings[folder]
    return os.path.isfile(path) if names is None else name in names


def _order(geom: Geom) -> float:
    return math.inf if geom.order is None else float(geom.order)


def parse_mjcf_extra(hrdf: HRDF) -> ET.Element | None:
    """The robot's ``mjcf_extra`` fragment parsed safely (no entity expansion)."""
    if not hrdf.mjcf_extra or not hrdf.mjcf_extra.strip():
        return None
    from defusedxml import ElementTree as SafeET

    try:
        root = SafeET.fromstring(hrdf.mjcf_extra)
    except Exception as exc:  # defusedxml raises several types; all mean "bad fragment"
        raise GeneratorError(f"robot '{hrdf.name}': mjcf_extra is not valid XML: {exc}") from exc
    if root.tag != "mujoco":
        raise GeneratorError(
            f"robot '{hrdf.name}': mjcf_extra: expected a <mujoco> element, got <{root.tag}>"
        )
    # Only the sections HRDF carries, naming no file (checked at load too).
    problems = check_extra(hrdf.mjcf_extra)
    if problems:
        raise GeneratorError(f"robot '{hrdf.name}': mjcf_extra: {problems[0]}")
    return root


class MJCFHumanoidGenerator(HRDFMixin, MJCFGeneratorBase):
    """HRDF robot -> MJCF. Works for any tree robot, floating or fixed base.

    Example::

        gen = MJCFHumanoidGenerator.from_robot_name("mini_humanoid")
        xml = gen.export("out/robot.xml", prefix="r1")
        model = gen.to_model()
    """

    def _on_hrdf_loaded(self, hrdf: HRDF) -> None:
        self.simulator_config = hrdf.meta.simulator_config

    def _clean(self) -> None:
        super()._clean()
        self.simulator_config = None

    def _model_name(self) -> str:
        return self.hrdf.name if self.hrdf is not None else "robot"

    # -- generation ---------------------------------------------------------------------
    def _generate(
        self,
        prefix: str | None = None,
        add_scene: bool = True,
        relative_mesh_path: bool = True,
        *,
        skybox: bool = True,
        strict: bool = False,
    ) -> None:
        """Build the MJCF tree.

        Args:
            prefix: prepended as ``<prefix>_`` to every name and name reference.
            add_scene: add ground, light and sky (``add_scene()``).
            relative_mesh_path: mesh paths relative to the output folder when exporting
                to a file; absolute otherwise.
            skybox: with ``add_scene``, also add the gradient skybox.
            strict: raise :class:`ConversionError` instead of warning about values MJCF
                cannot hold.
        """
        hrdf = self.loaded_hrdf
        losses: list[Problem] = []
        self.add_compiler()
        self.add_option()
        if hrdf.meta.mjcf_size:
            self.get_elem("size").attrib.update(
                {k: str(int(v)) for k, v in sorted(hrdf.meta.mjcf_size.items())}
            )
        mesh_names = self._add_mesh_assets(hrdf, prefix)
        self._add_bodies(hrdf, prefix, mesh_names, losses)
        self._add_actuators(hrdf, prefix, losses)
        self._add_sensors(hrdf, prefix, losses)
        extra = parse_mjcf_extra(hrdf)
        if extra is not None:
            prefix_tree(extra, prefix)
            for section in extra:
                self.get_elem(section.tag).extend(list(section))
        if add_scene:
            self.add_scene(skybox=skybox)
        self._layout_meshes(relative_mesh_path)
        self._order_sections()
        clashes = name_clashes(self.xml_root) if self._check_names else None
        if clashes:
            raise GeneratorError(f"robot '{hrdf.name}': names used twice in the MJCF: {clashes}")
        _report(hrdf, "MJCF", losses, strict)

    def _add_mesh_assets(self, hrdf: HRDF, prefix: str | None) -> list[str]:
        """One ``<mesh>`` per distinct (file, scale); returns the asset name of each row."""
        asset = self.get_elem("asset")
        by_key: dict[tuple[str, tuple[float, float, float], str | None], str] = {}
        used: set[str] = set()
        names: list[str] = []
        listings: dict[str, set[str] | None] = {}
        for row, m in enumerate(hrdf.meshes):
            path = self.mesh_abspath(m)
            if not _is_file(path, listings):
                raise GeneratorError(
                    f"robot '{hrdf.name}': mesh.csv row {row} (mesh '{m.name}'): "
                    f"file '{path}' does not exist"
                )
            key = (path, tuple(m.scale), m.inertia)
            name = by_key.get(key)
            if name is None:
                name, n = m.name, 1
                while name in used:
                    name = f"{m.name}_{n}"
                    n += 1
                used.add(name)
                by_key[key] = name
                attrs = {"name": prefixed(prefix, name), "file": path}
                if m.scale != (1.0, 1.0, 1.0):
                    attrs["scale"] = fmt_vec(m.scale)
                if m.inertia is not None:
                    attrs["inertia"] = m.inertia  # centre and volume as in the source
                ET.SubElement(asset, "mesh", attrs)
            names.append(prefixed(prefix, name))
        return names

    def _add_bodies(
        self, hrdf: HRDF, prefix: str | None, mesh_names: list[str], losses: list[Problem]
    ) -> None:
        joints: dict[str, list[Joint]] = {}
        for j in hrdf.joints:
            joints.setdefault(j.body, []).append(j)
        placed: dict[str, list[tuple[float, ET.Element]]] = {}
        for row, m in enumerate(hrdf.meshes):
            el = self._geom_elem(m, prefix, "mesh.csv", row, losses)
            el.set("type", "mesh")
            el.set("mesh", mesh_names[row])
            placed.setdefault(m.body, []).append((_order(m), el))
        for row, g in enumerate(hrdf.simple_geoms):
            el = self._geom_elem(g, prefix, "simple_geom.csv", row, losses)
            el.set("type", g.type)
            el.set("size", fmt_vec(g.size[: SIZE_COUNT[g.type]]))
            placed.setdefault(g.body, []).append((_order(g), el))
        # A body's geoms in their ``order`` where given (stable: else meshes, then
        # primitives, in row order); MuJoCo's contact order follows geom order.
        geoms = {
            body: [el for _, el in sorted(items, key=lambda item: item[0])]
            for body, items in placed.items()
        }
        sites: dict[str, list[ET.Element]] = {}
        for s in hrdf.sites:
            el = ET.Element("site", {"name": prefixed(prefix, s.name), "pos": fmt_vec(s.pos)})
            if s.quat != _IDENTITY:
                el.set("quat", fmt_vec(s.quat))
            el.set("type", s.type)
            el.set("size", fmt_vec(s.size[: SIZE_COUNT.get(s.type, 3)]))
            el.set("rgba", fmt_vec(s.rgba))
            if s.group:
                el.set("group", str(s.group))
            if s.user:
                el.set("user", fmt_vec(s.user))
            sites.setdefault(s.body, []).append(el)
        for imu, (name, new) in zip(hrdf.meta.imu_config_list or [], imu_sites(hrdf), strict=True):
            if not new:
                continue
            el = ET.Element("site", {"name": prefixed(prefix, name), "pos": fmt_vec(imu.position)})
            if imu.orientation != _IDENTITY:
                el.set("quat", fmt_vec(imu.orientation))
            sites.setdefault(imu.body_name, []).append(el)

        children: dict[int, list[int]] = {}
        for i, b in enumerate(hrdf.bodies):
            children.setdefault(b.parent, []).append(i)
        worldbody = self.get_elem("worldbody")
        for k, el in enumerate(sites.get(WORLD, ())):  # sites fixed in the world
            worldbody.insert(k, el)
        stack: list[tuple[ET.Element, int, int]] = [
            (worldbody, i, 1) for i in reversed(children.get(-1, []))
        ]
        while stack:
            parent_el, idx, depth = stack.pop()
            if depth > MJCF_MAX_BODY_DEPTH:
                raise GeneratorError(
                    f"robot '{hrdf.name}': body '{hrdf.bodies[idx].name}' is nested "
                    f"{depth} bodies deep; MuJoCo's MJCF reader accepts at most "
                    f"{MJCF_MAX_BODY_DEPTH} (write URDF or HRDF, whose files are flat)"
                )
            b = hrdf.bodies[idx]
            el = ET.SubElement(
                parent_el,
                "body",
                {"name": prefixed(prefix, b.name), "pos": fmt_vec(b.pos), "quat": fmt_vec(b.quat)},
            )
            if b.gravcomp:
                el.set("gravcomp", fmt_float(b.gravcomp))
            if b.user:
                el.set("user", fmt_vec(b.user))
            ET.SubElement(
                el,
                "inertial",
                {
                    "pos": fmt_vec(b.inertial_pos),
                    "quat": fmt_vec(b.inertial_quat),
                    "mass": fmt_float(b.mass),
                    "diaginertia": fmt_vec(b.diag_inertia),
                },
            )
            for j in joints.get(b.name, ()):
                el.append(self._joint_elem(j, prefix, losses))
            el.extend(geoms.get(b.name, ()))
            el.extend(sites.get(b.name, ()))
            for c in reversed(children.get(idx, [])):
                stack.append((el, c, depth + 1))

    @staticmethod
    def _geom_elem(
        g: Geom, prefix: str | None, table: str, row: int, losses: list[Problem]
    ) -> ET.Element:
        name = g.geom_name
        if name is None and isinstance(g, SimpleGeom):
            name = g.name
        # Attributes gathered in a dict (in output order) and given to the element at once:
        # a dict store costs a third of an Element.set call, and geoms are the most
        # numerous elements.
        attrs: dict[str, str] = {}
        if name:
            attrs["name"] = prefixed(prefix, name)
        attrs["pos"] = fmt_vec(g.pos)
        attrs["quat"] = fmt_vec(g.quat)
        attrs["contype"] = str(g.contact_type)
        attrs["conaffinity"] = str(g.contact_affinity)
        if g.condim != 3:
            attrs["condim"] = str(g.condim)
        if g.group:
            attrs["group"] = str(g.group)
        attrs["friction"] = fmt_vec((g.static_friction, g.torsional_friction, g.rolling_friction))
        attrs["rgba"] = fmt_vec(g.rgba)
        _solver_attrs(attrs, g, (("solref", "solref"), ("solimp", "solimp")))
        for key, value, default in (
            ("margin", g.margin, 0.0),
            ("gap", g.gap, 0.0),
            ("solmix", g.solmix, 1.0),
        ):
            if value != default:
                attrs[key] = fmt_float(value)
        if g.priority:
            attrs["priority"] = str(int(g.priority))
        if g.user:
            attrs["user"] = fmt_vec(g.user)
        el = ET.Element("geom", attrs)
        if g.restitution is not None:
            losses.append(
                Problem(table, "restitution has no MuJoCo meaning: dropped", row, "restitution")
            )
        if g.dynamic_friction != g.static_friction:
            losses.append(
                Problem(
                    table,
                    f"dynamic_friction {g.dynamic_friction} differs from static_friction "
                    f"{g.static_friction}; MuJoCo has one sliding friction (static written)",
                    row,
                    "dynamic_friction",
                )
            )
        return el

    @staticmethod
    def _joint_elem(j: Joint, prefix: str | None, losses: list[Problem]) -> ET.Element:
        dyn = {
            "armature": j.armature,
            "damping": j.viscous_friction,
            "frictionloss": j.dynamic_friction,
            "stiffness": j.stiffness,
            "springref": j.springref,
            "ref": j.ref,
            "margin": j.margin,
        }
        if j.static_friction and j.static_friction != j.dynamic_friction:
            losses.append(
                Problem(
                    "joint.csv",
                    f"joint '{j.name}': static_friction {j.static_friction} differs from "
                    f"dynamic_friction {j.dynamic_friction}; frictionloss = dynamic_friction",
                    column="static_friction",
                )
            )
        more: dict[str, str] = {}
        _solver_attrs(
            more,
            j,
            (
                ("solreflimit", "solreflimit"),
                ("solimplimit", "solimplimit"),
                ("solreffriction", "solreffriction"),
                ("solimpfriction", "solimpfriction"),
            ),
        )
        if j.actuatorfrcrange is not None:
            more["actuatorfrcrange"] = fmt_vec(j.actuatorfrcrange)
            more["actuatorfrclimited"] = "true"
        if j.actuatorgravcomp:
            more["actuatorgravcomp"] = "true"
        if j.user:
            more["user"] = fmt_vec(j.user)
        if j.type == "free" and not any(dyn.values()) and j.range is None and not more:
            el = ET.Element("freejoint")
            if j.name:
                el.set("name", prefixed(prefix, j.name))
            return el
        el = ET.Element("joint")
        if j.name:
            el.set("name", prefixed(prefix, j.name))
        el.set("type", j.type)
        if j.type != "free":
            el.set("pos", fmt_vec(j.pos))
        if j.type in ("hinge", "slide"):
            el.set("axis", fmt_vec(j.axis))
        if j.range is not None:
            el.set("range", fmt_vec(j.range))
            el.set("limited", "true")
        for key, value in dyn.items():
            if value:
                el.set(key, fmt_float(value))
        el.attrib.update(more)
        return el

    def _add_actuators(self, hrdf: HRDF, prefix: str | None, losses: list[Problem]) -> None:
        section = self.get_elem("actuator")
        for row, a in enumerate(hrdf.actuators):
            section.append(_actuator_elem(a, prefix, row, losses))

    def _add_sensors(self, hrdf: HRDF, prefix: str | None, losses: list[Problem]) -> None:
        section = self.get_elem("sensor")
        for imu, (name, _) in zip(hrdf.meta.imu_config_list or [], imu_sites(hrdf), strict=True):
            site = prefixed(prefix, name)
            for value in imu.value:
                kind = IMU_SENSORS.get(value)
                if kind is None:
                    raise GeneratorError(
                        f"robot '{hrdf.name}': meta.yaml imu_config_list: IMU value "
                        f"'{value}': expected one of {sorted(IMU_SENSORS)}"
                    )
                attrs = {"name": prefixed(prefix, f"{name}_{value}")}
                if kind == "framequat":
                    attrs |= {"objtype": "site", "objname": site}
                else:
                    attrs["site"] = site
                ET.SubElement(section, kind, attrs)
        for s in hrdf.sensors:
            attrs = {"name": prefixed(prefix, s.name)}
            if s.type.startswith("frame"):
                attrs |= {"objtype": s.objtype, "objname": prefixed(prefix, s.objname)}
                if s.reftype is not None and s.refname is not None:
                    attrs |= {"reftype": s.reftype, "refname": prefixed(prefix, s.refname)}
            else:
                attrs[s.objtype] = prefixed(prefix, s.objname)
                if s.reftype is not None or s.refname is not None:
                    losses.append(
                        Problem(
                            "sensor.csv",
                            f"sensor '{s.name}' ({s.type}): only frame sensors take a "
                            "reference frame; reftype/refname dropped",
                            column="reftype",
                        )
                    )
            if s.noise:
                attrs["noise"] = fmt_float(s.noise)
            if s.cutoff:
                attrs["cutoff"] = fmt_float(s.cutoff)
            if s.user:
                attrs["user"] = fmt_vec(s.user)
            ET.SubElement(section, s.type, attrs)


def _actuator_elem(a: Actuator, prefix: str | None, row: int, losses: list[Problem]) -> ET.Element:
    el = ET.Element(a.type)
    if a.name:
        el.set("name", prefixed(prefix, a.name))
    el.set("joint", prefixed(prefix, a.joint))
    if a.gear != 1.0:
        el.set("gear", fmt_float(a.gear))
    ctrl = a.ctrl_range
    force = a.force_range
    if a.type == "motor":
        if ctrl is None and a.peak_torque is not None:
            ctrl = (-a.peak_torque, a.peak_torque)
        if a.p_gain is not None or a.d_gain is not None:
            losses.append(
                Problem(
                    "actuator.csv",
                    f"motor on '{a.joint}': p_gain/d_gain are controller gains; a MuJoCo "
                    "motor has none (use type position for servo gains)",
                    row,
                    "p_gain",
                )
            )
    else:
        if force is None and a.peak_torque is not None:
            force = (-a.peak_torque, a.peak_torque)
        if a.type == "position" and a.p_gain is not None:
            el.set("kp", fmt_float(a.p_gain))
        if a.d_gain is not None:
            el.set("kv", fmt_float(a.d_gain))
        if a.type == "velocity" and a.p_gain is not None:
            losses.append(
                Problem(
                    "actuator.csv",
                    f"velocity actuator on '{a.joint}': p_gain has no meaning",
                    row,
                    "p_gain",
                )
            )
    if ctrl is not None:
        el.set("ctrlrange", fmt_vec(ctrl))
        el.set("ctrllimited", "true")
    if force is not None:
        el.set("forcerange", fmt_vec(force))
        el.set("forcelimited", "true")
    if a.user:
        el.set("user", fmt_vec(a.user))
    if a.peak_velocity is not None:
        losses.append(
            Problem(
                "actuator.csv",
                f"actuator on '{a.joint}': peak_velocity {a.peak_velocity} has no MJCF field",
                row,
                "peak_velocity",
            )
        )
    return el


def _solver_attrs(attrs: dict[str, str], record: object, fields: tuple) -> None:
    """Set each ``(attribute, field)`` of ``record`` that is not MuJoCo's default
    (``solref*`` fields: :data:`MUJOCO_SOLREF`; ``solimp*``: :data:`MUJOCO_SOLIMP`)."""
    for key, name in fields:
        value = tuple(getattr(record, name))
        default = MUJOCO_SOLREF if name.startswith("solref") else MUJOCO_SOLIMP
        if value != default:
            attrs[key] = fmt_vec(value)


def _report(hrdf: HRDF, fmt: str, losses: list[Problem], strict: bool | str) -> None:
    """One warning (or, with ``strict``, one error) listing what the output cannot hold
    (``strict``: see :func:`~robotwright.errors.strict_failures`)."""
    if not losses:
        return
    failing = strict_failures(losses, strict)
    if failing:
        raise ConversionError(failing, f"robot '{hrdf.name}': {fmt} cannot hold every value")
    shown = "\n".join(f"  - {p}" for p in losses)
    warnings.warn(
        f"robot '{hrdf.name}' to {fmt}: {len(losses)} value(s) not written:\n{shown}",
        ConversionWarning,
        stacklevel=4,
    )


__all__ = ["MJCFHumanoidGenerator", "imu_sites", "parse_mjcf_extra"]
