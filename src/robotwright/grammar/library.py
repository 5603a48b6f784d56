"""Component library: the parts a grammar symbol can become, with parameters and ports.

Units are SI (metres, kilograms, kg/m^3) and angles are radians.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Literal

from robotwright._names import shown

ComponentKind = Literal["base", "mount", "connector", "link", "gripper", "tool"]
COMPONENT_KINDS: tuple[str, ...] = ("base", "mount", "connector", "link", "gripper", "tool")

# Parameters each component kind needs so that it can be built (name -> meaning).
REQUIRED_PARAMS: dict[str, dict[str, str]] = {
    "base": {"diameter": "base cylinder diameter (m)", "thickness": "base height (m)"},
    "mount": {},
    "connector": {},
    "link": {
        "length": "link length along body x (m)",
        "diameter": "link diameter (m)",
        "rotation": "twist of the next joint axis about the link axis (rad)",
    },
    "gripper": {"finger_length": "finger length (m)"},
    "tool": {"length": "tool length along body x (m)"},
}


@dataclass(frozen=True)
class ParamDomain:
    """A component parameter: physical domain ``[low, high]`` and the discrete choices.

    Attributes:
        name: parameter name.
        low, high: inclusive physical domain.
        values: the discrete values used by enumeration, sampling and search; each
            lies in ``[low, high]``.
    """

    name: str
    low: float
    high: float
    values: tuple[float, ...]

    def __post_init__(self) -> None:
        if not (math.isfinite(self.low) and math.isfinite(self.high) and self.low <= self.high):
            raise ValueError(f"parameter {shown(self.name)}: range must be finite with low <= high")
        if not self.values:
            raise ValueError(f"parameter {shown(self.name)}: needs at least one value")

    def contains(self, value: float) -> bool:
        """Whether ``value`` lies in the physical domain (inclusive)."""
        return self.low <= value <= self.high


@dataclass(frozen=True)
class DofSpec:
    """One joint degree of freedom of a connector.

    Attributes:
        type: ``"hinge"`` (rotation about the joint frame's z) or ``"slide"`` (along z).
        twist: modified-DH alpha of this DoF relative to the previous frame (rad).
        range: lower and upper limit, each a number or a parameter name, optionally
            negated (``"-limit"``); radians for hinges, metres for slides.
    """

    type: Literal["hinge", "slide"]
    twist: float = 0.0
    range: tuple[float | str, float | str] = (0.0, 0.0)

    def __post_init__(self) -> None:
        if self.type not in ("hinge", "slide"):
            raise ValueError(f"dof type must be 'hinge' or 'slide', got {shown(self.type)}")

    def resolve_range(self, params: dict[str, float]) -> tuple[float, float]:
        """The numeric joint range for the component's parameter values."""
        return (_resolve(self.range[0], params), _resolve(self.range[1], params))


def _resolve(item: float | str, params: dict[str, float]) -> float:
    if isinstance(item, str):
        sign = -1.0 if item.startswith("-") else 1.0
        return sign * float(params[item.lstrip("-")])
    return float(item)


@dataclass(frozen=True)
class Component:
    """A library component that a grammar symbol can become.

    Attributes:
        name: unique component name (``"revolute"``).
        symbol: the grammar symbol it realises (``"C"``).
        kind: how it is built (base, mount, connector, link, gripper, tool).
        attach: port types through which it attaches to its parent.
        offer: port types it offers to its children.
        params: parameter domains by name.
        density: material density (kg/m^3) used to compute mass and inertia of its geoms.
        rgba: colour.
        dofs: joint DoFs (connectors only; one DoF per entry).
        housing: connector housing cylinder ``{"diameter": m, "length": m}``.
        actuator: ``{"peak_torque": N m or N, "peak_velocity": rad/s or m/s}`` (connectors),
            optionally ``"peak_bearing_force"`` [N] and ``"peak_bearing_moment"`` [N m]:
            what the joint's bearing (hinge) or guide (slide) carries besides its axis
            (the ``payload`` objective counts them; no rating: not limited).
    """

    name: str
    symbol: str
    kind: str
    attach: tuple[str, ...] = ()
    offer: tuple[str, ...] = ()
    params: dict[str, ParamDomain] = field(default_factory=dict)
    density: float = 1000.0
    rgba: tuple[float, float, float, float] = (0.7, 0.7, 0.7, 1.0)
    dofs: tuple[DofSpec, ...] = ()
    housing: dict[str, float] = field(default_factory=dict)
    actuator: dict[str, float] = field(default_factory=dict)

    def __post_init__(self) -> None:
        if self.kind not in COMPONENT_KINDS:
            raise ValueError(
                f"component {shown(self.name)}: kind must be one of {COMPONENT_KINDS}, got {shown(self.kind)}"
            )
        if self.density <= 0:
            raise ValueError(f"component {shown(self.name)}: density must be > 0 kg/m^3")

    def n_choices(self) -> int:
        """Number of distinct parameter assignments (product of value counts)."""
        n = 1
        for p in self.params.values():
            n *= len(p.values)
        return n

    def assignment(self, index: int) -> dict[str, float]:
        """The ``index``-th parameter assignment (mixed radix, params in name order)."""
        out: dict[str, float] = {}
        for name in sorted(self.params):
            vals = self.params[name].values
            index, r = divmod(index, len(vals))
            out[name] = vals[r]
        return out


@dataclass(frozen=True)
class Library:
    """A component library: components by name, and the port types they use."""

    name: str
    components: dict[str, Component]
    ports: tuple[str, ...] = ()
    source: str = "<memory>"

    def for_symbol(self, symbol: str) -> list[Component]:
        """Components realising ``symbol``, in file order."""
        return [c for c in self.components.values() if c.symbol == symbol]

    def n_choices(self, symbol: str) -> int:
        """Number of (component, parameter assignment) choices for a new ``symbol`` node."""
        return sum(c.n_choices() for c in self.for_symbol(symbol))

    def choice(self, symbol: str, index: int) -> tuple[Component, dict[str, float]]:
        """The ``index``-th (component, params) choice for ``symbol``."""
        for comp in self.for_symbol(symbol):
            n = comp.n_choices()
            if index < n:
                return comp, comp.assignment(index)
            index -= n
        raise IndexError(f"choice index out of range for symbol {symbol!r}")
