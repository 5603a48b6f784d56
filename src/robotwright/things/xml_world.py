"""An MJCF file or text read as a :class:`~robotwright.things.world.World` of things: the
XML checked safe first, then each element read by the reader of
:mod:`robotwright.things.xml_reader`, sections the things do not model carried as they
are."""

from __future__ import annotations

import os
import warnings
import xml.etree.ElementTree as ET
from collections.abc import Iterable
from pathlib import Path

import defusedxml.ElementTree as SafeET
import mujoco

from robotwright._inputs import MAX_XML_BYTES, read_bytes
from robotwright._paths import check_mjcf_includes, check_mjcf_spec, trusted_roots
from robotwright.errors import (
    ConversionError,
    ConversionWarning,
    InputFileError,
)
from robotwright.things.precision import SECTION_REFINERS
from robotwright.things.raw import RawElement
from robotwright.things.world import OPTION_ATTR, World
from robotwright.things.xml_reader import CARRIED_CLASS, ThingXMLError, _carried_class, _Reader

_CARRIED_SECTIONS = ("size", "visual", "statistic", "contact", "equality", "tendon", "keyframe")

_OPTION_ENUMS = {
    "integrator": ("Euler", "RK4", "implicit", "implicitfast"),
    "cone": ("pyramidal", "elliptic"),
    "jacobian": ("dense", "sparse", "auto"),
    "solver": ("PGS", "CG", "Newton"),
}


def _read_world(spec: mujoco.MjSpec, base_dir: Path, source: str, strict: bool) -> World:
    reader = _Reader(spec, base_dir, source, strict)
    n_keys = len(spec.keys)  # before to_xml(), which may add the keys <size nkey> asks for
    world = World(spec.modelname or None)
    opt = spec.option
    for key in OPTION_ATTR:
        if key in _OPTION_ENUMS:
            setattr(world, key, _OPTION_ENUMS[key][int(getattr(opt, key))])
        else:
            setattr(world, key, getattr(opt, key))
    comp = spec.compiler
    world.autolimits = bool(comp.autolimits)
    world.inertiafromgeom = {0: "false", 1: "true", 2: "auto"}[int(comp.inertiafromgeom)]
    world.inertiagrouprange = comp.inertiagrouprange
    world.settotalmass = comp.settotalmass
    world.boundmass = comp.boundmass
    world.boundinertia = comp.boundinertia
    world.balanceinertia = bool(comp.balanceinertia)
    world.fusestatic = bool(comp.fusestatic)
    world.alignfree = bool(comp.alignfree)
    world.discardvisual = bool(comp.discardvisual)
    world.disabled.update(
        m[len("mjDSBL_") :].lower()
        for m, v in mujoco.mjtDisableBit.__members__.items()
        if m != "mjNDISABLE" and opt.disableflags & int(v)
    )
    world.enabled.update(
        m[len("mjENBL_") :].lower()
        for m, v in mujoco.mjtEnableBit.__members__.items()
        if m != "mjNENABLE" and opt.enableflags & int(v)
    )
    if opt.disableactuator:
        reader.lose("<option>", "actuator group disabling (actuatorgroupdisable) is not kept")
    if len(spec.plugins) or len(spec.numerics) or len(spec.texts) or len(spec.tuples):
        reader.lose(
            "<extension>/<custom>", "plugins and custom numeric/text/tuple data are not kept"
        )

    reader.by_name[("body", "world")] = world
    reader.read_assets(world)
    reader.read_body_children(spec.worldbody, world)
    reader.unused_meshes(world)
    for hfield in spec.hfields:
        if hfield.name not in reader.used_hfields:
            reader.lose(f'<hfield name="{hfield.name}">', "no geom uses it; not kept")

    try:
        carried_root = ET.fromstring(spec.to_xml())
    except ValueError as exc:
        raise ThingXMLError(f"{source}: MuJoCo rejected the MJCF: {exc}") from None
    carried: dict[str, list[ET.Element]] = {}
    for section in ("actuator", "sensor"):
        node = carried_root.find(section)
        carried[section] = list(node) if node is not None else []
    if len(carried["actuator"]) != len(spec.actuators) or len(carried["sensor"]) != len(
        spec.sensors
    ):
        carried = {"actuator": [], "sensor": []}
    acts, sens = carried["actuator"], carried["sensor"]
    for i, sa in enumerate(spec.actuators):
        carried["actuator"] = [acts[i]] if acts else []
        reader.actuator(sa, world, carried, i)
    for i, ss in enumerate(spec.sensors):
        carried["sensor"] = [sens[i]] if sens else []
        reader.sensor(ss, world, carried, i)
    uses_classes = False
    for section in _CARRIED_SECTIONS:
        node = carried_root.find(section)
        if node is None or (section != "visual" and len(node) == 0 and not node.attrib):
            continue
        if section in SECTION_REFINERS:
            SECTION_REFINERS[section](node, reader.compiled)
        if section == "size":
            node = _split_size(node)
        if section in ("contact", "equality", "tendon", "keyframe"):
            for child in node:
                _carried_class(child)
                uses_classes = True
        world.extra_xml[section] = _indent(node)
    if uses_classes or any(isinstance(t, RawElement) for t in world._children):
        default = carried_root.find("default")
        if default is not None and [c.get("class") for c in default] == [CARRIED_CLASS]:
            world.extra_xml["default"] = _indent(default)
        elif default is not None:
            wrapper = ET.Element("default")
            inner = ET.SubElement(wrapper, "default", {"class": CARRIED_CLASS})
            inner.extend(list(default))
            world.extra_xml["default"] = _indent(wrapper)
        else:
            world.extra_xml["default"] = (
                f'  <default>\n    <default class="{CARRIED_CLASS}"/>\n  </default>'
            )
    if n_keys and "keyframe" not in world.extra_xml:
        reader.lose("<keyframe>", "keyframes could not be carried")

    if reader.problems:
        if strict:
            raise ConversionError(
                reader.problems, f"{source}: MJCF elements cannot be represented as Things"
            )
        for problem in reader.problems:
            warnings.warn(ConversionWarning(str(problem)), stacklevel=3)
    return world


