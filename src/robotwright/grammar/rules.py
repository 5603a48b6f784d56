"""Rules and the grammar G = (N, T, A, R, S) they form, with the node-state analysis.

A node's *state* is what a left side can see of it: symbol, open mark, whether it
has edges (:class:`~robotwright.grammar.symbols.NodeState`). Rules map a state to
the state of the matched node after the rule plus the states of the new nodes.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from robotwright.grammar.library import Library
from robotwright.grammar.symbols import NodePattern, NodeState, Symbol


@dataclass(frozen=True)
class Rule:
    """A rewriting rule ``lhs => rhs``.

    Attributes:
        name: rule name (``"r3"``), used in readable designs.
        lhs: the matched node.
        rhs: a chain; ``rhs[0]`` is the matched node after the rule (kept when
            ``rhs[0].keep``, else replaced by a new component), ``rhs[1:]`` are new
            nodes, each the child of the node before it.
        branching: when True and ``lhs`` has no open mark, the rule may grow any node
            of its symbol (an interior node gets a second branch). Without it, a
            left side without ``*`` is rejected when the symbol can occur closed.
        description: free text.
    """

    name: str
    lhs: NodePattern
    rhs: tuple[NodePattern, ...]
    branching: bool = False
    description: str = ""

    def __post_init__(self) -> None:
        if not self.rhs:
            raise ValueError(f"rule {self.name!r}: right side is empty")

    def matches(self, state: NodeState) -> bool:
        """Whether the left side matches a node in ``state``."""
        if state.symbol != self.lhs.symbol:
            return False
        if self.lhs.open and not state.open:
            return False
        return state.has_edges == self.lhs.keep

    def result_states(self, state: NodeState) -> tuple[NodeState, tuple[NodeState, ...]]:
        """State of the matched node after the rule, and the states of the new nodes."""
        head = self.rhs[0]
        has_edges = state.has_edges or len(self.rhs) > 1
        kept = NodeState(head.symbol, head.open, has_edges)
        new = tuple(NodeState(n.symbol, n.open, True) for n in self.rhs[1:])
        return kept, new

    def __str__(self) -> str:
        return f"{self.name}: {self.lhs} => {' -> '.join(str(n) for n in self.rhs)}"


@dataclass(frozen=True)
class Grammar:
    """A validated grammar bound to a component library.

    Build it with :func:`robotwright.grammar.loader.load_grammar`, which checks it.

    Attributes:
        name: grammar name.
        start: the start symbol; a derivation starts from one open, isolated node of it.
        symbols: symbols by name.
        rules: rules by name, in file order.
        library: the component library.
        link_symbols: symbols counted as links by size limits (``--max-links``).
        source: the grammar file.
    """

    name: str
    start: str
    symbols: dict[str, Symbol]
    rules: dict[str, Rule]
    library: Library
    link_symbols: tuple[str, ...] = ()
    source: str = "<memory>"
    _cache: dict = field(default_factory=dict, compare=False, repr=False)

    def __getstate__(self) -> dict:
        # Caches are rebuilt on demand; leaving them out keeps worker pickles small.
        state = dict(self.__dict__)
        state["_cache"] = {}
        return state

    @property
    def start_state(self) -> NodeState:
        return NodeState(self.start, True, False)

    def matching_rules(self, state: NodeState) -> list[Rule]:
        """Rules whose left side matches a node in ``state``, in file order."""
        key = ("match", state)
        hit = self._cache.get(key)
        if hit is None:
            hit = self._cache[key] = [r for r in self.rules.values() if r.matches(state)]
        return hit

    def n_choices(self, symbol: str) -> int:
        """(component, parameters) choices of a new ``symbol`` node (1 if it has no component)."""
        key = ("n_choices", symbol)
        hit = self._cache.get(key)
        if hit is None:
            n = self.library.n_choices(symbol)
            hit = self._cache[key] = n if n else 1
        return hit

    def is_link(self, symbol: str) -> bool:
        return symbol in self.link_symbols

    def reachable_states(self) -> set[NodeState]:
        """Every node state a derivation from the start can produce."""
        seen = {self.start_state}
        todo = [self.start_state]
        while todo:
            st = todo.pop()
            for rule in self.matching_rules(st):
                kept, new = rule.result_states(st)
                for s in (kept, *new):
                    if s not in seen:
                        seen.add(s)
                        todo.append(s)
        return seen
