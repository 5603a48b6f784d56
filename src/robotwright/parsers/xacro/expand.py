"""xacro sources: ``.xacro`` / ``.urdf.xacro`` files expanded to URDF without ROS.

The macros are expanded by the ``xacro`` package from PyPI (install the ``xacro`` extra:
``pip install robotwright[xacro]``); its ROS hooks are replaced by ours:

- ``$(find pkg)`` is the package folder that ``package://pkg/...`` names, found by
  :func:`robotwright.parsers.packages.find_package` (the ``package_map`` argument first,
  then ``ROS_PACKAGE_PATH``, ``AMENT_PREFIX_PATH`` and the file's ancestors);
- ``$(arg name)`` takes the ``xacro_args`` mapping (``--xacro-arg name:=value``), then
  the file's own ``<xacro:arg default=...>``;
- ``$(env VAR)`` is refused and ``$(optenv VAR default)`` gives its default: the
  environment is not read, so a file cannot copy it into its output;
- ``${...}`` and ``$(eval ...)`` expressions are evaluated by
  :mod:`robotwright.parsers.xacro.expressions` (an allow-list over the syntax tree), never by
  Python's ``eval``.

The files xacro reads (the source, ``<xacro:include>``, ``xacro.load_yaml``) must lie
inside the robot folder (:func:`~robotwright.parsers.packages.robot_root`), inside a
package folder that ``$(find)`` resolved, or inside a folder trusted with
``asset_roots``; each is checked with ``defusedxml`` (no entities, no DTD) before xacro
parses it, and read with the usual size cap. A mesh path that ``$(find pkg)`` made
absolute is written back as ``package://pkg/...``, so the URDF parser resolves it
through the same package map and the same containment rules as any ``package://`` URI.
"""

from __future__ import annotations

import contextlib
import io
import os
import tempfile
import threading
import xml.etree.ElementTree as ET
from collections.abc import Iterator, Mapping
from pathlib import Path
from typing import Any

import defusedxml
import defusedxml.ElementTree as DET

from robotwright._atomic import write_text_atomic
from robotwright._inputs import MAX_XML_BYTES, MAX_YAML_BYTES, decode, read_bytes
from robotwright._names import shown
from robotwright._paths import resolve_inside, trusted_roots
from robotwright._temporaries import prefix
from robotwright._xmlsafe import parse_xml
from robotwright.errors import ConversionError, InputFileError, Problem, UnsafePathError
from robotwright.parsers.packages import (
    find_package,
    given_package_map,
    package_not_found,
    robot_root,
)
from robotwright.parsers.report import Reporter
from robotwright.parsers.xacro.expressions import ExpressionError, installed

#: xacro keeps its state in module globals: one expansion at a time.
_LOCK = threading.Lock()


def is_xacro(path: str | os.PathLike[str]) -> bool:
    """Whether ``path`` names a xacro source (``.xacro``, ``.urdf.xacro``)."""
    return Path(path).name.lower().endswith(".xacro")


def read_robot_xml(path: Path, options: Any, rep: Reporter) -> ET.Element:
    """Root element of a URDF file, or of the URDF a xacro file expands to.

    ``options`` is the :class:`~robotwright.parsers.urdf.reader.URDFOptions` (its
    ``package_map``, ``xacro_args`` and ``asset_roots`` are used); xacro's own warnings
    are reported on ``rep``.
    """
    if not is_xacro(path):
        return parse_xml(path)
    text, packages, messages = expand_xacro(
        path,
        xacro_args=getattr(options, "xacro_args", None),
        package_map=getattr(options, "package_map", None),
        asset_roots=getattr(options, "asset_roots", ()),
    )
    for message in messages:
        rep.warn(f"xacro: {message}")
    try:
        root = DET.fromstring(text)
    except (ET.ParseError, defusedxml.DefusedXmlException) as exc:
        raise ConversionError(
            [Problem(str(path), f"xacro output is not readable as safe XML: {exc}")]
        ) from None
    _package_uris(root, packages)
    return root


#: Limits of one expansion (xacro macros and ``${}`` expressions can blow up: a macro
#: calling the previous one twice, 40 deep, or ``${'x' * 10**10}``): wall time (s), CPU
#: time (s) and address space (bytes) of the worker process.
XACRO_TIMEOUT_S = 120
XACRO_CPU_S = 4
XACRO_MEMORY_BYTES = 4 << 30


