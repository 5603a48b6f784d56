"""Writing a Thing tree as MJCF text.

Attributes equal to MuJoCo's defaults (``_DEFAULT_VALS``) are omitted. Angles are
written in radians (``<compiler angle="radian"/>``). Actuators and sensors are written in
the order they were created (reading MJCF creates them in file order, so the order of
``ctrl`` and ``sensordata`` survives a round trip).
"""

from __future__ import annotations

import os
from collections.abc import Callable
from typing import Any
from xml.sax.saxutils import escape

from robotwright._inputs import MJCF_MAX_BODY_DEPTH
from robotwright.errors import GeneratorError
from robotwright.things.assets import TEXTURE_FILE_ATTRS
from robotwright.things.attrs import ThingAttributeError
from robotwright.things.base import BaseThing

_QUOTE = {'"': "&quot;"}
#: Attributes holding a file path (rewritten by ``path_for``, e.g. copied on export).
_FILE_ATTRS = frozenset(TEXTURE_FILE_ATTRS)


def _q(text: str) -> str:
    if "&" in text or "<" in text or ">" in text or '"' in text:
        return escape(text, _QUOTE)
    return text


class _Writer:
    def __init__(self, root: BaseThing, path_for: Callable[[str], str] | None) -> None:
        self.root = root
        self.names = root._resolved_names()
        self.path_for = path_for or (lambda p: p)
        self.out: list[str] = []
        self.actuators: list[BaseThing] = []
        self.sensors: list[BaseThing] = []
        self.mesh_of_geom: dict[int, str] = {}  # geom ID -> name of the asset it owns
        self._owned_base: dict[str, str] = {}
        self._owned_assets: list[tuple[str, BaseThing]] = []
        self.asset_names: dict[int, str] = {}
        self.assets: list[BaseThing] = []
        # model ids in compile order: namespace -> list of Thing IDs
        self.order: dict[str, list[int]] = {}
        self.by_body: dict[str, list[tuple[int, int]]] = {}

    # ------------------------------------------------------------------ helpers
    def ref_name(self, value: Any) -> str:
        if isinstance(value, str):
            return value
        table = self.asset_names if value._NAMESPACE is None else self.names
        try:
            return table[value.ID]
        except KeyError:
            raise ThingAttributeError(
                f"{value._label()} is referred to but is not part of this World's tree "
                "(attach it, or refer to it by name)"
            ) from None

    def attrs(self, thing: BaseThing, skip: frozenset[str] | set[str] = frozenset()) -> str:
        parts: list[str] = []
        name = self.names.get(thing.ID) if thing._NAMESPACE else self.asset_names.get(thing.ID)
        if name:
            parts.append(f'name="{_q(name)}"')
        defaults = thing._DEFAULT_VALS
        # Untouched attributes still hold the shared default object: skip them cheaply.
        shared = type(thing).__dict__.get("_INIT_DEFAULTS") or {}
        for key, spec in thing._MUJOCO_ATTR.items():
            if key in skip:
                continue
            value = getattr(thing, key)
            if value is None or value is shared.get(key, False):
                continue
            if key in defaults and spec.equal(value, defaults[key]):
                continue
            if isinstance(value, BaseThing):
                text = self.ref_name(value)
            elif key in _FILE_ATTRS:
                text = self.path_for(value)
            else:
                text = spec.format(value)
            parts.append(f'{key}="{_q(text)}"')
        return " ".join(parts)

    # ------------------------------------------------------------------ assets
    def collect_assets(self) -> None:
        requested: list[BaseThing] = list(getattr(self.root, "assets", []))
        seen = {a.ID for a in requested}
        # Geoms that own their asset (Mesh, HField): equal asset attributes share one asset.
        owned: list[tuple[BaseThing, str, str]] = []
        for thing in self.root.walk():
            asset_tag = getattr(thing, "_ASSET_TAG", None)
            if asset_tag is not None:
                name_attr = asset_tag  # the geom attribute naming the asset ("mesh", ...)
                key = tuple(
                    (k, _hashable(getattr(thing, k))) for k in thing._ASSET_ATTR if k != name_attr
                )
                file = thing.__dict__.get("file")
                base = getattr(thing, name_attr) or (
                    os.path.splitext(os.path.basename(file))[0]
                    if file
                    else thing._name or asset_tag
                )
                owned.append((thing, asset_tag, repr((asset_tag, key, base))))
                self._owned_base[repr((asset_tag, key, base))] = base
            value = thing.__dict__.get("material")
            if isinstance(value, BaseThing) and value.ID not in seen:
                seen.add(value.ID)
                requested.append(value)
        for asset in list(requested):
            tex = asset.__dict__.get("texture")
            if isinstance(tex, BaseThing) and tex.ID not in seen:
                seen.add(tex.ID)
                requested.insert(requested.index(asset), tex)
        taken: set[tuple[str, str]] = set()
        next_k: dict[tuple[str, str], int] = {}
        for asset in requested:
            self.asset_names[asset.ID] = _unique(
                taken, asset._TAG, asset.__dict__.get("_name") or asset._TAG, next_k
            )
        self.assets = requested
        unique: dict[str, str] = {}
        for geom, asset_tag, ident in owned:
            if ident not in unique:
                unique[ident] = _unique(taken, asset_tag, self._owned_base[ident], next_k)
                self._owned_assets.append((unique[ident], geom))
            self.mesh_of_geom[geom.ID] = unique[ident]

    def write_assets(self) -> None:
        if not self.assets and not self._owned_assets:
            return
        self.out.append("  <asset>")
        for asset in self.assets:
            self.out.append(f"    <{asset._TAG} {self.attrs(asset)}/>")
        for name, geom in self._owned_assets:
            parts = [f'name="{_q(name)}"']
            cls = type(geom)
            for key in cls._ASSET_ATTR:
                if key == cls._ASSET_TAG:
                    continue
                value = getattr(geom, key)
                if value is None or (
                    key in cls._DEFAULT_VALS
                    and cls._MUJOCO_ATTR[key].equal(value, cls._DEFAULT_VALS[key])
                ):
                    continue
                text = (
                    self.path_for(value) if key == "file" else cls._MUJOCO_ATTR[key].format(value)
                )
                parts.append(f'{cls._ASSET_XML.get(key, key)}="{_q(text)}"')
            self.out.append(f"    <{cls._ASSET_TAG} {' '.join(parts)}/>")
        self.out.append("  </asset>")

    # ------------------------------------------------------------------ tree
    def write_children(self, node: BaseThing, indent: str, body_idx: int = 0) -> None:
        out = self.out
        order = self.order
        for child in node._children:
            ns = child._NAMESPACE
            if ns == "actuator" or ns == "sensor" or ns == "raw":
                self.collect_section(child)
                continue
            if ns == "body":
                order["body"].append(child.ID)
                child_idx = len(order["body"]) - 1
                attrs = self.attrs(child, skip=child._INERTIAL)
                inertial = self.inertial(child)
                if inertial or child._children:
                    out.append(f"{indent}<body {attrs}>" if attrs else f"{indent}<body>")
                    if inertial:
                        out.append(f"{indent}  {inertial}")
                    self.write_children(child, indent + "  ", child_idx)
                    out.append(f"{indent}</body>")
                else:
                    out.append(f"{indent}<body {attrs}/>")
                continue
            # MuJoCo numbers geoms, joints, sites, ... body by body (body id order).
            self.by_body.setdefault(ns, []).append((body_idx, child.ID))
            asset_tag = getattr(child, "_ASSET_TAG", None)
            if asset_tag is not None:
                attrs = self.attrs(child, skip=set(child._ASSET_ATTR))
                attrs += f' {asset_tag}="{_q(self.mesh_of_geom[child.ID])}"'
            else:
                attrs = self.attrs(child)
            out.append(f"{indent}<{child._TAG} {attrs}/>")
            for grandchild in child._children:
                self.collect_section(grandchild)

    def collect_section(self, thing: BaseThing) -> None:
        section = thing.section if thing._NAMESPACE == "raw" else thing._NAMESPACE
        (self.actuators if section == "actuator" else self.sensors).append(thing)
        for child in thing._children:
            self.collect_section(child)

    def inertial(self, body: Any) -> str:
        if body.mass is None:
            return ""
        parts = [f'mass="{_fmt(body.mass)}"']
        if body.ipos is not None:
            parts.append(f'pos="{_vec(body.ipos)}"')
        if body.iquat is not None and body.fullinertia is None:
            # MJCF forbids an orientation next to fullinertia (the tensor carries it).
            parts.append(f'quat="{_vec(body.iquat)}"')
        if body.fullinertia is not None:
            parts.append(f'fullinertia="{_vec(body.fullinertia)}"')
        elif body.inertia is not None:
            parts.append(f'diaginertia="{_vec(body.inertia)}"')
        return f"<inertial {' '.join(parts)}/>"

    def write_sections(self) -> None:
        if self.actuators:
            self.out.append("  <actuator>")
            for act in sorted(self.actuators, key=lambda t: t.ID):
                self.order.setdefault("actuator", []).append(act.ID)
                if act._NAMESPACE == "raw":
                    self.out.append(f"    {act.xml}")
                    continue
                target = act._parent._NAMESPACE
                parts = [self.attrs(act), f'{target}="{_q(self.names[act._parent.ID])}"']
                self.out.append(f"    <{act._TAG} {' '.join(p for p in parts if p)}/>")
            self.out.append("  </actuator>")
        if self.sensors:
            self.out.append("  <sensor>")
            for sensor in sorted(self.sensors, key=lambda t: t.ID):
                self.order.setdefault("sensor", []).append(sensor.ID)
                text = sensor.xml if sensor._NAMESPACE == "raw" else self.sensor_xml(sensor)
                self.out.append(f"    {text}")
            self.out.append("  </sensor>")

    def sensor_xml(self, sensor: Any) -> str:
        parent = sensor._parent
        target = "world" if parent is self.root else self.names[parent.ID]
        if sensor._TARGET_ATTR == "objname":
            attrs = self.attrs(sensor, skip={"objtype", "reftype", "refname"})
            objtype = sensor.objtype or parent._NAMESPACE or "body"
            extra = f'objtype="{objtype}" objname="{_q(target)}"'
            if sensor.refname is not None:
                ref = sensor.refname
                reftype = sensor.reftype or (
                    ref._NAMESPACE if isinstance(ref, BaseThing) else "body"
                )
                extra += f' reftype="{reftype}" refname="{_q(self.ref_name(ref))}"'
        else:
            attrs = self.attrs(sensor)
            extra = f'{sensor._TARGET_ATTR}="{_q(target)}"'
        return f"<{sensor._TAG} {' '.join(p for p in (attrs, extra) if p)}/>"


