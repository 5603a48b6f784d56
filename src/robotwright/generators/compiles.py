"""Does a valid HRDF model export and compile? The last step of ``validate``.

It sits with the generators, above the model, because it uses them to write the MJCF
and URDF it checks.

The table checks of :mod:`robotwright.hrdf.validate` catch what the format forbids;
MuJoCo is the judge of the rest (mesh contents, what ``extra.xml`` names, keyframe
sizes, ...). So a folder that validates is one whose generated MJCF compiles and whose
URDF generates. Each MuJoCo error becomes a :class:`~robotwright.errors.Problem` located
in the robot's files:

- every mesh file is compiled on its own first (an empty, truncated, ASCII or
  random-bytes STL, a non-finite vertex, a mesh too flat for a convex hull, more faces
  than MuJoCo reads): one problem per ``mesh.csv`` row, naming the file;
- then the whole model: the element MuJoCo names is found in the generated XML and
  traced back to its table row, or to ``extra.xml`` when the model compiles without it.
"""

from __future__ import annotations

import dataclasses
import re
import warnings
from pathlib import Path

from robotwright.errors import Problem, RobotwrightError, UnsafePathError
from robotwright.hrdf.model import HRDF, SENSOR_OBJTYPES

#: the file named in problems about the generated model as a whole.
GENERATED = "generated MJCF"
_LINE = re.compile(r"line (\d+)")
_NAME = re.compile(r"""name="([^"]*)\"""")
_ACTUATOR_TAGS = ("motor", "position", "velocity", "general")
#: how MuJoCo ends a message: the element it was compiling (shown separately here).
_WHERE = re.compile(r"\s*Element (name '[^']*', id \d+, |'[^']*', )?line \d+\s*$")


def _mujoco_message(exc: Exception) -> str:
    """MuJoCo's error without its 'Error: ' prefix, on one line."""
    text = " ".join(line.strip() for line in str(exc).splitlines() if line.strip())
    return text.removeprefix("Error: ").strip()


def _compile_xml(xml: str) -> str | None:
    """MuJoCo's message when ``xml`` does not compile, else ``None``."""
    from robotwright._mjspec_cache import compiled

    try:
        compiled(xml)
    except Exception as exc:  # noqa: BLE001 - MuJoCo raises ValueError or its own types
        return _mujoco_message(exc)
    return None


def check_meshes(hrdf: HRDF) -> list[Problem]:
    """One problem per ``mesh.csv`` row whose file MuJoCo cannot turn into a mesh.

    Each distinct (file, scale) is compiled once, as the generator writes it (a mesh
    asset used by a collision geom, so that its convex hull is built too).
    """
    from xml.sax.saxutils import quoteattr

    from robotwright.generators.xmlfmt import fmt_vec

    out: list[Problem] = []
    seen: dict[tuple[Path, tuple[float, ...]], str | None] = {}
    for row, m in enumerate(hrdf.meshes):
        try:
            path = hrdf.mesh_source(m)
        except UnsafePathError:
            continue  # reported by the table checks
        key = (path, tuple(m.scale))
        if key not in seen:
            scale = f" scale={quoteattr(fmt_vec(m.scale))}" if m.scale != (1.0, 1.0, 1.0) else ""
            xml = (
                f"<mujoco><asset><mesh name='m' file={quoteattr(str(path))}{scale}/></asset>"
                "<worldbody><body><geom type='mesh' mesh='m'/></body></worldbody></mujoco>"
            )
            seen[key] = _compile_xml(xml) if path.is_file() else None
        msg = seen[key]
        if msg is not None:
            msg = _WHERE.sub("", msg)
            column = "file" if m.file is not None else "name"
            out.append(
                Problem(
                    "mesh.csv",
                    f"mesh file '{path}' is not a mesh MuJoCo reads: {msg}",
                    row=row,
                    column=column,
                )
            )
    return out