def expand_xacro(
    path: str | os.PathLike[str],
    *,
    xacro_args: Mapping[str, str] | None = None,
    package_map: Mapping[str, str | os.PathLike[str]] | None = None,
    asset_roots: tuple[str | os.PathLike[str], ...] | list = (),
) -> tuple[str, dict[str, Path], list[str]]:
    """Expand the xacro file at ``path`` in a separate process with time and memory
    limits (:data:`XACRO_TIMEOUT_S`, :data:`XACRO_CPU_S`, :data:`XACRO_MEMORY_BYTES`).

    Returns:
        The URDF text, the package folders ``$(find)`` resolved (name -> folder), and
        xacro's warnings.

    Raises:
        ConversionError: the ``xacro`` package is not installed, a file it would read
            lies outside the allowed folders or is unsafe XML, an unknown package or
            ``$(arg)``, ``$(env)``, any error xacro reports (message names the file), or
            the expansion ran past its limits.
    """
    import json
    import subprocess

    src = Path(path)
    request = {
        "path": str(src),
        "xacro_args": {str(k): str(v) for k, v in (xacro_args or {}).items()},
        # The packages named with --package travel with the request (another process).
        "package_map": given_package_map(package_map),
        "trusted": [str(p) for p in trusted_roots(asset_roots)],
        "limits": [XACRO_CPU_S, XACRO_MEMORY_BYTES],
    }
    env = {**os.environ, "OPENBLAS_NUM_THREADS": "1", "OMP_NUM_THREADS": "1"}
    try:
        done = subprocess.run(
            isolated_python_command("robotwright.parsers.xacro.expand", "_worker"),
            input=json.dumps(request),
            capture_output=True,
            text=True,
            timeout=XACRO_TIMEOUT_S,
            env=env,
        )
    except subprocess.TimeoutExpired:
        raise ConversionError(
            [Problem(str(src), f"xacro expansion ran past {XACRO_TIMEOUT_S} s; refused")]
        ) from None
    try:
        reply = json.loads(done.stdout)
    except ValueError:
        how = f"signal {-done.returncode}" if done.returncode < 0 else f"exit {done.returncode}"
        raise ConversionError(
            [
                Problem(
                    str(src),
                    f"xacro expansion stopped ({how}; limits: {XACRO_CPU_S} s CPU, "
                    f"{XACRO_MEMORY_BYTES >> 30} GiB memory): refused",
                )
            ]
        ) from None
    if not reply["ok"]:
        raise ConversionError([Problem(f, m) for f, m in reply["problems"]])
    packages = {k: Path(v) for k, v in reply["packages"].items()}
    return reply["text"], packages, reply["messages"]


def isolated_python_command(module: str, function: str) -> list[str]:
    """The command that runs ``module.function()`` in a new interpreter started isolated
    (``-I``: neither the working folder nor ``PYTHONPATH`` nor the user's site folder
    on ``sys.path``, no ``PYTHON*`` variables), with robotwright's own installation
    folder first: a robot folder that ships ``xacro.py`` or ``yaml.py`` and is the
    working folder is never imported from."""
    import sys

    home = Path(__file__).resolve().parents[2]  # the folder holding robotwright/
    bootstrap = (
        f"import sys; sys.path.insert(0, {shown(str(home))}); "
        f"from {module} import {function}; {function}()"
    )
    return [sys.executable, "-I", "-c", bootstrap]


def _worker() -> None:
    """``python -m robotwright.parsers.xacro.expand``: one expansion, request on stdin, reply
    (JSON) on stdout, under CPU and memory limits."""
    import json
    import sys

    request = json.loads(sys.stdin.read())
    cpu_s, memory = request["limits"]
    try:
        import resource

        resource.setrlimit(resource.RLIMIT_CPU, (cpu_s, cpu_s))
        resource.setrlimit(resource.RLIMIT_AS, (memory, memory))
    except (ImportError, ValueError, OSError):  # not on this platform: wall time only
        pass
    try:
        text, packages, messages = _expand_here(
            Path(request["path"]),
            xacro_args=request["xacro_args"],
            package_map=request["package_map"] or None,
            trusted=tuple(Path(p) for p in request["trusted"]),
        )
        if len(text) > MAX_XML_BYTES:
            raise ConversionError(
                [Problem(request["path"], f"xacro output is over {MAX_XML_BYTES} bytes")]
            )
        reply = {
            "ok": True,
            "text": text,
            "packages": {k: str(v) for k, v in packages.items()},
            "messages": messages,
        }
    except ConversionError as exc:
        reply = {"ok": False, "problems": [[p.file, p.message] for p in exc.problems]}
    except MemoryError:
        reply = {
            "ok": False,
            "problems": [[request["path"], "xacro expansion ran out of memory; refused"]],
        }
    sys.stdout.write(json.dumps(reply))


