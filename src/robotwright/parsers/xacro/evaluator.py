"""The evaluator of xacro expressions: it walks Python's syntax tree of an expression and
allows only the nodes listed here (literals, names, arithmetic, comparisons,
comprehensions, calls of allowed functions), counting its steps; nothing is ever passed
to ``eval``."""

from __future__ import annotations

import ast
import math
import operator
import re
from collections.abc import Callable, Iterable, Mapping
from typing import Any

from robotwright._names import shown
from robotwright.parsers.xacro.names import (
    _CONTAINERS,
    _SCALARS,
    MAX_INT_BITS,
    MAX_ITEMS,
    MAX_STEPS,
    MAX_STR,
    MAX_WIDTH,
    METHODS,
    ExpressionError,
    Namespace,
    SafeFunction,
    _checked,
    _is_int,
    _length,
    _Method,
)

_BINOPS: dict[type, Callable[[Any, Any], Any]] = {
    ast.Add: operator.add,
    ast.Sub: operator.sub,
    ast.Mult: operator.mul,
    ast.Div: operator.truediv,
    ast.FloorDiv: operator.floordiv,
    ast.Mod: operator.mod,
    ast.Pow: operator.pow,
    ast.LShift: operator.lshift,
    ast.RShift: operator.rshift,
    ast.BitOr: operator.or_,
    ast.BitXor: operator.xor,
    ast.BitAnd: operator.and_,
}

_UNARY: dict[type, Callable[[Any], Any]] = {
    ast.USub: operator.neg,
    ast.UAdd: operator.pos,
    ast.Not: operator.not_,
    ast.Invert: operator.invert,
}

_COMPARE: dict[type, Callable[[Any, Any], Any]] = {
    ast.Eq: operator.eq,
    ast.NotEq: operator.ne,
    ast.Lt: operator.lt,
    ast.LtE: operator.le,
    ast.Gt: operator.gt,
    ast.GtE: operator.ge,
    ast.Is: operator.is_,
    ast.IsNot: operator.is_not,
    ast.In: lambda a, b: a in b,
    ast.NotIn: lambda a, b: a not in b,
}

#: ``%`` conversions: an optional key, flags, width and precision (digits; ``*`` is
#: refused as the width would come from the arguments).
_PERCENT = re.compile(r"%(?:\([^)]*\))?[#0\- +]*(\*|\d*)(?:\.(\*|\d*))?[hlL]?(.)", re.S)

#: Errors of a value-level operation (a division by zero, a missing key, a wrong type)
#: that are the file's fault and are reported as such.
_VALUE_ERRORS = (
    ArithmeticError,
    ValueError,
    TypeError,
    KeyError,
    IndexError,
    AttributeError,
    RecursionError,
    MemoryError,
)

_VIEWS = (type({}.keys()), type({}.values()), type({}.items()))

_ITERABLE = (str, list, tuple, dict, set, frozenset, *_VIEWS)