def _rows(hrdf: HRDF) -> dict[tuple[str, str], tuple[str, int]]:
    """(MJCF tag, name) -> (table, row) for the elements generated from table rows."""
    rows: dict[tuple[str, str], tuple[str, int]] = {}
    for i, b in enumerate(hrdf.bodies):
        rows[("body", b.name)] = ("body.csv", i)
    for i, j in enumerate(j for j in hrdf.joints if j.type != "free"):
        if j.name:
            rows[("joint", j.name)] = ("joint.csv", i)
    for i, a in enumerate(hrdf.actuators):
        for tag in _ACTUATOR_TAGS:
            rows[(tag, a.name or a.joint)] = ("actuator.csv", i)
    for i, g in enumerate(hrdf.simple_geoms):
        if g.name:
            rows[("geom", g.name)] = ("simple_geom.csv", i)
    for i, m in enumerate(hrdf.meshes):
        rows[("mesh", m.name)] = ("mesh.csv", i)
        if m.name:
            rows.setdefault(("geom", m.name), ("mesh.csv", i))
    for i, s in enumerate(hrdf.sites):
        rows[("site", s.name)] = ("site.csv", i)
    for i, s in enumerate(hrdf.sensors):
        for tag in SENSOR_OBJTYPES:
            rows[(tag, s.name)] = ("sensor.csv", i)
    return rows


def _element(xml: str, message: str) -> tuple[str | None, str | None, str | None]:
    """(tag, name, short text) of the generated element MuJoCo's message points at."""
    match = _LINE.search(message)
    if match is None:
        return None, None, None
    lines = xml.splitlines()
    n = int(match.group(1))
    if not 1 <= n <= len(lines):
        return None, None, None
    text = lines[n - 1].strip()
    tag_match = re.match(r"<([A-Za-z_][\w.-]*)", text)
    if tag_match is None:
        return None, None, None
    name = _NAME.search(text)
    short = text if len(text) <= 120 else text[:117] + "..."
    return tag_match.group(1), name.group(1) if name else None, short


def _generated_xml(hrdf: HRDF) -> str:
    """The MJCF export writes, scene included, less the scene's textures and material:
    fixed built-in pictures that cost most of the compile time and hold no value of the
    robot's files."""
    from robotwright.generators import MJCFHumanoidGenerator
    from robotwright.generators.xmlfmt import to_xml_string

    gen = MJCFHumanoidGenerator.from_hrdf(hrdf)
    root = gen.generate(relative_mesh_path=False)
    asset = root.find("asset")
    if asset is not None:
        for el in [e for e in asset if e.tag in ("texture", "material")]:
            asset.remove(el)
    for geom in root.iter("geom"):
        geom.attrib.pop("material", None)
    return to_xml_string(root)


def robot_xml(hrdf: HRDF) -> str:
    """Our MJCF of ``hrdf`` as a string: the robot alone (no scene), mesh paths
    absolute."""
    from robotwright.generators import MJCFHumanoidGenerator

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # conversion warnings are reported on export
        gen = MJCFHumanoidGenerator.from_hrdf(hrdf)
        return gen.export(None, relative_mesh_path=False, add_scene=False)


def check_compiles(hrdf: HRDF) -> list[Problem]:
    """Problems that stop ``hrdf`` from exporting or compiling (empty list when it does).

    Meant for a model without table errors: it generates the MJCF and the URDF in
    memory and compiles the MJCF with MuJoCo. Conversion warnings are not problems here.
    """
    from robotwright.generators import URDFHumanoidGenerator

    out = check_meshes(hrdf)
    if out:
        return out  # the whole model would stop at the same meshes
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # conversion warnings are reported on export
        try:
            URDFHumanoidGenerator.from_hrdf(hrdf).generate()
        except RobotwrightError as exc:
            out.append(Problem("generated URDF", f"cannot be generated: {exc}"))
        try:
            xml = _generated_xml(hrdf)
        except RobotwrightError as exc:
            return [*out, Problem(GENERATED, f"cannot be generated: {exc}")]
        message = _compile_xml(xml)
        if message is None:
            return out
        tag, name, text = _element(xml, message)
        if text is not None:
            message = _WHERE.sub("", message)
        where = _rows(hrdf).get((tag, name)) if tag and name is not None else None
        if where is not None:
            out.append(
                Problem(
                    where[0], f"MuJoCo refuses the model: {message}", row=where[1], element=text
                )
            )
            return out
        if hrdf.mjcf_extra and _compile_xml(_generated_xml(_without_extra(hrdf))) is None:
            out.append(
                Problem(
                    "extra.xml",
                    f"MuJoCo refuses what extra.xml adds: {message}",
                    element=text,
                )
            )
            return out
        out.append(Problem(GENERATED, f"MuJoCo refuses the model: {message}", element=text))
    return out


