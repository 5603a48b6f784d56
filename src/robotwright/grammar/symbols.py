"""Grammar symbols and node patterns (``-L*``: a link node with edges, open end)."""

from __future__ import annotations

import re
from dataclasses import dataclass
from typing import Literal, NamedTuple

from robotwright._names import shown

SymbolKind = Literal["terminal", "nonterminal"]

_PATTERN = re.compile(r"^\s*(-?)\s*([A-Za-z_][A-Za-z0-9_]*)\s*(\*?)\s*$")


@dataclass(frozen=True)
class Symbol:
    """A grammar symbol.

    Attributes:
        name: the symbol's name as written in rules (``"L"``).
        kind: ``"terminal"`` symbols are never rewritten; ``"nonterminal"`` ones may be.
        description: free text shown in docs and ``grammar check``.
    """

    name: str
    kind: SymbolKind
    description: str = ""

    def __post_init__(self) -> None:
        if self.kind not in ("terminal", "nonterminal"):
            raise ValueError(
                f"symbol {shown(self.name)}: kind must be 'terminal' or 'nonterminal', got {shown(self.kind)}"
            )


@dataclass(frozen=True)
class NodePattern:
    """One node of a rule side, parsed from the grammar's notation.

    ``-X`` (``keep=True``): on a left side, the node has at least one edge; on a right
    side (first node only), the matched node is kept with its component, parameters and
    edges. ``X*`` (``open=True``): on a left side, match only an open end; on a right
    side, leave the node open so that later rules may grow it.
    """

    symbol: str
    keep: bool = False
    open: bool = False

    @classmethod
    def parse(cls, text: str) -> NodePattern:
        """Parse ``"-L*"``-style text; raises ``ValueError`` naming the text."""
        m = _PATTERN.match(text) if isinstance(text, str) else None
        if m is None:
            raise ValueError(
                f"cannot parse node {shown(text)}: expected SYMBOL with optional leading '-' "
                "and trailing '*', e.g. '-L*'"
            )
        return cls(symbol=m.group(2), keep=m.group(1) == "-", open=m.group(3) == "*")

    def __str__(self) -> str:
        return f"{'-' if self.keep else ''}{self.symbol}{'*' if self.open else ''}"


class NodeState(NamedTuple):
    """What a rule's left side can see of a node: its symbol, open mark, and edges.

    A named tuple, not a dataclass: derivations hash and compare states at every step
    (sampling, counting, replay), and a tuple does both in C."""

    symbol: str
    open: bool
    has_edges: bool

    def __str__(self) -> str:
        return f"{'-' if self.has_edges else ''}{self.symbol}{'*' if self.open else ''}"


def parse_chain(text: str) -> tuple[NodePattern, ...]:
    """Parse a right side ``"-B -> C -> L*"`` into node patterns (``ValueError`` if bad)."""
    if not isinstance(text, str):
        raise ValueError(f"cannot parse chain {shown(text)}: expected a text 'A -> B'")
    parts = text.split("->")
    if any(not p.strip() for p in parts):
        raise ValueError(f"cannot parse chain {shown(text)}: empty node between '->'")
    nodes = tuple(NodePattern.parse(p) for p in parts)
    for i, node in enumerate(nodes[1:], start=1):
        if node.keep:
            raise ValueError(
                f"chain {shown(text)}: only the first node may be written '-X' (node {i} is {node})"
            )
    return nodes
