"""Round-trip fidelity: source -> HRDF -> our MJCF (and our URDF), compared with the
source compiled by MuJoCo, or with an independent URDF library when MuJoCo refuses it.

Used by ``robotwright roundtrip SOURCE`` and by the real-robot tests. Tolerances:

- MJCF path: masses and inertia tensors relative 1e-9, centres of mass 1e-9 m, joint
  axes and ranges 1e-9, forward kinematics of every body and site 1e-9 (m and rad) at
  ``configs`` random configurations (uniform inside joint ranges, [-pi, pi] for
  unlimited hinges, [-1, 1] m for unlimited slides, uniform rotations for ball/free).
- URDF path (our URDF loaded by MuJoCo): total mass and FK 1e-6.

Mimic joints are set from the joint they follow (``offset + multiplier * q``) in both
models, since forward kinematics does not apply equality constraints.
"""

from __future__ import annotations

import os
import tempfile
from concurrent.futures import ThreadPoolExecutor
from contextlib import ExitStack
from pathlib import Path
from typing import Any

import mujoco

from robotwright._temporaries import prefix
from robotwright.errors import ConversionError, InputFileError, Problem
from robotwright.parsers.reference import (
    compile_urdf,
    mimic_map,
    view_from_model,
)
from robotwright.parsers.xacro.expand import is_xacro, xacro_as_urdf
from robotwright.proof.roundtrip.compare import (
    compare_views,
    random_configs,  # noqa: F401
)
from robotwright.proof.roundtrip.geoms import compare_extras, compare_geoms, rotation_angles  # noqa: F401
from robotwright.proof.roundtrip.report import FLOOR, TOL_EXACT, TOL_URDF, RoundTripReport, Row  # noqa: F401
from robotwright.proof.roundtrip.sides import (  # noqa: F401
    OurURDF,
    our_mjcf_model,
    our_mjcf_text,
    our_urdf,
    our_urdf_model,
    our_urdf_view,
    parse_source,
    reference_loader,
    reference_view,
    source_kind,
    xyz_angles,
)


def roundtrip(
    source: str | os.PathLike,
    *,
    configs: int = 50,
    urdf: bool = True,
    reference: str = "auto",
    simulate: bool = True,
    **options: Any,
) -> RoundTripReport:
    """The fidelity table of one MJCF or URDF file (see the module docstring).

    ``reference``: ``"auto"`` (MuJoCo's import; yourdfpy for a URDF MuJoCo refuses),
    ``"mujoco"`` or ``"yourdfpy"`` (URDF only). ``simulate`` (the default; MJCF sources
    read whole, without ``root_body``, as ``convert``): one more row, the source and our
    MJCF stepped side by side (:mod:`robotwright.proof.rollout`: 200 steps with
    zero and with pseudo-random control, contacts on; MuJoCo references only). ``options``
    go to the parser. Staged
    meshes live in a temporary folder removed at the end (unless ``work_dir`` is given).

    Raises:
        ConversionError: the input itself is unusable (no such file, not a .urdf/.xml
            file, not well-formed or unsafe XML, ``configs`` < 1); later failures
            (parser, reference, compile) are reported in the table instead.
    """
    _check_input(Path(source), configs)
    # As in convert, a source read whole: a robot taken out of a larger world (root_body)
    # has a reference that still holds the rest of that world; a URDF's massless leaf
    # links made sites have no counterpart in MuJoCo's import (which keeps them bodies).
    whole = options.get("root_body") is None and options.get("fixed_joints") != "site"
    stepped = simulate and whole
    with ExitStack() as stack:
        if "work_dir" not in options:
            tmp = stack.enter_context(tempfile.TemporaryDirectory(prefix=prefix("rt")))
            options = {**options, "work_dir": tmp}
        # The three MuJoCo imports (the source, our MJCF, our URDF) run on threads as soon
        # as each text is ready, beside the Python work that writes the next one: on a
        # large robot they are most of the time, and MuJoCo releases the interpreter while
        # it works. The pool ends before the staged meshes go.
        pool = stack.enter_context(ThreadPoolExecutor(max_workers=3))
        report = _roundtrip_on(pool, Path(source), configs, urdf, reference, options, stepped)
    if stepped and not report.error:
        report.rows.insert(_after_mjcf_rows(report), simulation_row(report))
    return report


#: The check of the simulation row (a long chain is stepped fewer times: the row's value
#: says how many; see :func:`~robotwright.proof.rollout.rollout_steps`).
SIMULATION_CHECK = "MJCF: simulation (200 steps, zero and pseudo-random control, contacts on)"


