"""Convert between MJCF, URDF and HRDF folders (type by extension, or folder = HRDF); a
USD file (``.usd``, ``.usda``, ``.usdc``) is read too (:mod:`robotwright.parsers.usd.reader`),
and written by ``robotwright export`` (:func:`robotwright.generators.to_usd`).

Outputs are written atomically by the writers (HRDF folder: all or nothing; MJCF/URDF:
temporary file then rename) with meshes copied next to the output, so the result loads
on its own.
"""

from __future__ import annotations

import os
import tempfile
import warnings
from pathlib import Path
from typing import Any

from robotwright._temporaries import prefix
from robotwright._usd_format import USD_SUFFIXES
from robotwright.errors import ConversionError, HRDFError, OutputExistsError, Problem
from robotwright.hrdf.model import HRDF


def file_kind(path: Path, *, existing: bool) -> str:
    """``"urdf"``, ``"mjcf"`` or ``"hrdf"`` from the extension (a folder is HRDF)."""
    ext = path.suffix.lower()
    if ext in (".urdf", ".xacro"):  # .xacro / .urdf.xacro: expanded to URDF first
        return "urdf"
    if ext in (".xml", ".mjcf"):
        return "mjcf"
    if existing and ext in USD_SUFFIXES:
        return "usd"
    if (existing and path.is_dir()) or (not existing and ext == ""):
        return "hrdf"
    raise ConversionError(
        [
            Problem(
                str(path),
                "expected a .urdf or .xacro file, a .xml (MJCF) file or an HRDF folder"
                + ("" if existing else " (USD is written by 'robotwright export')"),
            )
        ]
    )


def load_any(path: Path, *, strict: bool = False, **options: Any) -> tuple[HRDF, list[Problem]]:
    """Read a robot from any supported source; returns it and the parse warnings."""
    from robotwright.parsers.api import (
        mjcf_to_hrdf_with_warnings,
        urdf_to_hrdf_with_warnings,
        usd_to_hrdf_with_warnings,
    )

    kind = file_kind(path, existing=True)
    if kind == "hrdf":
        return HRDF.from_dir(path, asset_roots=options.get("asset_roots")), []
    _check_options(path, kind, options)
    parse = {
        "urdf": urdf_to_hrdf_with_warnings,
        "mjcf": mjcf_to_hrdf_with_warnings,
        "usd": usd_to_hrdf_with_warnings,
    }[kind]
    result = parse(path, strict=strict, **options)
    return result.hrdf, result.warnings


def _check_options(path: Path, kind: str, options: dict[str, Any]) -> None:
    """Name an option that does not apply to this kind of source (e.g. ``bound_mass``
    for an MJCF) instead of failing inside the options dataclass with a TypeError."""
    import dataclasses

    from robotwright.parsers.mjcf.reader import MJCFOptions
    from robotwright.parsers.urdf.reader import URDFOptions
    from robotwright.parsers.usd.reader import USDOptions

    cls = {"urdf": URDFOptions, "usd": USDOptions}.get(kind, MJCFOptions)
    known = {f.name for f in dataclasses.fields(cls)}
    unknown = sorted(set(options) - known)
    if unknown:
        flags = ", ".join(f"{k} (--{k.replace('_', '-')})" for k in unknown)
        raise ConversionError(
            [Problem(str(path), f"option(s) {flags} do not apply to a {kind.upper()} source")]
        )