def _split_size(node: ET.Element) -> ET.Element:
    """MuJoCo's writer puts ``memory`` and ``njmax``/``nstack`` (read from two ``<size>``
    elements) into one element, which its schema refuses; write ``memory`` on its own."""
    if "memory" not in node.attrib or not ({"njmax", "nstack"} & set(node.attrib)):
        return node
    memory = ET.Element("size", {"memory": node.attrib.pop("memory")})
    wrapper = ET.Element("sizes")
    wrapper.extend([memory, node])
    return wrapper


def _indent(node: ET.Element) -> str:
    if node.tag == "sizes":  # several top-level elements (see _split_size)
        return "\n".join(_indent(child) for child in node)
    ET.indent(node, space="  ", level=1)
    return "  " + ET.tostring(node, encoding="unicode").strip()


def _check_safe(text: str | bytes, source: str) -> ET.Element:
    try:
        root = SafeET.fromstring(text)
    except Exception as exc:  # defusedxml raises several types; all mean "do not read"
        raise ThingXMLError(f"{source}: not readable as safe XML: {exc}") from None
    # MuJoCo also compiles a URDF (<robot>) here, silently dropping what it cannot map.
    if root.tag != "mujoco":
        raise ThingXMLError(
            f"{source}: root element <{root.tag}>: expected <mujoco> (MJCF); "
            "convert a URDF first with 'robotwright convert'"
        )
    return root


def world_from_string(
    xml: str,
    base_dir: str | os.PathLike[str] | None = None,
    strict: bool = False,
    asset_roots: Iterable[str | os.PathLike[str]] | None = None,
) -> World:
    """Things from MJCF text; relative files resolve against ``base_dir`` (default: cwd)
    and must lie inside it or inside one of ``asset_roots`` (``<include>`` files, which
    MuJoCo takes from the working folder, too)."""
    tree = _check_safe(xml, "<string>")
    base = Path(base_dir).resolve() if base_dir is not None else Path.cwd()
    trusted = trusted_roots(asset_roots)
    check_mjcf_includes(tree, source="<string>", model_dir=Path.cwd(), root=base, trusted=trusted)
    try:
        spec = mujoco.MjSpec.from_string(xml)
    except ValueError as exc:
        raise ThingXMLError(f"<string>: MuJoCo rejected the MJCF: {exc}") from None
    spec.modelfiledir = str(base)
    check_mjcf_spec(spec, source="<string>", model_dir=base, root=base, trusted=trusted)
    return _read_world(spec, base, "<string>", strict)


def world_from_path(
    path: str | os.PathLike[str],
    strict: bool = False,
    asset_roots: Iterable[str | os.PathLike[str]] | None = None,
) -> World:
    """Things from an MJCF file (includes and relative paths resolve from its folder).

    Every file the model names (includes, meshes, textures, height fields) must lie
    inside the file's folder or inside one of ``asset_roots`` (see
    :mod:`robotwright._paths`); :class:`~robotwright.errors.UnsafePathError` otherwise.
    """
    path = Path(path)
    if not path.exists():
        raise ThingXMLError(f"{path}: no such MJCF file")
    try:
        text = read_bytes(path, MAX_XML_BYTES)
    except InputFileError as exc:
        raise ThingXMLError(str(exc)) from None
    tree = _check_safe(text, str(path))
    folder = path.parent.resolve()
    where = {"source": str(path), "model_dir": folder, "root": folder}
    trusted = trusted_roots(asset_roots)
    check_mjcf_includes(tree, **where, trusted=trusted)
    try:
        spec = mujoco.MjSpec.from_file(str(path))
    except ValueError as exc:
        raise ThingXMLError(f"{path}: MuJoCo rejected the MJCF: {exc}") from None
    check_mjcf_spec(spec, **where, trusted=trusted)
    return _read_world(spec, folder, str(path), strict)