def _after_mjcf_rows(report: RoundTripReport) -> int:
    return sum(1 for r in report.rows if r.check.startswith("MJCF: "))


def simulation_row(report: RoundTripReport) -> Row:
    """The source's model and our MJCF's stepped side by side, as one row: "n/a" when
    the two cannot be (no MuJoCo reference, joints or actuators not matched one to
    one); "not simulated: ..." where the source cannot be (the reason)."""
    from robotwright.proof.compare import _rollouts

    source = report.simulated_reference
    ours = report.simulated_model
    if source is None or ours is None or not report.reference.startswith("mujoco"):
        return Row(SIMULATION_CHECK, "no MuJoCo model of the source", True, compared=0)
    from robotwright.proof.rollout import ROLLOUT_STEPS, RolloutNotMade, rollout_steps

    try:
        found = _rollouts(source, ours)
    except RolloutNotMade as why:
        return Row(SIMULATION_CHECK, f"not simulated: {why}", True, compared=0)
    if found is None:
        return Row(SIMULATION_CHECK, "not comparable one to one", True, compared=0)
    if not found:
        steps = rollout_steps(source)
        over = "" if steps == ROLLOUT_STEPS else f" over {steps} steps, fewer for a long chain"
        return Row(SIMULATION_CHECK, f"the same motion{over} (within 1e-6)", True, compared=1)
    return Row(SIMULATION_CHECK, "; ".join(d.result for d in found), False, compared=1)


def _without_visuals(mjcf_text: str) -> mujoco.MjModel:
    spec = mujoco.MjSpec.from_string(mjcf_text)
    spec.compiler.discardvisual = True
    return spec.compile()


def _check_input(path: Path, configs: int) -> None:
    from robotwright._xmlsafe import parse_xml

    if configs < 1:
        raise ConversionError(
            [Problem(str(path), f"configs: expected at least 1 configuration, got {configs}")]
        )
    if path.suffix.lower() not in (".urdf", ".xml", ".mjcf", ".xacro"):
        raise ConversionError([Problem(str(path), "expected a .urdf, .xacro or .xml (MJCF) file")])
    if not path.is_file():
        what = (
            "is a folder"
            if path.is_dir()
            else "not a regular file"
            if path.exists()
            else "file not found"
        )
        raise ConversionError([Problem(str(path), f"{what}: expected a .urdf or .xml file")])
    parse_xml(path)  # not well-formed or unsafe XML: an input error, named with its line