def _expand_here(
    src: Path,
    *,
    xacro_args: Mapping[str, str] | None,
    package_map: Mapping[str, str | os.PathLike[str]] | None,
    trusted: tuple[Path, ...],
) -> tuple[str, dict[str, Path], list[str]]:
    """The expansion itself (in the worker process)."""
    try:
        import xacro
        from xacro import substitution_args
    except ImportError:
        raise ConversionError(
            [
                Problem(
                    str(src),
                    "reading .xacro needs the xacro package: pip install 'robotwright[xacro]'",
                )
            ]
        ) from None
    guard = _Guard(src, package_map, trusted)
    args = {str(k): str(v) for k, v in (xacro_args or {}).items()}
    messages = io.StringIO()
    with (
        _LOCK,
        _patched(xacro, substitution_args, guard),
        installed(xacro, substitution_args),
        contextlib.redirect_stderr(messages),
    ):
        try:
            guard.check(src, what="the xacro file")
            doc = xacro.process_file(str(src.resolve()), mappings=args)
            text = doc.toxml()
        except ConversionError:
            raise
        except Exception as exc:  # xacro raises many types; each is a fault of the source
            kinds = (_Refused, ExpressionError, substitution_args.ArgException, MemoryError)
            cause = _cause(exc, kinds)
            if isinstance(cause, _Refused):
                message = str(cause)
            elif isinstance(cause, ExpressionError):
                message = f"xacro expression refused: {cause}"
            elif isinstance(cause, MemoryError):
                message = "xacro expansion ran out of memory; refused"
            elif isinstance(cause, substitution_args.ArgException):
                message = (
                    f"xacro argument {cause} has no value and no default "
                    f"(give it with xacro_args / --xacro-arg {cause}:=VALUE)"
                )
            else:
                message = f"xacro could not expand the file: {exc}"
            where = " > ".join(str(f) for f in (getattr(xacro, "filestack", None) or []) if f)
            detail = f" (in {where})" if where and where != str(src.resolve()) else ""
            raise ConversionError([Problem(str(src), message + detail)]) from None
    lines = [line.strip() for line in messages.getvalue().splitlines() if line.strip()]
    return text, dict(guard.packages), lines


def _cause(exc: BaseException, kinds: tuple[type, ...]) -> BaseException:
    """The first exception of ``kinds`` that xacro wrapped into ``exc`` (through its
    ``XacroException.exc`` or a cause), else ``exc``."""
    seen: set[int] = set()
    current: BaseException | None = exc
    while current is not None and id(current) not in seen:
        if isinstance(current, kinds):
            return current
        seen.add(id(current))
        current = getattr(current, "exc", None) or current.__cause__ or current.__context__
    return exc


class _Refused(Exception):
    """A file or substitution the hostile-input rules refuse (message says why)."""


class _Guard:
    """The folders xacro may read from, and the packages ``$(find)`` resolved."""

    def __init__(
        self,
        src: Path,
        package_map: Mapping[str, str | os.PathLike[str]] | None,
        trusted: tuple[Path, ...],
    ) -> None:
        self.src = src
        self.package_map = package_map
        self.root = robot_root(src)
        self.trusted = trusted
        self.packages: dict[str, Path] = {}

    def find(self, name: str) -> str:
        folder = find_package(name, self.src, self.package_map)
        if folder is None:
            raise _Refused(f"$(find {name}): {package_not_found(name, self.src)}")
        resolved = folder.resolve()
        self.packages[name] = resolved
        return str(resolved)

    def check(self, file: str | os.PathLike[str], what: str = "a file xacro reads") -> Path:
        allowed = (*self.trusted, *self.packages.values())
        try:
            return resolve_inside(
                file, base=Path.cwd(), root=self.root, trusted=allowed, what="the robot folder"
            )
        except UnsafePathError as exc:
            raise _Refused(f"{what}: {exc}") from None

    def open(self, file: Any, mode: str = "r", *args: Any, **kwargs: Any) -> io.StringIO:
        """xacro's ``open``: checked path, size cap, safe XML; read-only."""
        if "r" not in mode or any(c in mode for c in "wax+"):
            raise _Refused(f"xacro tried to open {shown(file)} with mode {shown(mode)}; refused")
        path = self.check(file)
        is_yaml = path.suffix.lower() in (".yaml", ".yml")
        try:
            data = read_bytes(path, MAX_YAML_BYTES if is_yaml else MAX_XML_BYTES)
        except FileNotFoundError:
            raise _Refused(f"{path}: no such file (named by an include or load_yaml)") from None
        except InputFileError as exc:
            raise _Refused(str(exc)) from None
        if not is_yaml:
            try:
                DET.fromstring(data)
            except defusedxml.DefusedXmlException as exc:
                raise _Refused(f"{path}: unsafe XML refused ({type(exc).__name__})") from None
            except ET.ParseError as exc:
                raise _Refused(f"{path}: not well-formed XML: {exc}") from None
        try:
            return io.StringIO(decode(data, path))
        except InputFileError as exc:
            raise _Refused(str(exc)) from None


