"""MJCF -> HRDF through MuJoCo itself.

The file is loaded with ``mujoco.MjSpec`` and compiled, so defaults and classes,
``fromto``, euler angles, includes, frames and compiler options are resolved by MuJoCo.
Numbers are then read from the compiled ``MjModel`` (what MuJoCo simulates): body frames,
inertias (as compiled, also when MuJoCo computed them from geoms), joints, actuators,
geoms, sites and sensors. Mesh files and scales come from the spec's mesh assets; a mesh
geom's pose is the authored one (MuJoCo's mesh re-centring is undone), so that our MJCF,
compiled again, gives the same model.

What the tables cannot hold goes to ``HRDF.mjcf_extra`` (tendons, equality constraints,
contact pairs and excludes, keyframes) or is reported as a warning naming it.
"""

from __future__ import annotations

import os
import xml.etree.ElementTree as ET
from pathlib import Path

import mujoco

from robotwright._limits import keyframes_problem
from robotwright._paths import check_mjcf_includes, check_mjcf_spec, trusted_roots
from robotwright._xmlsafe import parse_xml
from robotwright.errors import ConversionError, InputFileError, Problem, UnsafePathError
from robotwright.hrdf.model import (
    HRDF,
    Meta,
    SimulatorConfig,
)
from robotwright.hrdf.options import nuser_from_model, options_from_model
from robotwright.parsers.meshes import (
    mesh_store,
)
from robotwright.parsers.mjcf import extra as mjcf_extra
from robotwright.parsers.mjcf.actuators import _actuators, _carried_instances, _plugin_instances
from robotwright.parsers.mjcf.common import MJCFOptions, _t3
from robotwright.parsers.mjcf.geoms import _geoms
from robotwright.parsers.mjcf.tree import (
    _bodies,
    _frames_as_sites,
    _joints,
    _keyframes,
    _select_robot,
    _sensors,
    _sites,
)
from robotwright.parsers.reference import body_name
from robotwright.parsers.report import ParseResult, Reporter, warn_massless_moving

_INTEGRATORS = {0: "Euler", 1: "RK4", 2: "implicit", 3: "implicitfast"}


def _report_scene(model: mujoco.MjModel, rep: Reporter, carried_plugins: int = 0) -> None:
    """Warnings for the model parts HRDF has no place for (``carried_plugins``: plugin
    instances that travel with their actuators)."""
    for what, count in (("camera", model.ncam), ("light", model.nlight)):
        if count:
            rep.warn(f"{count} {what}(s) dropped (HRDF has no {what}s)", cosmetic=True)
    for what, count in (
        ("flex", model.nflex),
        ("skin", model.nskin),
        ("plugin instance (of a sensor or passive force)", model.nplugin - carried_plugins),
        ("custom numeric", model.nnumeric),
        ("custom text", model.ntext),
        ("custom tuple", model.ntuple),
    ):
        if count:
            rep.warn(f"{count} {what} element(s) dropped (no HRDF equivalent)")
    for what, count in (("height field", model.nhfield), ("texture", model.ntex)):
        if count:
            rep.warn(
                f"{count} {what}(s) dropped (HRDF geoms carry a colour only)",
                cosmetic=what == "texture",
            )


def parse_mjcf(
    path: str | os.PathLike, options: MJCFOptions | None = None, *, strict: bool = False
) -> ParseResult:
    """Parse an MJCF file into an HRDF (see the module docstring and :class:`MJCFOptions`).

    Raises:
        ConversionError: unsafe XML, a file path leaving the MJCF's folder (an include,
            mesh or texture: ``..``, an absolute path or ``meshdir``, a symbolic link; see
            ``asset_roots``), a model MuJoCo cannot compile (MuJoCo's message), a world
            with several robots and no ``root_body``, or, with ``strict=True``, any
            warning.
    """
    path = Path(path)
    opt = options or MJCFOptions()
    rep = Reporter(str(path))
    # Refuse entity tricks before MuJoCo's own (expanding) XML reader, and any file the
    # model would make MuJoCo read (include, mesh, texture) outside the MJCF's folder.
    tree = parse_xml(path)
    where = {"source": str(path), "model_dir": path.resolve().parent}
    try:
        trusted = trusted_roots(opt.asset_roots)
        sub_dirs = check_mjcf_includes(tree, **where, root=path.resolve().parent, trusted=trusted)
        spec = mujoco.MjSpec.from_file(str(path))
        check_mjcf_spec(spec, **where, root=path.resolve().parent, trusted=trusted)
        # Keyframes are allocated when the model compiles: refuse a flood of them first.
        too_many = keyframes_problem(max(len(spec.keys), spec.nkey))
        if too_many is not None:
            raise InputFileError(path, too_many)
        model = spec.compile()
        # The proof of the conversion compares with this compile (one compile saved).
        from robotwright.parsers.mjcf.compiled import remember_parsed

        remember_parsed(path, spec, model)
    except UnsafePathError as exc:
        problem = Problem(exc.file or str(path), exc.reason, element=exc.element)
        raise ConversionError([problem]) from exc
    except InputFileError:
        raise  # a file over the size limit: refused before MuJoCo read it
    except ValueError as exc:
        raise ConversionError([Problem(str(path), f"MuJoCo cannot load it: {exc}")]) from exc
    return _from_compiled(spec, model, path, opt, rep, strict, sub_dirs)