class Evaluator:
    """Evaluates expressions over ``lookup`` (the file's names: raises ``KeyError``
    for a name it does not hold) and ``names`` (the allowed functions and constants).

    ``dotted`` are list and dict subclasses treated as lists and dicts, the dicts' keys
    also read as attributes (xacro's ``YamlListWrapper``, ``YamlDictWrapper``);
    ``scopes`` the types of a file's namespaces (``ns.NAME``), read through
    ``scope_lookup(scope, name)`` (``KeyError`` when absent).
    """

    def __init__(
        self,
        lookup: Callable[[str], Any],
        names: Mapping[str, Any],
        *,
        dotted: tuple[type, ...] = (),
        scopes: tuple[type, ...] = (),
        scope_lookup: Callable[[Any, str], Any] | None = None,
    ) -> None:
        self.lookup = lookup
        self.names = names
        self.dotted = dotted
        self.scopes = scopes
        self.scope_lookup = scope_lookup
        self.steps = 0
        self.expr = ""

    # -- entry

    def evaluate(self, expr: str) -> Any:
        """The value of ``expr``; :class:`ExpressionError` when refused or failing."""
        self.expr = expr.strip()
        self.steps = 0
        try:
            tree = ast.parse(self.expr, mode="eval")
        except SyntaxError as exc:
            raise ExpressionError(f"'{self._short()}': not an expression ({exc.msg})") from None
        except (RecursionError, MemoryError, ValueError):
            raise ExpressionError(f"'{self._short()}': too deeply nested") from None
        try:
            return self._eval(tree.body, {})
        except ExpressionError as exc:
            raise ExpressionError(f"'{self._short()}': {exc}") from None
        except _VALUE_ERRORS as exc:
            if isinstance(exc, RecursionError):
                message = "too deeply nested"
            elif isinstance(exc, MemoryError):
                message = "out of memory"
            else:
                message = f"{type(exc).__name__}: {exc}"
            raise ExpressionError(f"'{self._short()}': {message}") from None

    def _short(self) -> str:
        return self.expr if len(self.expr) <= 200 else self.expr[:200] + "..."

    # -- nodes

    def _eval(self, node: ast.AST, local: dict[str, Any]) -> Any:
        self.steps += 1
        if self.steps > MAX_STEPS:
            raise ExpressionError(f"over {MAX_STEPS} evaluation steps; refused")
        method = getattr(self, "_" + type(node).__name__, None)
        if method is None:
            raise ExpressionError(f"{_describe(node)} is not allowed in xacro expressions")
        return method(node, local)

    def _Constant(self, node: ast.Constant, local: dict[str, Any]) -> Any:
        if type(node.value) not in _SCALARS:
            raise ExpressionError(f"the literal {shown(node.value)} is not allowed")
        return _checked(node.value, "a literal")

    def _Name(self, node: ast.Name, local: dict[str, Any]) -> Any:
        name = node.id
        if name.startswith("_"):
            raise ExpressionError(f"the name '{name}' is refused (names may not start with _)")
        if name in local:
            return local[name]
        try:
            return self._value(self.lookup(name), name)
        except KeyError:
            pass
        if name in self.names:
            return self.names[name]
        raise ExpressionError(f"name '{name}' is not defined")

    def _value(self, value: Any, name: str) -> Any:
        """A value from the file's names, if it is of a type expressions may hold."""
        if self._holdable(value):
            return value
        raise ExpressionError(f"'{name}' holds a {type(value).__name__}, not a value")

    def _holdable(self, value: Any) -> bool:
        return (
            type(value) in _SCALARS
            or type(value) in _CONTAINERS
            or isinstance(value, (*self.dotted, *self.scopes, SafeFunction, _Method, Namespace))
            or type(value) in _VIEWS
            or _is_plain_data(value)
        )

    def _BinOp(self, node: ast.BinOp, local: dict[str, Any]) -> Any:
        op = _BINOPS.get(type(node.op))
        if op is None:
            raise ExpressionError(f"the operator {type(node.op).__name__} is not allowed")
        left = self._eval(node.left, local)
        right = self._eval(node.right, local)
        _precheck(type(node.op), left, right)
        return _checked(op(left, right), "the result")

    def _UnaryOp(self, node: ast.UnaryOp, local: dict[str, Any]) -> Any:
        return _UNARY[type(node.op)](self._eval(node.operand, local))

    def _BoolOp(self, node: ast.BoolOp, local: dict[str, Any]) -> Any:
        is_and = isinstance(node.op, ast.And)
        value: Any = None
        for item in node.values:
            value = self._eval(item, local)
            if bool(value) != is_and:
                return value
        return value

    def _Compare(self, node: ast.Compare, local: dict[str, Any]) -> Any:
        left = self._eval(node.left, local)
        for op, right_node in zip(node.ops, node.comparators):
            right = self._eval(right_node, local)
            if not _COMPARE[type(op)](left, right):
                return False
            left = right
        return True

    def _IfExp(self, node: ast.IfExp, local: dict[str, Any]) -> Any:
        if self._eval(node.test, local):
            return self._eval(node.body, local)
        return self._eval(node.orelse, local)

    def _items(self, nodes: Iterable[ast.expr], local: dict[str, Any]) -> list[Any]:
        items: list[Any] = []
        for item in nodes:
            if isinstance(item, ast.Starred):
                items.extend(self._iterate(self._eval(item.value, local)))
            else:
                items.append(self._eval(item, local))
            if len(items) > MAX_ITEMS:
                raise ExpressionError(f"over {MAX_ITEMS} items; refused")
        return items

    def _List(self, node: ast.List, local: dict[str, Any]) -> Any:
        return _checked(self._items(node.elts, local), "a list")

    def _Tuple(self, node: ast.Tuple, local: dict[str, Any]) -> Any:
        return _checked(tuple(self._items(node.elts, local)), "a tuple")

    def _Set(self, node: ast.Set, local: dict[str, Any]) -> Any:
        return _checked(set(self._items(node.elts, local)), "a set")

    def _Dict(self, node: ast.Dict, local: dict[str, Any]) -> Any:
        result: dict[Any, Any] = {}
        for key, value in zip(node.keys, node.values):
            if key is None:  # {**other}
                other = self._eval(value, local)
                if not (type(other) is dict or isinstance(other, self.dotted)):
                    raise ExpressionError("** needs a dict")
                result.update(other)
            else:
                result[self._eval(key, local)] = self._eval(value, local)
        return _checked(result, "a dict")

    def _iterate(self, value: Any) -> Iterable[Any]:
        """The items of a value expressions may iterate (never a generator of Python)."""
        if type(value) in _ITERABLE or isinstance(value, self.dotted):
            return value
        raise ExpressionError(f"a {type(value).__name__} cannot be iterated")

    def _Subscript(self, node: ast.Subscript, local: dict[str, Any]) -> Any:
        value = self._eval(node.value, local)
        index = self._eval(node.slice, local)
        if isinstance(value, self.scopes) and self.scope_lookup is not None:
            if not isinstance(index, str) or index.startswith("_"):
                raise ExpressionError(f"a namespace key must be a name, not {shown(index)}")
            return self._value(self.scope_lookup(value, index), index)
        if not (type(value) in (str, list, tuple, dict) or isinstance(value, self.dotted)):
            raise ExpressionError(f"a {type(value).__name__} cannot be subscripted")
        if not isinstance(index, (int, str, float, tuple, slice, type(None))):
            raise ExpressionError(f"a {type(index).__name__} is not an index")
        return self._value(value[index], "the item")

    def _Slice(self, node: ast.Slice, local: dict[str, Any]) -> Any:
        parts = [
            None if p is None else self._eval(p, local) for p in (node.lower, node.upper, node.step)
        ]
        for part in parts:
            if part is not None and not _is_int(part):
                raise ExpressionError("slice bounds must be integers")
        return slice(*parts)

    def _Attribute(self, node: ast.Attribute, local: dict[str, Any]) -> Any:
        name = node.attr
        if name.startswith("_"):
            raise ExpressionError(
                f"the attribute '{name}' is refused (attributes may not start with _)"
            )
        value = self._eval(node.value, local)
        if isinstance(value, Namespace):
            if name in value.members:
                return value.members[name]
            raise ExpressionError(f"'{value.name}.{name}' is not available")
        if isinstance(value, self.scopes) and self.scope_lookup is not None:
            try:
                return self._value(self.scope_lookup(value, name), name)
            except KeyError:
                pass
            if name in self.names:
                return self.names[name]
            raise ExpressionError(f"name '{name}' is not defined in the namespace")
        for kind, allowed in METHODS.items():
            same = type(value) is kind or isinstance(value, self.dotted)
            if same and isinstance(value, kind) and name in allowed:
                return _Method(value, name)
        if isinstance(value, self.dotted) and isinstance(value, dict):
            # Python looks up the dict's own attributes first, then the key.
            if hasattr(dict, name):
                raise ExpressionError(f"the dict method '{name}' is not allowed")
            return self._value(getattr(value, name), name)
        raise ExpressionError(f"the attribute '{name}' of a {type(value).__name__} is not allowed")

    def _Call(self, node: ast.Call, local: dict[str, Any]) -> Any:
        fn = self._eval(node.func, local)
        if not isinstance(fn, (SafeFunction, _Method)):
            raise ExpressionError(f"a {type(fn).__name__} cannot be called")
        args = self._items(node.args, local)
        kwargs: dict[str, Any] = {}
        for keyword in node.keywords:
            if keyword.arg is None:
                extra = self._eval(keyword.value, local)
                if not isinstance(extra, dict) or not all(isinstance(k, str) for k in extra):
                    raise ExpressionError("** in a call needs a dict of names")
                kwargs.update(extra)
            else:
                kwargs[keyword.arg] = self._eval(keyword.value, local)
        if any(k.startswith("_") for k in kwargs):
            raise ExpressionError("keyword arguments may not start with _")
        return self._value(fn(*args, **kwargs), "the result")

    # -- comprehensions

    def _comprehend(
        self, generators: list[ast.comprehension], local: dict[str, Any], emit: Callable
    ) -> None:
        def loop(index: int, scope: dict[str, Any]) -> None:
            if index == len(generators):
                emit(scope)
                return
            gen = generators[index]
            if gen.is_async:
                raise ExpressionError("async comprehensions are not allowed")
            for item in self._iterate(self._eval(gen.iter, scope)):
                self.steps += 1
                if self.steps > MAX_STEPS:
                    raise ExpressionError(f"over {MAX_STEPS} evaluation steps; refused")
                inner = dict(scope)
                self._bind(gen.target, item, inner)
                if all(self._eval(cond, inner) for cond in gen.ifs):
                    loop(index + 1, inner)

        loop(0, dict(local))

    def _bind(self, target: ast.AST, value: Any, scope: dict[str, Any]) -> None:
        if isinstance(target, ast.Name):
            if target.id.startswith("_"):
                raise ExpressionError(f"the name '{target.id}' is refused")
            scope[target.id] = value
        elif isinstance(target, (ast.Tuple, ast.List)):
            items = list(self._iterate(value))
            if len(items) != len(target.elts):
                raise ExpressionError("cannot unpack: wrong number of values")
            for sub, item in zip(target.elts, items):
                self._bind(sub, item, scope)
        else:
            raise ExpressionError(f"{_describe(target)} is not a loop name")

    def _collect(self, node: Any, local: dict[str, Any]) -> list[Any]:
        out: list[Any] = []

        def emit(scope: dict[str, Any]) -> None:
            out.append(self._eval(node.elt, scope))
            if len(out) > MAX_ITEMS:
                raise ExpressionError(f"over {MAX_ITEMS} items; refused")

        self._comprehend(node.generators, local, emit)
        return out

    def _ListComp(self, node: ast.ListComp, local: dict[str, Any]) -> Any:
        return _checked(self._collect(node, local), "a list")

    def _GeneratorExp(self, node: ast.GeneratorExp, local: dict[str, Any]) -> Any:
        return _checked(self._collect(node, local), "a list")

    def _SetComp(self, node: ast.SetComp, local: dict[str, Any]) -> Any:
        return _checked(set(self._collect(node, local)), "a set")

    def _DictComp(self, node: ast.DictComp, local: dict[str, Any]) -> Any:
        out: dict[Any, Any] = {}

        def emit(scope: dict[str, Any]) -> None:
            out[self._eval(node.key, scope)] = self._eval(node.value, scope)
            if len(out) > MAX_ITEMS:
                raise ExpressionError(f"over {MAX_ITEMS} items; refused")

        self._comprehend(node.generators, local, emit)
        return _checked(out, "a dict")