def convert(
    src: str | os.PathLike,
    dst: str | os.PathLike,
    *,
    strict: bool = False,
    overwrite: bool = False,
    proof: bool = True,
    scene: bool = False,
    simulate: bool = True,
    **options: Any,
) -> list[str]:
    """Convert ``src`` to ``dst``; returns every warning (parser and writer) as text.

    An MJCF output holds the robot and nothing else; ``scene=True`` adds a floor, a light
    and a sky (one note names them: they are not the source's).

    With ``proof`` (the default), an MJCF or URDF source that MuJoCo compiles is compared
    with the output, compiled, field by field (:mod:`robotwright.proof.compare`): each
    difference no warning reports becomes one; under ``strict`` any fails the conversion
    before anything is written. ``simulate`` (the default): the proof also steps the
    source and the output side by side (:mod:`robotwright.proof.rollout`; MJCF sources)
    and reports a divergence neither the source's own sensitivity nor its round-off
    twin explains; ``simulate=False`` compares the compiled models only.

    ``options`` go to the parser (see ``URDFOptions`` / ``MJCFOptions``), except
    ``collision_max_faces`` and ``convex_decomposition``, which repair the collision
    meshes afterwards (see :mod:`robotwright.parsers.collision`; each repair reported).
    """
    src_p, dst_p = Path(src), Path(dst)
    out_kind = file_kind(dst_p, existing=False)
    if dst_p.exists() and not overwrite:
        raise OutputExistsError(f"{dst_p} exists (pass overwrite=True / --overwrite)")
    if scene and out_kind != "mjcf":
        raise ConversionError([Problem(str(dst_p), "scene=True / --scene applies to MJCF output")])
    if "work_dir" in options or file_kind(src_p, existing=True) == "hrdf":
        return _convert(src_p, dst_p, out_kind, strict, overwrite, options, proof, scene, simulate)
    # The output gets its own copies of the meshes: staging lives only for the call.
    with tempfile.TemporaryDirectory(prefix=prefix("convert")) as tmp:
        return _convert(
            src_p,
            dst_p,
            out_kind,
            strict,
            overwrite,
            {**options, "work_dir": tmp},
            proof,
            scene,
            simulate,
        )


def _convert(
    src_p: Path,
    dst_p: Path,
    out_kind: str,
    strict: bool,
    overwrite: bool,
    options: dict[str, Any],
    proof: bool = True,
    scene: bool = False,
    simulate: bool = False,
) -> list[str]:
    from robotwright._confine import run_confined
    from robotwright.parsers.collision import pop_config
    from robotwright.parsers.packages import source_read_roots

    options = dict(options)
    repairs = pop_config(options)  # opt-in collision-mesh repairs, after the parse
    # Reading, repairs and the proof in one confined reader: the proof compiles the
    # source and the output where MuJoCo has just decoded the source's meshes.
    work = options.get("work_dir")
    from robotwright.parsers.api import prepare_read

    prepare_read()
    if file_kind(src_p, existing=True) == "usd":
        from robotwright.parsers.usd.reader import prepare_confined_read

        prepare_confined_read()
    hrdf, messages, proved = run_confined(
        _read_and_prove,
        src_p,
        out_kind,
        strict,
        options,
        repairs,
        proof,
        simulate,
        (dst_p, scene),
        roots=source_read_roots(src_p, file_kind(src_p, existing=True), options),
        writable=[work] if work else [],
        what=str(src_p),
    )
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            if proof:
                if proved is None:  # the reader could not prove it: say why here
                    proved = _proof(src_p, hrdf, out_kind, messages, strict, options, simulate)
                messages += proved
            if out_kind == "hrdf":
                hrdf.save(dst_p, overwrite=overwrite)
            else:
                from robotwright.generators import MJCFHumanoidGenerator, URDFHumanoidGenerator

                if out_kind == "mjcf":
                    # The robot alone, as the proof compiled it; a scene only when asked.
                    MJCFHumanoidGenerator.from_hrdf(hrdf).export(
                        dst_p, copy_meshes=True, strict=strict, add_scene=scene
                    )
                    if scene:
                        messages.append(
                            f"{dst_p}: scene added (asked for with --scene): a floor plane "
                            "'floor', a light and a sky; not part of the source robot"
                        )
                else:
                    URDFHumanoidGenerator.from_hrdf(hrdf).export(
                        dst_p, copy_meshes=True, strict=strict
                    )
        except HRDFError as exc:
            raise _not_valid(exc, dst_p) from exc
    messages += [str(w.message) for w in caught]
    return messages


def _not_valid(exc: HRDFError, dst_p: Path) -> ConversionError:
    """The conversion's error for a robot that is not a valid HRDF (its problems)."""
    massless = any(p.column in ("mass", "diag_inertia") for p in exc.problems)
    hint = (
        " (massless links: try fixed_joints='merge' / --fixed-joints merge, or "
        "bound_mass / --bound-mass)"
        if massless
        else ""
    )
    return ConversionError(
        exc.problems, summary=f"cannot write {dst_p}: the robot is not a valid HRDF{hint}"
    )


