"""Applying rules: partial derivations, exact counting, enumeration, uniform sampling.

Canonical order. A derivation grows one node at a time, depth first: the current node
receives rule applications until it *stops* (allowed only once it is closed, i.e. not
an open end); then the nodes it created are grown in creation order. A node with no
applicable rule stops by itself; a node that a ``branching`` rule may still grow makes
the choice explicit. Every design (derivation tree) has exactly one canonical step
list, so counting, enumeration and sampling all range over the same set.
"""

from __future__ import annotations

import random
import sys
from collections.abc import Iterator
from dataclasses import dataclass

from robotwright.errors import GrammarError, Problem
from robotwright.grammar.design import Choice, Design, DesignNode, Step
from robotwright.grammar.library import Component
from robotwright.grammar.rules import Grammar, Rule
from robotwright.grammar.symbols import NodeState

# (node id, ids of the nodes it created so far) for each node still to be grown.
_Entry = tuple[int, tuple[int, ...]]


@dataclass(frozen=True)
class Partial:
    """An immutable partial derivation in canonical order.

    Attributes:
        grammar: the grammar.
        states: state of every node, by id.
        stack: nodes still to grow; the last entry is the current node.
        steps: the steps so far.
        links: number of link-symbol nodes so far.
    """

    grammar: Grammar
    states: tuple[NodeState, ...]
    stack: tuple[_Entry, ...]
    steps: tuple[Step, ...] = ()
    links: int = 0

    @classmethod
    def start(cls, grammar: Grammar) -> Partial:
        return cls(grammar, (grammar.start_state,), ((0, ()),)).settle()

    @property
    def complete(self) -> bool:
        return not self.stack

    @property
    def current(self) -> int | None:
        return self.stack[-1][0] if self.stack else None

    def rules(self) -> list[Rule]:
        """Rules applicable at the current node."""
        if not self.stack:
            return []
        return self.grammar.matching_rules(self.states[self.current])

    def can_stop(self) -> bool:
        return bool(self.stack) and not self.states[self.current].open

    def stop(self) -> Partial:
        """Finish the current node (must be closed) and move on to the next one."""
        if not self.can_stop():
            raise ValueError("the current node is open and cannot stop")
        node, created = self.stack[-1]
        stack = self.stack[:-1] + tuple((c, ()) for c in reversed(created))
        return Partial(self.grammar, self.states, stack, self.steps, self.links).settle()

    def settle(self) -> Partial:
        """Stop every current node that has no applicable rule (no choice to make)."""
        p = self
        while p.stack and not p.rules():
            if p.states[p.current].open:
                return p  # dead end: open with no rule; counted as zero completions
            p = p.stop()
        return p

    def link_delta(self, rule: Rule) -> int:
        g = self.grammar
        head = rule.rhs[0]
        delta = sum(g.is_link(n.symbol) for n in rule.rhs[1:])
        if not head.keep:
            delta += g.is_link(head.symbol) - g.is_link(self.states[self.current].symbol)
        return delta

    def apply(self, rule: Rule, choices: tuple[Choice, ...]) -> Partial:
        """Apply ``rule`` at the current node with the given component choices."""
        node, created = self.stack[-1]
        kept, new = rule.result_states(self.states[node])
        states = list(self.states)
        states[node] = kept
        new_ids = tuple(range(len(states), len(states) + len(new)))
        states.extend(new)
        step = Step(rule.name, node, choices)
        stack = self.stack[:-1] + ((node, created + new_ids),)
        return Partial(
            self.grammar,
            tuple(states),
            stack,
            self.steps + (step,),
            self.links + self.link_delta(rule),
        ).settle()

    def pending_states(self) -> list[NodeState]:
        """States of every node that may still grow (current, created, and queued)."""
        out = []
        for node, created in self.stack:
            out.append(self.states[node])
            out.extend(self.states[c] for c in created)
        return out

    def design(self) -> Design:
        if not self.complete:
            raise ValueError("the derivation is not complete")
        return Design(self.grammar.name, self.steps)


def new_symbols(rule: Rule) -> list[str]:
    """Symbols of the right-side nodes that get a component choice, in order."""
    head = rule.rhs[0]
    return ([] if head.keep else [head.symbol]) + [n.symbol for n in rule.rhs[1:]]