def _is_plain_data(value: Any) -> bool:
    """Scalars YAML gives besides numbers and strings (dates, times)."""
    import datetime

    return type(value) in (datetime.date, datetime.datetime, datetime.time)


def _describe(node: ast.AST) -> str:
    names = {
        "Lambda": "a lambda",
        "JoinedStr": "an f-string",
        "FormattedValue": "an f-string",
        "NamedExpr": "an assignment (:=)",
        "Await": "await",
        "Yield": "yield",
        "YieldFrom": "yield",
        "Starred": "a * outside a call or literal",
    }
    return names.get(type(node).__name__, f"the construct {type(node).__name__}")


def _precheck(op: type, left: Any, right: Any) -> None:
    """Refuse before computing what would be over the caps (the computation itself
    would take the memory or time)."""
    if op is ast.Pow and _is_int(left) and _is_int(right) and right > 0:
        if abs(left) > 1 and right * math.log2(abs(left)) > MAX_INT_BITS:
            raise ExpressionError(f"a power over {MAX_INT_BITS} bits is refused")
    elif op is ast.Mult:
        for seq, n in ((left, right), (right, left)):
            length = _length(seq)
            if length is not None and _is_int(n) and length * n > MAX_STR:
                raise ExpressionError(f"a repetition over {MAX_STR} items is refused")
        bits = left.bit_length() + right.bit_length() if _is_int(left) and _is_int(right) else 0
        if bits > MAX_INT_BITS + 1:
            raise ExpressionError(f"an integer over {MAX_INT_BITS} bits is refused")
    elif op is ast.LShift and _is_int(left) and _is_int(right):
        if right > MAX_INT_BITS or left.bit_length() + right > MAX_INT_BITS:
            raise ExpressionError(f"an integer over {MAX_INT_BITS} bits is refused")
    elif op is ast.Add:
        a, b = _length(left), _length(right)
        if a is not None and b is not None and a + b > MAX_STR:
            raise ExpressionError(f"a value over {MAX_STR} items is refused")
    elif op is ast.Mod and isinstance(left, str):
        for match in _PERCENT.finditer(left):
            width, precision = match.group(1), match.group(2)
            if "*" in (width, precision):
                raise ExpressionError("'%*' (a width from the arguments) is refused")
            for number in (width, precision):
                if number and int(number) > MAX_WIDTH:
                    raise ExpressionError(f"a % width over {MAX_WIDTH} is refused")