def _hashable(value: Any) -> Any:
    if hasattr(value, "tobytes"):
        return (value.dtype.str, value.tobytes())
    return value


def _unique(
    taken: set[tuple[str, str]], kind: str, base: str, next_k: dict[tuple[str, str], int]
) -> str:
    """``base``, or ``base_k`` with the smallest ``k >= 1`` not ``taken`` yet. ``next_k``
    remembers where each base's search stopped (``taken`` only grows), so many assets
    of one name cost linear time, not quadratic."""
    name = base
    if (kind, name) in taken:
        k = next_k.get((kind, base), 1)
        name = f"{base}_{k}"
        while (kind, name) in taken:
            k += 1
            name = f"{base}_{k}"
        next_k[(kind, base)] = k + 1
    taken.add((kind, name))
    return name


def _fmt(value: float) -> str:
    from robotwright.things.attrs import fmt_float

    return fmt_float(value)


def _vec(values: Any) -> str:
    from robotwright.things.attrs import fmt_float

    return " ".join(fmt_float(v) for v in values)


def write_mjcf(
    world: Any, path_for: Callable[[str], str] | None = None
) -> tuple[str, dict[str, list[int]]]:
    """MJCF text of a World and, per namespace, Thing IDs in model-id order.

    Raises:
        GeneratorError: bodies nest deeper than MuJoCo's MJCF reader accepts
            (:data:`~robotwright._inputs.MJCF_MAX_BODY_DEPTH`).
    """
    _check_depth(world)
    w = _Writer(world, path_for)
    w.collect_assets()
    model_name = world.name or "robotwright"
    w.out.append(f'<mujoco model="{_q(model_name)}">')
    w.out.append(f"  {world._compiler_xml()}")
    option = world._option_xml(w)
    if option:
        w.out.append(f"  {option}")
    for snippet in world._head_xml():
        w.out.append(snippet)
    w.write_assets()
    w.out.append("  <worldbody>")
    w.order["body"] = [world.ID]
    w.write_children(world, "    ")
    w.out.append("  </worldbody>")
    for ns, pairs in w.by_body.items():
        w.order[ns] = [thing_id for _, thing_id in sorted(pairs, key=lambda p: p[0])]
    w.write_sections()
    for snippet in world._tail_xml():
        w.out.append(snippet)
    w.out.append("</mujoco>")
    return "\n".join(w.out) + "\n", w.order


def _check_depth(world: Any) -> None:
    """Refuse (iteratively, before the recursive writer runs) a body tree deeper than
    MuJoCo's XML reader accepts."""
    stack = [(world, 0)]
    while stack:
        node, depth = stack.pop()
        for child in node._children:
            if child._NAMESPACE == "body":
                if depth + 1 > MJCF_MAX_BODY_DEPTH:
                    raise GeneratorError(
                        f"{world._label()}: {child._label()} is nested {depth + 1} bodies "
                        f"deep; MuJoCo's MJCF reader accepts at most {MJCF_MAX_BODY_DEPTH}"
                    )
                stack.append((child, depth + 1))
