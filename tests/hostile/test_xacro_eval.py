"""Hostile xacro expressions: no ``${...}`` or ``$(eval ...)`` runs Python.

Every payload tries to run ``touch MARKER`` (or to read a file or the environment, or to
exhaust memory); each must end in a :class:`ConversionError` that names the file and
says the expression was refused, and the marker must not exist afterwards. The
families are the known ways out of Python-``eval`` sandboxes: forbidden builtins
reached by any name or namespace, dunder attribute walks from every kind of value the
evaluator hands out, dunder strings through ``vars``/``getattr``-like functions,
format-string attribute access, generator and frame attributes, lambdas and
comprehension closures, memory and CPU bombs; plus a seeded random mix of them.

The bulk runs the expansion in this process (``_expand_here``, the function the
expansion worker runs); a sample goes through the CLI (exit 2, one ``error:`` line).
"""

from __future__ import annotations

import random
from pathlib import Path
from xml.sax.saxutils import escape

import pytest

pytest.importorskip("xacro", reason="the xacro extra (pip install 'robotwright[xacro]') is absent")

from robotwright.cli import main  # noqa: E402
from robotwright.errors import ConversionError  # noqa: E402
from robotwright.parsers.xacro.expand import _expand_here  # noqa: E402

MARK = "PWNED_MARKER"
RUN = f"__import__('os').system('touch {MARK}')"

TEMPLATE = """<robot name="evil" xmlns:xacro="http://www.ros.org/wiki/xacro">
  <xacro:include filename="inc.xacro" ns="ns"/>
  <xacro:property name="d" value="${{xacro.load_yaml('d.yaml')}}"/>
  <xacro:property name="s" value="text"/>
  <xacro:property name="fmt" value="{{0.__class__.__mro__}}"/>
  <xacro:property name="run" value="{run}"/>
  <xacro:property name="getenv" value="env('ROBOTWRIGHT_TEST_SECRET')"/>
  <link name="base"/>
  <link name="x">{body}</link>
</robot>
"""