def choice_at(grammar: Grammar, symbol: str, index: int) -> Choice:
    """The ``index``-th component choice of ``symbol`` (``Choice(symbol, None)`` if none)."""
    if not grammar.library.for_symbol(symbol):
        return Choice(symbol, None)
    comp, params = grammar.library.choice(symbol, index)
    return Choice(symbol, comp.name, tuple(sorted(params.items())))


def rule_choices(grammar: Grammar, rule: Rule) -> int:
    n = 1
    for s in new_symbols(rule):
        n *= grammar.n_choices(s)
    return n


def choices_at(grammar: Grammar, rule: Rule, index: int) -> tuple[Choice, ...]:
    """The ``index``-th combination of choices for ``rule`` (mixed radix over new nodes)."""
    key = ("choices", rule.name, index)
    hit = grammar._cache.get(key)
    if hit is None:
        hit = grammar._cache[key] = _choices_at(grammar, rule, index)
    return hit


def _choices_at(grammar: Grammar, rule: Rule, index: int) -> tuple[Choice, ...]:
    out = []
    for s in new_symbols(rule):
        index, r = divmod(index, grammar.n_choices(s))
        out.append(choice_at(grammar, s, r))
    return tuple(out)


#: Most memoised convolutions a :class:`Counter` keeps.
CONV_MEMO = 100_000


class Counter:
    """Exact counts of completions, memoised per grammar.

    ``g(state, n)``: ways to finish a node in ``state`` (and everything it creates)
    adding exactly ``n`` link nodes.
    """

    def __init__(self, grammar: Grammar) -> None:
        self.grammar = grammar
        self._g: dict[tuple[NodeState, int], int] = {}
        self._busy: set[tuple[NodeState, int]] = set()
        # state -> (fewest links found or None, largest link count searched)
        self._min: dict[NodeState, tuple[int | None, int]] = {}
        # (states, n) -> conv(states, n): sampling asks for the same pending states at
        # every step of every design (emptied at CONV_MEMO entries: a bound on memory)
        self._conv: dict[tuple[tuple[NodeState, ...], int], int] = {}

    def g(self, state: NodeState, n: int) -> int:
        if n < 0:
            return 0
        key = (state, n)
        if key in self._g:
            return self._g[key]
        if key in self._busy:
            raise GrammarError(
                [
                    Problem(
                        self.grammar.source,
                        f"derivations of '{state}' can grow forever without adding a link; "
                        "counts are infinite (make every repeatable rule add a link symbol)",
                        element=f"symbol '{state.symbol}'",
                    )
                ]
            )
        self._busy.add(key)
        total = 1 if (not state.open and n == 0) else 0
        for rule in self.grammar.matching_rules(state):
            kept, new = rule.result_states(state)
            p = Partial(self.grammar, (state,), ((0, ()),))
            delta = p.link_delta(rule)
            total += rule_choices(self.grammar, rule) * self.conv((kept, *new), n - delta)
        self._busy.discard(key)
        self._g[key] = total
        return total

    def conv(self, states: tuple[NodeState, ...] | list[NodeState], n: int) -> int:
        """Ways to finish all ``states`` adding exactly ``n`` links in total."""
        if n < 0:
            return 0
        if not states:
            return 1 if n == 0 else 0
        key = (tuple(states), n)
        hit = self._conv.get(key)
        if hit is None:
            if len(self._conv) >= CONV_MEMO:
                self._conv.clear()
            first, rest = key[0][0], key[0][1:]
            hit = self._conv[key] = sum(
                self.g(first, k) * self.conv(rest, n - k) for k in range(n + 1)
            )
        return hit

    def min_links(self, state: NodeState, limit: int) -> int | None:
        """Fewest links that finish a node in ``state``, or None if more than ``limit``."""
        found, searched = self._min.get(state, (None, -1))
        if found is not None:
            return found if found <= limit else None
        for n in range(searched + 1, limit + 1):
            if self.g(state, n) > 0:
                self._min[state] = (n, n)
                return n
        self._min[state] = (None, max(searched, limit))
        return None

    def feasible(self, partial: Partial, max_links: int) -> bool:
        """Whether some completion of ``partial`` has at most ``max_links`` links."""
        need = partial.links
        for st in partial.pending_states():
            m = self.min_links(st, max_links)
            if m is None:
                return False
            need += m
            if need > max_links:
                return False
        return True

    def completions(self, partial: Partial, max_links: int) -> int:
        """Complete designs reachable from ``partial`` with at most ``max_links`` links."""
        budget = max_links - partial.links
        if partial.complete:
            return 1 if budget >= 0 else 0
        states = partial.pending_states()
        return sum(self.conv(states, k) for k in range(budget + 1))