def _roundtrip_on(
    pool: ThreadPoolExecutor,
    path: Path,
    configs: int,
    urdf: bool,
    reference: str,
    options: dict[str, Any],
    stepped: bool = False,
) -> RoundTripReport:
    """The table of :func:`roundtrip`; ``stepped``: the models its simulation row steps
    are made too (see RoundTripReport.simulated_model and simulated_reference)."""
    report = RoundTripReport(str(path), "")
    try:
        # The parse reads the xacro itself (its messages name it); the references read
        # a URDF file: the expansion, written into work_dir.
        result = parse_source(path, **options)
        if is_xacro(path):
            path, options = xacro_as_urdf(path, options)
    except Exception as exc:  # the table reports any failure with its reason
        report.error = f"parse failed: {type(exc).__name__}: {exc}"
        if isinstance(exc, ConversionError):
            report.input_error = exc
        elif isinstance(exc, InputFileError):  # a file refused unread (over a size cap)
            report.input_error = ConversionError([Problem(exc.path, exc.reason)])
        return report
    report.warnings = [str(w) for w in result.warnings]
    report.parse = result
    mimic = mimic_map(path)
    try:
        mjcf_text = our_mjcf_text(result.hrdf)
    except Exception as exc:
        # Known before MuJoCo's import of the source starts: for a robot our MJCF cannot
        # hold (a chain deeper than MJCF allows) that import can take far longer than
        # this answer (MuJoCo 4.0 spends 20 s refusing a chain of 2,000 links).
        report.error = f"our MJCF is not written: {type(exc).__name__}: {exc}"
        from robotwright.errors import HRDFError

        if isinstance(exc, HRDFError):
            # The robot's own values are refused (non-physical inertias): bad input, exit
            # 2, as convert refuses it.
            report.input_error = ConversionError(
                exc.problems, summary=f"{path}: the robot is not a valid HRDF"
            )
        return report
    try:
        loader = reference_loader(
            path, reference, **{k: v for k, v in options.items() if k != "work_dir"}
        )
    except Exception as exc:
        report.error = f"no reference: {type(exc).__name__}: {exc}"
        return report
    # MuJoCo's import, started in its confined reader before the pool's threads run
    # MuJoCo; a fallback runs only if needed.
    started = loader.started()
    # A URDF merged: the simulation row steps it beside MuJoCo's fused import (see
    # RoundTripReport.simulated_reference), started now for the same reason.
    fused = None
    urdf_source = source_kind(path) != "mjcf"
    if stepped and urdf_source and options.get("fixed_joints") == "merge":
        from robotwright.proof.models import start_source_model

        given = {k: v for k, v in options.items() if k != "work_dir"}
        fused = start_source_model(path, "urdf", given)
    ref_job = pool.submit(started)
    mjcf_job = pool.submit(lambda: mujoco.MjSpec.from_string(mjcf_text).compile())
    # The simulation row's model of a URDF source: without the visual geoms that MuJoCo's
    # import of the source leaves out (compiled while the staged meshes are there).
    sim_job = pool.submit(_without_visuals, mjcf_text) if stepped and urdf_source else None
    ours_urdf: OurURDF | Exception | None = None
    urdf_job = None
    if urdf:
        try:
            ours_urdf = our_urdf(result.hrdf)
        except Exception as exc:  # reported in the URDF rows
            ours_urdf = exc
        else:
            urdf_job = pool.submit(compile_urdf, ours_urdf.text)
    try:
        try:
            ref = ref_job.result()
        except ValueError as exc:
            ref = loader.instead(exc)
    except Exception as exc:
        report.error = f"no reference: {type(exc).__name__}: {exc}"
        if fused:
            fused()  # its reader waited for, not left behind
        return report
    simulated_reference = fused() if fused else ref.model
    report.reference = ref.kind
    report.reference_model = ref.model
    try:
        report.mjcf_model = mjcf_job.result()
        report.simulated_model = sim_job.result() if sim_job else report.mjcf_model
        report.simulated_reference = simulated_reference
        ours = view_from_model(report.mjcf_model)
    except Exception as exc:
        report.error = f"our MJCF does not compile: {type(exc).__name__}: {exc}"
        if ref.kind.startswith("yourdfpy (MuJoCo refuses"):
            # MuJoCo refuses the source too (non-physical inertias): bad input, exit 2.
            report.input_error = ConversionError(
                [Problem(str(path), f"MuJoCo refuses it: {str(exc).splitlines()[0]}")]
            )
        if "mass" in str(exc) and source_kind(path) == "urdf":
            report.error += (
                "\nhint: massless links; try --fixed-joints merge, or --bound-mass/--bound-inertia"
            )
        return report
    collision_only = source_kind(path) == "urdf"  # MuJoCo's URDF import drops visuals
    rows = compare_views(
        ref,
        ours,
        configs=configs,
        mimic=mimic,
        collision_only=collision_only,
        source_has_actuators=source_kind(path) != "urdf",
    )
    for r in rows:
        r.check = "MJCF: " + r.check
        report.rows.append(r)
    if not urdf:
        return report
    if isinstance(ours_urdf, ImportError):
        report.rows.append(Row("URDF: generator", "not available", False))
        return report
    try:
        if isinstance(ours_urdf, Exception):
            raise ours_urdf
        assert isinstance(ours_urdf, OurURDF) and urdf_job is not None
        ours_u = ours_urdf.view(urdf_job.result())
    except Exception as exc:
        # MuJoCo refusing our URDF for the reason it refuses the source (a non-physical
        # inertia the parser noted and kept) is the source's fault: nothing to compare.
        first = str(exc).splitlines()[0] if str(exc) else ""
        as_source = (
            bool(first) and ref.kind.startswith("yourdfpy (MuJoCo refuses") and (first in ref.kind)
        )
        report.rows.append(
            Row(
                "URDF: our URDF loads in MuJoCo",
                f"no: {type(exc).__name__}: {str(exc)[:200]}",
                as_source,
                "MuJoCo refuses the source for the same reason" if as_source else "",
                compared=0 if as_source else None,
            )
        )
        return report
    urdf_rows = compare_views(
        ref, ours_u, tol=TOL_URDF, configs=configs, mimic=mimic, full=False, inertials_ref=ours
    )
    for r in urdf_rows:
        r.check = "URDF: " + r.check
        report.rows.append(r)
    return report