@pytest.fixture
def robot(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    folder = tmp_path / "robot"
    folder.mkdir()
    (folder / "inc.xacro").write_text(
        '<robot xmlns:xacro="http://www.ros.org/wiki/xacro">'
        '<xacro:property name="p" value="1"/></robot>'
    )
    (folder / "d.yaml").write_text("a: 1\nb: [1, 2]\n")
    (tmp_path / "secret.yaml").write_text("token: abc\n")
    monkeypatch.chdir(folder)  # a payload's relative 'touch' would land here
    monkeypatch.setenv("ROBOTWRIGHT_TEST_SECRET", "s3cret")
    return folder


def _write(folder: Path, body: str) -> Path:
    marker = folder / MARK
    path = folder / "evil.urdf.xacro"
    run = escape(RUN.replace(MARK, str(marker)), {'"': "&quot;"})
    path.write_text(TEMPLATE.format(body=escape(body.replace(MARK, str(marker))), run=run))
    return path


def _refused(folder: Path, body: str, match: str = "xacro expression refused") -> None:
    src = _write(folder, body)
    with pytest.raises(ConversionError) as info:
        _expand_here(src, xacro_args={}, package_map=None, trusted=())
    text = str(info.value)
    assert str(src) in text, text
    assert match in text, text
    assert not (folder / MARK).exists()


def test_the_template_expands_when_the_expression_is_benign(robot: Path) -> None:
    # The control: the hostile cases below fail because of their expression alone.
    src = _write(robot, "${d.a + ns.p + len(s)}|${d['b'][1] * 2}|$(eval 1 + 2)")
    text, _, _ = _expand_here(src, xacro_args={}, package_map=None, trusted=())
    assert ">6|4|3<" in text


# ---------------------------------------------------------------- forbidden builtins

FORBIDDEN = [
    "eval",
    "exec",
    "compile",
    "open",
    "__import__",
    "globals",
    "locals",
    "breakpoint",
    "input",
    "getattr",
    "setattr",
    "delattr",
    "vars",
    "type",
    "dir",
    "help",
    "memoryview",
    "object",
    "super",
    "print",
    "exit",
    "quit",
    "id",
    "hash",
    "isinstance",
    "issubclass",
    "classmethod",
    "staticmethod",
    "property",
    "format",
    "bytes",
    "bytearray",
    "iter",
    "next",
    "filter",
    "complex",
    "slice",
    "set",
    "frozenset",
    "repr",
    "ascii",
    "chr",
    "callable",
    "os",
    "sys",
    "builtins",
    "__builtins__",
    "__loader__",
    "__spec__",
]
REACHERS = ("{n}", "python.{n}", "xacro.{n}", "math.{n}", "ns.{n}", "ns.python.{n}")


@pytest.mark.parametrize("reach", REACHERS)
@pytest.mark.parametrize("name", FORBIDDEN)
def test_forbidden_builtins_by_any_name(robot: Path, name: str, reach: str) -> None:
    _refused(robot, "${" + reach.format(n=name) + f'("{RUN}")' + "}")


# ---------------------------------------------------------------- attribute walks

BASES = (
    "''",
    "s",
    "()",
    "[]",
    "[1]",
    "{}",
    "d",
    "d.b",
    "1",
    "1.5",
    "True",
    "pi",
    "sin",
    "len",
    "python.len",
    "python",
    "xacro",
    "math",
    "ns",
    "xacro.load_yaml",
    "''.join",
    "d.keys",
    "d.keys()",
    "[x for x in [1]]",
    "(x for x in [1])",
    "range(2)",
    "map(len, [s])",
)
ATTRS = (
    "__class__",
    "__class__.__mro__[1].__subclasses__()",
    "__class__.__base__.__subclasses__()",
    "__globals__",
    "__builtins__",
    "__dict__",
    "__init__.__globals__",
    "__reduce__()",
    "__reduce_ex__(2)",
    "__getattribute__('__class__')",
    "__self__",
    "__func__",
    "__closure__",
    "__code__",
    "_fn",
    "_obj",
    "_guard",
    "gi_frame",
    "gi_frame.f_globals",
    "gi_code",
    "f_back",
    "f_globals",
    "cr_frame",
    "mro()",
    "func_globals",
    "format",
    "format_map",
    "mapping",
)


@pytest.mark.parametrize("attr", ATTRS)
@pytest.mark.parametrize("base", BASES)
def test_attribute_walks_from_every_value(robot: Path, base: str, attr: str) -> None:
    _refused(robot, "${(" + base + ")." + attr + "}")


# ---------------------------------------------------------------- dunder strings, format

OTHER = (
    "python.vars(python.type)['__subclasses__']",
    "python.vars(python.type)['__subclasses__'](python.object)",
    "d['__class__']",
    "ns['__builtins__']",
    "ns['python']",
    "xacro.dotify(dict(a=1)).__class__",
    "xacro.dotify(1)",
    "xacro.dotify(dict(__init__=1))['__init__']",
    "dict(__class__=1)",
    "sorted([1], key=python.type)",
    "map(python.vars, [1])",
    "max([1], key=lambda x: x)",
    "fmt.format(1)",
    "fmt.format_map(d)",
    "str.format(fmt, 1)",
    "s.format",
    "f'text'",
    "F'x'",
    "rf'x'",
    "(lambda: 0)()",
    "[f() for f in [lambda: 1]]",
    "(y := 1)",
    "[y for x in [1] if (y := 2)]",
    "[__import__ for x in [1]]",
    "[_ for _ in [1]]",
    "[x.__class__ for x in [1]]",
    "[x for x in (1).__class__.__mro__]",
    "{x: x.gi_frame for x in [1]}",
    "list((x for x in [1]).gi_frame.f_back)",
    "b'bytes'",
    "1j",
    "...",
    "python.sum.__call__",
    "python.enumerate([1]).__iter__",
    "len(*[python.type])",
    "min(**dict(key=python.vars))",
)


@pytest.mark.parametrize("expr", OTHER)
def test_dunder_strings_format_strings_closures(robot: Path, expr: str) -> None:
    _refused(robot, "${" + expr + "}")


# ---------------------------------------------------------------- $(eval ...)

EVAL_PAYLOADS = (
    "${run}",
    "__import__('os')",
    "open('/etc/passwd')",
    "eval('1')",
    "().__class__",
    "globals()",
    "python.type",
    "arg.__globals__",
    "dirname.__code__",
    "find.__self__",
    "'{0.__class__}'.format(1)",
    "[c for c in ().__class__.__bases__]",
)


@pytest.mark.parametrize("payload", EVAL_PAYLOADS)
def test_eval_substitution_runs_nothing(robot: Path, payload: str) -> None:
    _refused(robot, "$(eval " + payload + ")")


def test_eval_substitution_does_not_read_the_environment(robot: Path) -> None:
    _refused(robot, "$(eval ${getenv})", match="reading the environment")


@pytest.mark.parametrize(
    ("body", "match"),
    [
        ("${xacro.load_yaml('/etc/passwd')}", "outside the robot folder"),
        ("${xacro.load_yaml('../secret.yaml')}", "outside the robot folder"),
        ("${load_yaml('../secret.yaml')}", "outside the robot folder"),
        ("${python.open('/etc/passwd')}", "xacro expression refused"),
        ("${os.environ}", "xacro expression refused"),
        ("$(env ROBOTWRIGHT_TEST_SECRET)", "reading the environment"),
    ],
)
def test_no_file_or_environment_read(robot: Path, body: str, match: str) -> None:
    _refused(robot, body, match=match)


# ---------------------------------------------------------------- bombs

BOMBS = (
    "9**9**9",
    "10**10**10",
    "2**100000",
    "(-3)**99999",
    "'a'*10**10",
    "10**10*'a'",
    "[0]*10**10",
    "(1,)*10**9",
    "[[0]*10**6]*10**6",
    "str([[0]*1000]*2000)",
    "1<<10**9",
    "10**4000*10**4000",
    "range(10**10)",
    "list(range(10**10))",
    "math.factorial(10**6)",
    "factorial(10**5)",
    "math.comb(10**6, 5*10**5)",
    "math.ldexp(1.0, 10**6)",
    "int('9'*5000)",
    "'%0999999999d' % 1",
    "'%.999999999f' % 1.0",
    "'%*d' % (10**9, 1)",
    "'x'.zfill(10**9)",
    "'x'.center(10**9)",
    "'x'.ljust(10**9)",
    "('a'*10**5).replace('a', 'a'*100)",
    "'-'.join(['a'*10**5]*100)",
    "[x for x in range(10**6) for y in range(10**6)]",
    "(" * 300 + "1" + ")" * 300,
    "-" * 100000 + "1",
    "1+" * 100000 + "1",
    "1/0",
)


@pytest.mark.parametrize("expr", BOMBS, ids=[b[:40] for b in BOMBS])
def test_memory_and_cpu_bombs_are_refused(robot: Path, expr: str) -> None:
    _refused(robot, "${" + expr + "}")


def test_doubling_through_properties_is_refused(robot: Path) -> None:
    chain = '<xacro:property name="p0" value="${\'a\' * 1000}"/>' + "".join(
        f'<xacro:property name="p{k}" value="${{p{k - 1} + p{k - 1}}}"/>' for k in range(1, 14)
    )
    src = _write(robot, "${p13}")
    src.write_text(src.read_text().replace('<link name="base"/>', chain + '<link name="base"/>'))
    with pytest.raises(ConversionError, match="xacro expression refused"):
        _expand_here(src, xacro_args={}, package_map=None, trusted=())


# ---------------------------------------------------------------- random mixes


def _random_payloads(count: int, seed: int) -> list[str]:
    rng = random.Random(seed)
    out = []
    for _ in range(count):
        base = rng.choice(BASES)
        attr = rng.choice(ATTRS)
        name = rng.choice(FORBIDDEN)
        reach = rng.choice(REACHERS).format(n=name)
        shape = rng.randrange(5)
        if shape == 0:
            out.append(f"[({base}).{attr} for x in [1]]")
        elif shape == 1:
            out.append(f"{reach}(({base}).{attr})")
        elif shape == 2:
            out.append(f"(1 if {base} else 2) + ({base}).{attr}")
        elif shape == 3:
            out.append(f"[{reach} for y in [1]][0]('{name}')")
        else:
            out.append(f"d.get('a', ({base}).{attr})")
    return out


@pytest.mark.parametrize("expr", _random_payloads(120, seed=19))
def test_random_mixes_are_refused(robot: Path, expr: str) -> None:
    _refused(robot, "${" + expr + "}")


# ---------------------------------------------------------------- the CLI

CLI_SAMPLE = (
    "${python.vars(python.type)['__subclasses__']}",
    "${''.__class__.__mro__[1].__subclasses__()}",
    "${[x.gi_frame for x in [1]]}",
    "${9**9**9}",
    "$(eval ${run})",
    "${fmt.format(1)}",
)


@pytest.mark.parametrize("body", CLI_SAMPLE)
def test_cli_refuses_with_one_error_line_and_exit_2(
    robot: Path, tmp_path: Path, body: str, capsys: pytest.CaptureFixture[str]
) -> None:
    src = _write(robot, body)
    out = tmp_path / "out.xml"
    assert main(["convert", str(src), "-o", str(out)]) == 2
    err = capsys.readouterr().err
    assert "Traceback" not in err
    assert [line for line in err.splitlines() if line.startswith("error:")], err
    assert "xacro expression refused" in err
    assert not out.exists()
    assert not (robot / MARK).exists()