def count(grammar: Grammar, max_links: int) -> int:
    """Exact number of complete designs with at most ``max_links`` link nodes."""
    _check_limit(max_links)
    return Counter(grammar).completions(Partial.start(grammar), max_links)


def count_by_links(grammar: Grammar, max_links: int) -> list[int]:
    """``out[n]`` = number of complete designs with exactly ``n`` links, n = 0..max_links."""
    _check_limit(max_links)
    c = Counter(grammar)
    return [c.conv((grammar.start_state,), n) for n in range(max_links + 1)]


def _check_limit(max_links: int) -> None:
    if not isinstance(max_links, int) or max_links < 0:
        raise ValueError(f"max_links must be an integer >= 0, got {max_links!r}")


def options(partial: Partial) -> list[tuple[Rule | None, int]]:
    """Decisions at the current node: ``(None, 1)`` to stop, ``(rule, n_choices)``."""
    out: list[tuple[Rule | None, int]] = []
    if partial.can_stop():
        out.append((None, 1))
    for rule in partial.rules():
        out.append((rule, rule_choices(partial.grammar, rule)))
    return out


def enumerate_designs(grammar: Grammar, max_links: int) -> Iterator[Design]:
    """Every complete design with at most ``max_links`` links, in canonical order."""
    _check_limit(max_links)
    counter = Counter(grammar)
    limit = sys.getrecursionlimit()
    sys.setrecursionlimit(max(limit, 10_000))
    start = Partial.start(grammar)
    try:
        if counter.feasible(start, max_links):
            yield from _enum(start, max_links, counter)
    finally:
        sys.setrecursionlimit(limit)


def _enum(p: Partial, max_links: int, counter: Counter) -> Iterator[Design]:
    if p.complete:
        if p.links <= max_links:
            yield p.design()
        return
    for rule, n in options(p):
        if rule is None:
            yield from _enum(p.stop(), max_links, counter)
            continue
        first = p.apply(rule, choices_at(p.grammar, rule, 0))
        # Feasibility does not depend on the component choices: test once per rule.
        if not counter.feasible(first, max_links):
            continue
        yield from _enum(first, max_links, counter)
        for i in range(1, n):
            yield from _enum(p.apply(rule, choices_at(p.grammar, rule, i)), max_links, counter)


def sample(
    grammar: Grammar, max_links: int, rng: random.Random, counter: Counter | None = None
) -> Design:
    """One design drawn uniformly from all designs with at most ``max_links`` links.

    All randomness comes from ``rng``; the same seed gives the same design.
    """
    _check_limit(max_links)
    counter = counter or Counter(grammar)
    p = Partial.start(grammar)
    if counter.completions(p, max_links) == 0:
        raise GrammarError(
            [Problem(grammar.source, f"no complete design has at most {max_links} link(s)")]
        )
    while not p.complete:
        p = random_step(p, max_links, rng, counter)
    return p.design()


def random_step(p: Partial, max_links: int, rng: random.Random, counter: Counter) -> Partial:
    """One decision at the current node, weighted so that completions are uniform."""
    weighted: list[tuple[int, Rule | None]] = []
    for rule, n in options(p):
        nxt = p.stop() if rule is None else p.apply(rule, choices_at(p.grammar, rule, 0))
        # Completion counts do not depend on which component was chosen.
        weighted.append((n * counter.completions(nxt, max_links), rule))
    total = sum(w for w, _ in weighted)
    if total == 0:
        raise ValueError("no completion within the link budget")
    r = rng.randrange(total)
    for w, rule in weighted:
        if r < w:
            if rule is None:
                return p.stop()
            return p.apply(
                rule, choices_at(p.grammar, rule, rng.randrange(rule_choices(p.grammar, rule)))
            )
        r -= w
    raise AssertionError("unreachable")