@contextlib.contextmanager
def _patched(xacro: Any, substitution_args: Any, guard: _Guard) -> Iterator[None]:
    """Our file access and substitutions in place of xacro's for one expansion."""

    def refuse_env(name: str, *_: Any) -> str:
        raise _Refused(f"$(env {name}): reading the environment is refused; use $(arg ...)")

    def optenv_default(_name: str, default: str = "") -> str:
        return default

    saved_extension = xacro.eval_extension

    def eval_extension(text: str) -> Any:
        # $(cwd) writes the working folder (a user's path) into the output, like $(env).
        if text.strip() == "$(cwd)":
            raise _Refused("$(cwd): reading the working folder is refused; use $(arg ...)")
        return saved_extension(text)

    saved_find = substitution_args._eval_find
    saved_env = substitution_args._eval_env
    saved_optenv = substitution_args._eval_optenv
    saved_dict = dict(substitution_args._eval_dict)
    had_open = "open" in vars(xacro)
    saved_open = vars(xacro).get("open")
    substitution_args._eval_find = guard.find
    substitution_args._eval_env = refuse_env
    substitution_args._eval_optenv = optenv_default
    substitution_args._eval_dict.update(find=guard.find, env=refuse_env, optenv=optenv_default)
    xacro.open = guard.open  # module global: shadows the builtin in xacro's own code
    xacro.eval_extension = eval_extension
    try:
        yield
    finally:
        xacro.eval_extension = saved_extension
        substitution_args._eval_find = saved_find
        substitution_args._eval_env = saved_env
        substitution_args._eval_optenv = saved_optenv
        substitution_args._eval_dict.clear()
        substitution_args._eval_dict.update(saved_dict)
        if had_open:
            xacro.open = saved_open
        else:
            del xacro.open
        xacro.all_includes = []


def _package_uris(root: ET.Element, packages: Mapping[str, Path]) -> None:
    """Absolute mesh paths inside a ``$(find)`` package become ``package://`` URIs."""
    if not packages:
        return
    for mesh in root.iter("mesh"):
        filename = mesh.get("filename") or ""
        plain = filename[len("file://") :] if filename.startswith("file://") else filename
        if not os.path.isabs(plain):
            continue
        for name, folder in packages.items():
            rel = os.path.relpath(os.path.normpath(plain), folder)
            if not rel.startswith(".."):
                mesh.set("filename", f"package://{name}/{Path(rel).as_posix()}")
                break


def xacro_as_urdf(path: Path, options: dict[str, Any]) -> tuple[Path, dict[str, Any]]:
    """Expand a xacro source into ``<work_dir>/xacro/<name>.urdf`` for tools that read a
    URDF file (the round trip's references: MuJoCo's import, yourdfpy).

    Mesh URIs are resolved now (through ``package_map`` and the containment rules, from
    the xacro file's place) and written as absolute paths; the returned options trust
    the folders they lie in (the robot folder and the packages ``$(find)`` named) and no
    longer carry ``xacro_args``. Raises :class:`ConversionError` as
    :func:`expand_xacro`, or for a mesh that does not resolve.
    """
    from robotwright.parsers.packages import UnresolvedMesh, resolve_uri

    opts = dict(options)
    xacro_args = opts.pop("xacro_args", None)
    package_map = opts.get("package_map")
    asset_roots = tuple(opts.get("asset_roots", ()))
    text, packages, _ = expand_xacro(
        path, xacro_args=xacro_args, package_map=package_map, asset_roots=asset_roots
    )
    root = DET.fromstring(text)
    _package_uris(root, packages)
    roots: list[Path] = [robot_root(path)]
    problems: list[Problem] = []
    for mesh in root.iter("mesh"):
        uri = mesh.get("filename")
        if not uri:
            continue
        try:
            resolved = resolve_uri(uri, path, package_map)
        except UnresolvedMesh as exc:
            problems.append(Problem(str(path), f"mesh '{uri}': {exc}"))
            continue
        mesh.set("filename", str(resolved))
        if uri.startswith("package://"):
            name = uri[len("package://") :].lstrip("/").partition("/")[0]
            found = find_package(name, path, package_map)
            if found is not None:
                roots.append(found.resolve())
    if problems:
        raise ConversionError(problems, summary=f"meshes of {path} not resolved")
    work = opts.get("work_dir")
    out_dir = Path(work) / "xacro" if work else Path(tempfile.mkdtemp(prefix=prefix("xacro")))
    out_dir.mkdir(parents=True, exist_ok=True)
    name = Path(path).name
    out = out_dir / (name[: -len(".xacro")] if name.lower().endswith(".xacro") else name)
    if out.suffix.lower() != ".urdf":
        out = out.with_name(out.name + ".urdf")
    write_text_atomic(out, ET.tostring(root, encoding="unicode"))
    opts["asset_roots"] = (*asset_roots, *dict.fromkeys(roots))
    return out, opts


if __name__ == "__main__":
    _worker()