def too_deep_for_mjcf(hrdf: HRDF) -> str | None:
    """Why no MJCF of ``hrdf`` can be compiled (its bodies nest deeper than MuJoCo's
    MJCF reader reads; HRDF and URDF files are flat and hold it), or None."""
    from robotwright._inputs import MJCF_MAX_BODY_DEPTH

    depth: dict[int, int] = {}
    for index in range(len(hrdf.bodies)):
        chain = []
        k = index
        while k >= 0 and k not in depth:
            chain.append(k)
            k = hrdf.bodies[k].parent
            if len(chain) > len(hrdf.bodies):
                return None  # a cycle: validation reports it
        base = depth.get(k, 0)
        for offset, body in enumerate(reversed(chain), start=1):
            depth[body] = base + offset
    deepest = max(depth.values(), default=0)
    if deepest <= MJCF_MAX_BODY_DEPTH:
        return None
    return (
        f"the robot nests {deepest} bodies deep and MuJoCo's MJCF reader at most "
        f"{MJCF_MAX_BODY_DEPTH}, so no MJCF of it compiles to compare with"
    )


def require_compiles(hrdf: HRDF, doing: str, *, scene: bool = True) -> None:
    """Refuse a model MuJoCo refuses, saying where: ``convert``/``export`` call it before
    writing (so they never write what ``validate`` calls invalid, and exit 0), ``render``
    and ``view`` when MuJoCo cannot compile what they were given. ``doing`` starts the
    message (``"cannot write out.xml"``). ``scene``: the MJCF with the scene export adds
    (a floor, a light and a sky), else the robot alone, as :func:`robot_xml` writes it
    and the proof compiles it (MuJoCo's parse of it is then made once:
    :mod:`robotwright._mjspec_cache`).

    The whole model is compiled once; only when MuJoCo refuses it are the per-mesh and
    per-row checks of :func:`check_compiles` run to say where.

    Raises:
        HRDFError: the problems (naming table and row, mesh file, or the generated MJCF);
            also the table errors that stop the model from being generated at all.
    """
    from robotwright.errors import HRDFError

    if too_deep_for_mjcf(hrdf) is not None:
        return  # MuJoCo cannot judge it: the MJCF writer refuses it, flat formats hold it
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # conversion warnings are reported on export
        # table errors raise HRDFError here
        message = _compile_xml(_generated_xml(hrdf) if scene else robot_xml(hrdf))
    if message is None:
        return
    problems = [p for p in check_compiles(hrdf) if p.severity == "error"]
    if not problems:  # the detailed checks found nothing more precise than MuJoCo's words
        problems = [Problem(GENERATED, f"MuJoCo refuses the model: {message}")]
    raise HRDFError(problems, summary=f"{doing}: MuJoCo refuses the model")


def _without_extra(hrdf: HRDF) -> HRDF:
    return dataclasses.replace(hrdf, mjcf_extra=None)


__all__ = [
    "GENERATED",
    "check_compiles",
    "check_meshes",
    "require_compiles",
    "robot_xml",
    "too_deep_for_mjcf",
    "validate_dir",
]


def validate_dir(path: str | Path, *, compile_model: bool = True) -> list[Problem]:
    """Read and check an HRDF folder; return every problem (errors and warnings).

    With ``compile_model`` (the default), a folder without table errors is also exported in
    memory and compiled with MuJoCo (see :func:`check_compiles`):
    a folder that validates exports to MJCF and URDF, and its MJCF compiles.
    """
    from robotwright.hrdf.io import collect_hrdf_dir

    hrdf, problems = collect_hrdf_dir(path)
    if compile_model and hrdf is not None and not any(p.severity == "error" for p in problems):
        problems += check_compiles(hrdf)
    return problems