def replay(grammar: Grammar, design: Design, source: str = "<design>") -> DesignNode:
    """Check a design against the grammar and library and return its tree.

    Raises:
        GrammarError: naming the step, the field and what was expected (unknown rule,
            wrong node, unknown component, missing or out-of-domain parameter,
            incomplete design).
    """
    if design.grammar != grammar.name:
        raise GrammarError(
            [Problem(source, f"design is for grammar {design.grammar!r}, not {grammar.name!r}")]
        )
    p = Partial.start(grammar)
    nodes = {0: DesignNode(0, grammar.start)}
    for i, step in enumerate(design.steps):
        where = f"step {i} ({step.rule} @{step.at})"

        def fail(msg: str, col: str | None = None, _w: str = where) -> GrammarError:
            return GrammarError([Problem(source, msg, column=col, element=_w)])

        while p.stack and p.current != step.at and p.can_stop():
            p = p.stop()
        if p.current != step.at:
            nxt = (
                "none (design already complete)"
                if p.complete
                else f"node {p.current} ({p.states[p.current]})"
            )
            raise fail(f"node {step.at} is not the next node to grow; expected {nxt}", "at")
        rule = grammar.rules.get(step.rule)
        if rule is None:
            raise fail(f"unknown rule (grammar has {list(grammar.rules)})", "rule")
        if rule not in p.rules():
            raise fail(f"rule '{rule}' does not match node {step.at} ({p.states[step.at]})", "rule")
        syms = new_symbols(rule)
        if len(step.choices) != len(syms):
            raise fail(
                f"expected {len(syms)} choice(s) for symbols {syms}, got {len(step.choices)}",
                "choices",
            )
        for sym, ch in zip(syms, step.choices):
            _check_choice(grammar, sym, ch, fail)
        head = rule.rhs[0]
        node = nodes[step.at]
        it = iter(step.choices)
        if not head.keep:
            ch = next(it)
            node.symbol, node.component, node.params, node.rule = (
                ch.symbol,
                ch.component,
                ch.param_dict,
                rule.name,
            )
        node.open = head.open
        parent = node
        next_id = len(p.states)
        for pat in rule.rhs[1:]:
            ch = next(it)
            child = DesignNode(
                next_id, pat.symbol, ch.component, ch.param_dict, pat.open, rule.name, parent
            )
            parent.children.append(child)
            nodes[next_id] = child
            parent = child
            next_id += 1
        p = p.apply(rule, step.choices)
    while p.stack and p.can_stop():
        p = p.stop()
    if not p.complete:
        raise GrammarError(
            [
                Problem(
                    source,
                    f"design is incomplete: node {p.current} ({p.states[p.current]}) is still open",
                )
            ]
        )
    return nodes[0]


def _check_choice(grammar: Grammar, symbol: str, ch: Choice, fail) -> None:
    comps = grammar.library.for_symbol(symbol)
    if ch.symbol != symbol:
        raise fail(f"choice {ch} is for symbol {ch.symbol!r}, expected {symbol!r}", "choices")
    if not comps:
        if ch.component is not None:
            raise fail(f"symbol {symbol!r} has no components, got {ch.component!r}", "choices")
        return
    comp: Component | None = grammar.library.components.get(ch.component or "")
    if comp is None or comp.symbol != symbol:
        raise fail(
            f"unknown component {ch.component!r} for symbol {symbol!r} (library: {[c.name for c in comps]})",
            "choices",
        )
    given = ch.param_dict
    for name, dom in comp.params.items():
        if name not in given:
            raise fail(f"component '{comp.name}' needs parameter '{name}'", "choices")
        if not dom.contains(given[name]):
            raise fail(
                f"parameter '{name}'={given[name]} of '{comp.name}' is out of the domain [{dom.low}, {dom.high}]",
                "choices",
            )
    for name in given:
        if name not in comp.params:
            raise fail(f"component '{comp.name}' has no parameter '{name}'", "choices")
