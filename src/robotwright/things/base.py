"""BaseThing: the tree node, attribute registries, copying and naming shared by all Things.

Class-level registries
----------------------
Each registry is aggregated along the class hierarchy by :class:`ThingType` when a
class is created, so a new Thing subclass declares only what it adds or removes:

=====================  ===========================================  ===================
registry               built from                                   structure
=====================  ===========================================  ===================
``_MUJOCO_ATTR``       ``_NEW_MUJOCO_ATTR`` / ``_DEL_MUJOCO_ATTR``  {MJCF name: type}
``_BLUEPRINT_ATTR``    ``_NEW_BLUEPRINTS_ATTR`` / ``_DEL_...``      {init arg: type}
``_NO_COPY_VALS``      ``_NEW_NO_COPY_VALS``                        {attribute names}
``_DERIVED_ATTR``      ``_NEW_DERIVED_ATTR``                        {attribute names}
``_DEFAULT_VALS``      ``_NEW_DEFAULT_VALS``                        {name: MuJoCo default}
=====================  ===========================================  ===================

A *derived* attribute is written to MJCF but fixed by the class (``Sphere.type ==
"sphere"``); reading MJCF picks the subclass whose derived values match the element.

Names
-----
A Thing keeps the name its user gave unless another Thing of the same namespace (MuJoCo
object type: body, joint, geom, ...) in the same tree requests the same name. Then the
tree is walked depth-first in child order; the first Thing keeps the name and each later
one becomes ``<name>_<k>`` with the smallest ``k >= 1`` that no Thing of that namespace
in the tree requests or already got. Unnamed Things stay unnamed unless another element
must refer to them by name (an actuator on a joint, a sensor on a site): they are then
named after their class (``hinge``, ``site``) and enumerated the same way.
``thing.name`` always reports the resolved name.
"""

from __future__ import annotations

import copy as _copy
from collections.abc import Iterator
from typing import Any, ClassVar

from robotwright._names import name_problem
from robotwright.things.attrs import Extras, Ref, Text, ThingAttributeError
from robotwright.things.registry import REGISTRY, bump_asset_epoch, next_version

_REGISTRIES: tuple[tuple[str, str, str | None, type], ...] = (
    ("_MUJOCO_ATTR", "_NEW_MUJOCO_ATTR", "_DEL_MUJOCO_ATTR", dict),
    ("_BLUEPRINT_ATTR", "_NEW_BLUEPRINTS_ATTR", "_DEL_BLUEPRINTS_ATTR", dict),
    ("_NO_COPY_VALS", "_NEW_NO_COPY_VALS", None, set),
    ("_DERIVED_ATTR", "_NEW_DERIVED_ATTR", None, set),
    ("_DEFAULT_VALS", "_NEW_DEFAULT_VALS", None, dict),
)


class ThingType(type):
    """Metaclass that aggregates the class-level attribute registries along the MRO."""

    def __init__(cls, name: str, bases: tuple[type, ...], ns: dict[str, Any]) -> None:
        super().__init__(name, bases, ns)
        for agg, new, delete, kind in _REGISTRIES:
            merged: Any = kind()
            for base in reversed(bases):
                merged.update(getattr(base, agg, kind()))
            merged.update(ns.get(new, kind()))
            if delete is not None:
                for key in ns.get(delete, ()):
                    merged.pop(key, None)
            setattr(cls, agg, merged)
        # References to other Things are re-pointed after a copy, never deep-copied.
        cls._NO_COPY_VALS = cls._NO_COPY_VALS | {
            k for k, t in cls._MUJOCO_ATTR.items() if isinstance(t, Ref)
        }