def _read_and_prove(
    src_p: Path,
    out_kind: str,
    strict: bool,
    options: dict[str, Any],
    repairs: Any,
    proof: bool,
    simulate: bool = False,
    check: tuple[Path, bool] | None = None,
) -> tuple[HRDF, list[str], list[str] | None]:
    """Read the source, repair its collision meshes, refuse an output MuJoCo refuses
    (``check``: the output and whether it has a scene, for
    :func:`~robotwright.generators.compiles.require_compiles`; in the same process as the
    proof, which then compiles our MJCF from MuJoCo's parse already made) and prove the
    conversion (run in a confined reader): the robot, the notes, and the proof's notes
    (None: not proved here, for example because the output does not compile; the caller
    says why).

    Raises:
        ConversionError: MuJoCo refuses the output (its problems), or ``strict`` and the
            proof found a difference.
    """
    from robotwright.generators.compiles import require_compiles
    from robotwright.parsers.collision import repair_collision_meshes

    hrdf, problems = load_any(src_p, strict=strict, **options)
    messages = [str(p) for p in problems]
    hrdf, repaired = repair_collision_meshes(hrdf, repairs)
    messages += [str(r) for r in repaired]
    if check is not None:  # what MuJoCo refuses is not written
        dst_p, scene = check
        try:
            require_compiles(hrdf, f"cannot write {dst_p}", scene=scene)
        except HRDFError as exc:
            raise _not_valid(exc, dst_p) from exc
    proved = None
    if proof:
        try:
            proved = _proof(src_p, hrdf, out_kind, messages, strict, options, simulate)
        except ConversionError:
            raise  # a strict proof's refusal is the conversion's answer
        except Exception:  # noqa: BLE001 - the output's own check gives the reason
            proved = None
    return hrdf, messages, proved


def _proof(
    src_p: Path,
    hrdf: HRDF,
    out_kind: str,
    notes: list[str],
    strict: bool,
    options: dict[str, Any],
    simulate: bool = False,
) -> list[str]:
    """The proof's notes (see :func:`robotwright.proof.compare.prove`); under ``strict``
    any of them is a ConversionError, raised before the output is written."""
    from robotwright.parsers.xacro.expand import is_xacro, xacro_as_urdf
    from robotwright.proof.compare import prove

    kind = file_kind(src_p, existing=True)
    if kind == "hrdf":
        if out_kind != "urdf":
            return []  # the output is the folder's own export: nothing else to compare with
        # A URDF holds less than the folder: MuJoCo's import of it against its MJCF.
        from robotwright.proof.urdf_output import prove_urdf_output

        found = prove_urdf_output(hrdf, str(src_p), notes)
    elif kind == "usd":
        found = _usd_proof(src_p, hrdf, out_kind, options)
    else:
        path, opts = src_p, options
        if is_xacro(src_p):
            path, opts = xacro_as_urdf(src_p, options)
        work = opts.get("work_dir")
        found = prove(
            path,
            kind,
            hrdf,
            out_kind,
            notes,
            options=opts,
            work_dir=Path(work) if work else None,
            simulate=simulate,
        )
    if strict and found:
        raise ConversionError(
            found,
            summary=f"strict conversion of {src_p}: {len(found)} value(s) differ between the "
            "source and the output, compiled by MuJoCo",
        )
    return [str(p) for p in found]


def _usd_proof(src_p: Path, hrdf: HRDF, out_kind: str, options: dict[str, Any]) -> list[Problem]:
    """A USD source's proof: Newton's reading of the file against MuJoCo's compile of the
    output (:func:`robotwright.generators.usd_proof.prove_usd`)."""
    from robotwright.generators.usd_proof import prove_usd
    from robotwright.proof.models import result_model

    work = options.get("work_dir")
    model, _ = result_model(hrdf, out_kind, Path(work) if work else None)
    proof = prove_usd(src_p, model, hrdf)
    return [Problem(str(src_p), line, severity="warning") for line in proof.differences]