def parse_mjcf_spec(
    spec: mujoco.MjSpec, path: Path, options: MJCFOptions | None = None, *, strict: bool = False
) -> ParseResult:
    """An HRDF from a spec built in memory by another reader (its values exactly: an
    MJCF text would keep 6 digits). ``path`` names the source in notes, and its folder
    holds the spec's mesh files (``spec.modelfiledir``)."""
    rep = Reporter(str(path))
    try:
        model = spec.compile()
    except ValueError as exc:
        raise ConversionError([Problem(str(path), f"MuJoCo cannot compile it: {exc}")]) from exc
    return _from_compiled(spec, model, Path(path), options or MJCFOptions(), rep, strict)


def _from_compiled(
    spec: mujoco.MjSpec,
    model: mujoco.MjModel,
    path: Path,
    opt: MJCFOptions,
    rep: Reporter,
    strict: bool,
    sub_dirs: list[Path] | None = None,
) -> ParseResult:
    """The HRDF of a compiled spec (the body of :func:`parse_mjcf`; ``sub_dirs``: the
    folders of its sub-models, from the containment check)."""
    roots, keep = _select_robot(model, path, opt, rep)
    kept = set(keep)
    frames = _frames_as_sites(model, keep, roots, opt)
    bodies = _bodies(model, keep, roots, frames, rep)
    joints = _joints(model, kept, roots, path, rep)
    store = mesh_store(opt.work_dir, opt.join_obj_objects)
    trusted = trusted_roots(opt.asset_roots)
    meshes, simple = _geoms(model, spec, kept, path, store, frames, rep, sub_dirs or [], trusted)
    sites = _sites(model, kept, frames, roots, rep)
    names = {
        "joint": {j.name for j in joints if j.name},
        "tendon": {model.tendon(t).name for t in range(model.ntendon) if model.tendon(t).name},
        "site": {x.name for x in sites},
        "body": {body_name(model, b) for b in keep if b not in frames} | {"world"},
        "geom": {x.geom_name for x in [*meshes, *simple] if x.geom_name},
    }
    extra_parts: list[ET.Element] = []
    tendon_section, names["tendon"] = mjcf_extra.tendons(model, names, rep.warn)
    for section in (
        tendon_section,
        mjcf_extra.equalities(model, names, rep.warn, mjcf_extra.welds_with_relpose(spec, model)),
        mjcf_extra.contacts(model, names, rep.warn),
    ):
        if section is not None:
            extra_parts.append(section)
    actuators, carried_actuators, kept_actuators = _actuators(model, spec, names, rep)
    option, flag, option_unheld = options_from_model(model)
    if option_unheld:
        rep.warn(f"<option> fields {option_unheld} dropped (no HRDF key)")
    kept_names = {
        "body": {body_name(model, b) for b in keep if b not in frames},
        "xbody": {body_name(model, b) for b in keep if b not in frames},
        "site": {x.name for x in sites},
        "joint": {x.name for x in joints},
        "actuator": {x.name for x in actuators} | {e.get("name") for e in carried_actuators},
        "geom": {x.geom_name for x in [*meshes, *simple] if x.geom_name},
        "tendon": names["tendon"],
    }
    in_extra = {"actuator": {e.get("name") for e in carried_actuators if e.get("name")}}
    sensors, extra_sensors = _sensors(model, kept_names, rep, in_extra)
    _report_scene(model, rep, _carried_instances(carried_actuators))

    if carried_actuators:
        used = {e.get("instance") for e in carried_actuators if e.tag == "plugin"}
        instances = _plugin_instances(spec, used - {None})
        if instances is not None:
            extra_parts.insert(0, instances)
        section = ET.Element("actuator")
        section.extend(carried_actuators)
        extra_parts.append(section)
    if extra_sensors:
        section = ET.Element("sensor")
        section.extend(extra_sensors)
        extra_parts.append(section)
    if model.nkey:
        extra_parts.append(_keyframes(model, keep, kept_actuators, rep))
    extra = None
    if extra_parts:
        root = ET.Element("mujoco")
        root.extend(extra_parts)
        ET.indent(root)
        extra = ET.tostring(root, encoding="unicode") + "\n"

    sim = SimulatorConfig(
        timestep=float(model.opt.timestep),
        gravity=_t3(model.opt.gravity),
        ground=None,
        integrator=_INTEGRATORS.get(int(model.opt.integrator)),
        option=option,
        flag=flag,
    )
    hrdf = HRDF(
        name=spec.modelname or path.stem,
        bodies=bodies,
        joints=joints,
        actuators=actuators,
        meshes=meshes,
        simple_geoms=simple,
        sites=sites,
        sensors=sensors,
        meta=Meta(simulator_config=sim, body_name_config=None, mjcf_size=nuser_from_model(model)),
        mjcf_extra=extra,
        root_dir=store.root,
        temp_assets=store.lifetime,
    )
    warn_massless_moving(hrdf, rep, '<body name="{}">')
    warnings = rep.finish(strict)
    return ParseResult(hrdf, warnings, str(path))