class BaseThing(metaclass=ThingType):
    """The base of every Thing: ID, tree links, attribute registries, copy and naming.

    Args:
        name: the user's name. It may be enumerated to resolve clashes (see module doc).
        parent: a Thing to attach to right away.
        extras: (keyword) a dict of Python-side data carried along and copied deeply,
            never written to MJCF (the HRDF bridge keeps HRDF-only columns there).
        **kwargs: values for any attribute in ``_BLUEPRINT_ATTR``; unknown names raise
            ``TypeError`` (a misspelt attribute is never silently ignored).
    """

    #: MuJoCo object type; Things of one namespace in a tree get unique names.
    _NAMESPACE: ClassVar[str | None] = None
    #: MJCF tag written for this Thing.
    _TAG: ClassVar[str] = ""
    #: Namespaces of Things that may be attached to this one.
    _CHILD_KINDS: ClassVar[frozenset[str]] = frozenset()
    #: True when this Thing refers to its parent by name (actuator on a joint, ...).
    _NAMES_PARENT: ClassVar[bool] = False
    #: Namespaces this Thing may be attached to (empty: any that accepts its kind).
    _TARGET_KINDS: ClassVar[frozenset[str]] = frozenset()

    _NEW_BLUEPRINTS_ATTR: ClassVar[dict[str, Any]] = {"name": Text(), "extras": Extras()}
    _NEW_NO_COPY_VALS: ClassVar[set[str]] = set()

    _MUJOCO_ATTR: ClassVar[dict[str, Any]]
    _BLUEPRINT_ATTR: ClassVar[dict[str, Any]]
    _NO_COPY_VALS: ClassVar[set[str]]
    _DERIVED_ATTR: ClassVar[set[str]]
    _DEFAULT_VALS: ClassVar[dict[str, Any]]

    def __init__(self, name: str | None = None, parent: BaseThing | None = None, **kwargs: Any):
        object.__setattr__(self, "ID", REGISTRY.register(self))
        object.__setattr__(self, "_parent", None)
        object.__setattr__(self, "_children", [])
        object.__setattr__(self, "_version", next_version())
        object.__setattr__(self, "_name_cache", None)
        self.name = name
        cls = type(self)
        unknown = [k for k in kwargs if k not in cls._BLUEPRINT_ATTR or k in cls._DERIVED_ATTR]
        if unknown:
            raise TypeError(
                f"{cls.__name__}() got unknown attribute(s) {', '.join(sorted(unknown))}; "
                f"known: {', '.join(sorted(a for a in cls._BLUEPRINT_ATTR if a != 'name'))}"
            )
        state = self.__dict__
        defaults = cls.__dict__.get("_INIT_DEFAULTS")
        if defaults is None:
            defaults = cls._init_defaults()
        # Validated defaults are immutable (read-only arrays), so instances may share them.
        state.update(defaults)
        # Python-side data (e.g. HRDF columns MuJoCo has no field for); never in MJCF.
        state["extras"] = {}
        attrs = cls._MUJOCO_ATTR
        for key, value in kwargs.items():
            spec = attrs.get(key)
            if spec is None:
                setattr(self, key, value)
            else:
                state[key] = spec.convert(value, self, key)
        if parent is not None:
            parent.attach(self)

    @classmethod
    def _init_defaults(cls) -> dict[str, Any]:
        defaults = {
            key: cls._MUJOCO_ATTR[key].convert(_copy.deepcopy(value), cls, key)
            for key, value in cls._DEFAULT_VALS.items()
            if key in cls._MUJOCO_ATTR and key not in cls._DERIVED_ATTR
        }
        cls._INIT_DEFAULTS = defaults
        return defaults

    # ----------------------------------------------------------------- attributes
    def __setattr__(self, key: str, value: Any) -> None:
        if key in self._DERIVED_ATTR:
            raise ThingAttributeError(
                f"{self._label()}.{key} is fixed by the class {type(self).__name__}; "
                "create a Thing of another class instead"
            )
        spec = self._MUJOCO_ATTR.get(key)
        if spec is not None:
            value = spec.convert(value, self, key)
        object.__setattr__(self, key, value)
        if spec is not None:
            self._touch()

    def _label(self) -> str:
        user = self.__dict__.get("_name")
        shown = f" '{user}'" if user else ""
        return f"{type(self).__name__}{shown} (ID {self.__dict__.get('ID')})"

    def __repr__(self) -> str:
        return f"<{self._label()}>"

    def mujoco_attributes(self) -> dict[str, Any]:
        """All MJCF attribute values of this Thing (derived ones included)."""
        return {k: getattr(self, k) for k in self._MUJOCO_ATTR}

    # ----------------------------------------------------------------- tree
    @property
    def parent(self) -> BaseThing | None:
        """The Thing this one is attached to; assign to re-parent, None to detach."""
        return self._parent

    @parent.setter
    def parent(self, new_parent: BaseThing | None) -> None:
        if new_parent is None:
            self.detach()
        else:
            new_parent.attach(self)

    @property
    def children(self) -> tuple[BaseThing, ...]:
        return tuple(self._children)

    @property
    def root(self) -> BaseThing:
        """The root of the tree this Thing is part of (itself when unattached)."""
        node = self
        while node._parent is not None:
            node = node._parent
        return node

    @property
    def path(self) -> list[BaseThing]:
        """The Things from this one up to its root, both included."""
        out = [self]
        while out[-1]._parent is not None:
            out.append(out[-1]._parent)
        return out

    def attach(self, *things: BaseThing) -> BaseThing:
        """Attach Things as children (re-parenting them if attached elsewhere); returns self."""
        for thing in things:
            if not isinstance(thing, BaseThing):
                raise ThingAttributeError(f"{self._label()}.attach: {thing!r} is not a Thing")
            if thing._NAMESPACE not in self._CHILD_KINDS:
                raise ThingAttributeError(
                    f"{self._label()}.attach: a {type(thing).__name__} cannot be attached to a "
                    f"{type(self).__name__} (accepts: {', '.join(sorted(self._CHILD_KINDS))})"
                )
            kind = self._NAMESPACE or getattr(self, "_TARGET_AS", None)
            if thing._TARGET_KINDS and kind not in thing._TARGET_KINDS:
                raise ThingAttributeError(
                    f"{self._label()}.attach: a {type(thing).__name__} measures or drives a "
                    f"{' or '.join(sorted(thing._TARGET_KINDS))}, not a {type(self).__name__}"
                )
            if any(node is thing for node in self.path):
                raise ThingAttributeError(
                    f"{self._label()}.attach: {thing._label()} is this Thing or one of its "
                    "ancestors; attaching it would make a cycle"
                )
            if thing._parent is not None:
                thing.detach()
            object.__setattr__(thing, "_parent", self)
            self._children.append(thing)
        self._touch()
        return self

    def detach(self) -> BaseThing:
        """Remove this Thing from its parent; it becomes the root of its own tree."""
        parent = self._parent
        if parent is not None:
            parent._children.remove(self)
            object.__setattr__(self, "_parent", None)
            parent._touch()
            self._touch()
        return self

    def walk(self) -> Iterator[BaseThing]:
        """This Thing and all below it, depth-first in child order (MJCF order)."""
        stack = [self]
        while stack:
            node = stack.pop()
            yield node
            stack.extend(reversed(node._children))

    def find_all(self, kind: type | tuple[type, ...] = object) -> list[Any]:
        """All Things of a class in this subtree (this one included), in MJCF order."""
        return [t for t in self.walk() if isinstance(t, kind)]

    def find(self, name: str, kind: type | tuple[type, ...] = object) -> Any:
        """The Thing of a class whose resolved name is ``name``; KeyError naming it if none."""
        for thing in self.walk():
            if isinstance(thing, kind) and thing.name == name:
                return thing
        raise KeyError(f"no {getattr(kind, '__name__', 'Thing')} named {name!r} under {self}")

    def _touch(self) -> None:
        root = self.root
        object.__setattr__(root, "_version", next_version())
        if getattr(self, "_ASSET_KIND", None):
            bump_asset_epoch()

    # ----------------------------------------------------------------- names
    @property
    def name(self) -> str | None:
        """The resolved name (the user's name, enumerated when it clashes in the tree)."""
        root = self.root
        if self._NAMESPACE is None:
            return self._name
        return root._resolved_names().get(self.ID, self._name)

    @name.setter
    def name(self, value: str | None) -> None:
        if value is not None and (not isinstance(value, str) or not value):
            raise ThingAttributeError(
                f"{self._label()}.name: got {value!r}, expected a non-empty string or None"
            )
        problem = None if value is None else name_problem(value)
        if problem is not None:
            shown = value if len(value) <= 80 else f"{value[:80]}..."  # type: ignore[index]
            raise ThingAttributeError(f"{self._label()}.name: {shown!r} {problem}")
        object.__setattr__(self, "_name", value)
        self._touch()

    def _needs_name(self) -> bool:
        return any(c._NAMES_PARENT for c in self._children)

    def _resolved_names(self) -> dict[int, str]:
        cache = self._name_cache
        if cache is not None and cache[0] == self._version:
            return cache[1]
        referenced: set[int] = set()
        order: list[BaseThing] = []
        for thing in self.walk():
            order.append(thing)
            for key, spec in thing._MUJOCO_ATTR.items():
                if isinstance(spec, Ref):
                    value = thing.__dict__.get(key)
                    if isinstance(value, BaseThing):
                        referenced.add(value.ID)
        requested: dict[tuple[str, str], int] = {}
        wanted: list[tuple[BaseThing, str]] = []
        for thing in order:
            if thing._NAMESPACE is None:
                continue
            base = thing._name
            if base is None and (thing.ID in referenced or thing._needs_name()):
                base = type(thing).__name__.lower()
            if base is None:
                continue
            wanted.append((thing, base))
            requested[(thing._NAMESPACE, base)] = requested.get((thing._NAMESPACE, base), 0) + 1
        resolved: dict[int, str] = {}
        taken: set[tuple[str, str]] = set()
        # The next suffix to try per requested name. ``taken`` only grows, so a suffix
        # refused once stays refused: each name resumes where its last clash stopped
        # (linear in the number of clashes; restarting at 1 made 20,000 copies quadratic).
        next_k: dict[tuple[str, str], int] = {}
        for thing, base in wanted:
            ns = thing._NAMESPACE
            final = base
            if (ns, base) in taken:
                k = next_k.get((ns, base), 1)
                while (ns, f"{base}_{k}") in taken or (ns, f"{base}_{k}") in requested:
                    k += 1
                next_k[(ns, base)] = k + 1
                final = f"{base}_{k}"
            taken.add((ns, final))
            resolved[thing.ID] = final
        object.__setattr__(self, "_name_cache", (self._version, resolved))
        return resolved

    # ----------------------------------------------------------------- copy
    def copy(self, **kwargs: Any) -> BaseThing:
        """A deep copy of this Thing and its subtree; ``kwargs`` override attributes.

        No mutable state is shared (arrays, lists, children). Attributes in
        ``_NO_COPY_VALS`` are shared on purpose (assets such as meshes); references to
        Things inside the copied subtree point to their copies.
        """
        memo: dict[int, BaseThing] = {}
        new = self._copy_tree(memo, kwargs)
        for original_id, clone in memo.items():
            original = REGISTRY.get(original_id)
            for key, spec in clone._MUJOCO_ATTR.items():
                if not isinstance(spec, Ref) or key in clone._DERIVED_ATTR:
                    continue
                if original_id == self.ID and key in kwargs:
                    continue
                value = original.__dict__.get(key)
                if isinstance(value, BaseThing) and value.ID in memo:
                    setattr(clone, key, memo[value.ID])
        return new

    def _copy_tree(self, memo: dict[int, BaseThing], overrides: dict[str, Any]) -> BaseThing:
        # Iterative (a chain of thousands of bodies exceeds Python's recursion limit).
        # Copies are made depth-first in child order, as MJCF lists them; children are
        # attached from the deepest up, so each parent is still a root when it receives
        # its children (attach checks the parent's path: cheap for a root).
        made: list[tuple[BaseThing, BaseThing]] = []
        stack: list[BaseThing] = [self]
        while stack:
            node = stack.pop()
            new = node._copy_one(overrides if node is self else {})
            memo[node.ID] = new
            made.append((node, new))
            stack.extend(reversed(node._children))
        for node, new in reversed(made):
            if node._children:
                new.attach(*(memo[child.ID] for child in node._children))
        return memo[self.ID]

    def _copy_one(self, overrides: dict[str, Any]) -> BaseThing:
        """A copy of this Thing alone (no children); ``overrides`` replace attributes."""
        args: dict[str, Any] = {}
        for key in self._BLUEPRINT_ATTR:
            if key in overrides or key in self._DERIVED_ATTR:
                continue
            value = self._name if key == "name" else self.__dict__.get(key)
            args[key] = value if key in self._NO_COPY_VALS else _copy.deepcopy(value)
        args.update(overrides)
        return type(self)(**args)
