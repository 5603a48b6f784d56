"""The proof of a conversion: the source and the result compiled by MuJoCo, every
per-object array of ``MjModel`` compared.

The fields are not a hand-picked list: every array attribute of ``mujoco.MjModel``
whose name starts with a family prefix (``body_``, ``jnt_``, ``dof_``, ``geom_``,
``site_``, ``actuator_``, ``sensor_``, ``tendon_``, ``eq_``, ``key_``) and whose first
dimension is that family's count (``nbody``, ``njnt``, ...) is compared, as the installed
MuJoCo defines them (MuJoCo 3.11 and 4.x have different sets), and every field of
``model.opt``. ``user`` arrays are among them (``body_user``, ``jnt_user``, ...).

Objects are matched by name, not index (a conversion may reorder them): first by the
name, or the name the parsers give an unnamed object (``body_3``, ``joint_5``, ...),
then the rest by structure: an unnamed geom, site or joint by its body, type and order
in that body; a degree of freedom by its joint and order in it; an unnamed actuator,
sensor, tendon, equality or keyframe by its type and order. Fields holding ids of other
objects (``jnt_bodyid``, ``geom_bodyid``, ``actuator_trnid``, ``sensor_objid``,
``eq_obj1id``, ...) are compared through that matching (the names they point at);
keyframe columns (``key_qpos``, ``key_qvel``, ``key_ctrl``, ``key_act``) through the
joints and actuators they belong to. Addresses and counts into other arrays (``*adr``,
``*num``), tree and bounding-volume bookkeeping, and ids of assets (meshes, materials,
plugins) are not compared: they follow from the rest. Values the compiler derives
from several objects (``body_subtreemass``, ``*_invweight0``, ``dof_M0``,
``actuator_acc0``, ``*length0``) are reported only when nothing else differs: a changed
mass changes the subtree mass of every ancestor, and the mass is the difference to name.

Tolerance: two values of one object's field agree when
``|a - b| <= RTOL * max(|a|, |b| over that object's field) + ATOL`` with ``RTOL = 1e-9``
and ``ATOL = 1e-12`` (the absolute floor: a zero inertia that compiles to 6e-36 is
zero). Integers and flags must be equal.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from pathlib import Path
from typing import TYPE_CHECKING

import mujoco
import numpy as np

from robotwright.errors import Problem
from robotwright.proof.families import (
    _collision_hulls,
    _contacts,
    _geom_order,
    _massless,
    _mesh_data,
    _plugin_keys,
    _plugin_text,
    _tendon_paths,
    _tensors,
)
from robotwright.proof.match import (
    _act_map,
    _dof_map,
    _match,
    _match_bodies,
    _qpos_map,
    _robot_bodies,
    _used_sizes,
)
from robotwright.proof.models import (
    result_model,
    source_model,
)
from robotwright.proof.notes import (
    _stem,
    as_problems,
    covered,  # noqa: F401
    uncovered,
)
from robotwright.proof.objects import (  # noqa: F401
    _EQ_FAMILY,
    _ID_FIELDS,
    _KEY_COLUMNS,
    _OBJ_FAMILY,
    _POLY_ID_FIELDS,
    _TRN_FAMILY,
    ATOL,
    FAMILIES,
    RTOL,
    Difference,
    _bad_rows,
    _diff,
    _fmt,
    _missing,
    _Side,
    fields,
    option_fields,
)

if TYPE_CHECKING:
    from robotwright.hrdf.model import HRDF


def compare_models(
    source: mujoco.MjModel,
    result: mujoco.MjModel,
    *,
    root_body: str | None = None,
    families: Iterable[str] | None = None,
    options: bool = True,
    geom_order: bool = True,
) -> list[Difference]:
    """Every difference between two compiled models (see the module docstring).

    ``root_body``: the top-level body of ``source`` that is the robot (the others are
    scene and not compared); ``None``: all of it. ``families``: the prefixes compared
    (default all of :data:`FAMILIES`); ``options``: compare ``model.opt`` too;
    ``geom_order``: compare the order of each body's geoms (contacts come in that order).
    """
    src, res, maps, cols = _matched(source, result, root_body)
    wanted = list(FAMILIES) if families is None else list(families)
    diffs: list[Difference] = []
    if options:
        diffs += _compare_options(source, result)
    src_fields, res_fields = fields(source), fields(result)
    for fam in wanted:
        # The world body is scene (its mass sums what the scene holds): not compared.
        m = {i: j for i, j in maps[fam].items() if fam != "body" or i != 0}
        diffs += _missing(src, res, fam, m)
        if not m:
            continue
        si = np.fromiter(m.keys(), dtype=int, count=len(m))
        ri = np.fromiter(m.values(), dtype=int, count=len(m))
        for attr in src_fields[fam]:
            if attr not in res_fields[fam]:
                continue
            a, b = getattr(source, attr), getattr(result, attr)
            if attr in _KEY_COLUMNS:
                a, b = _key_columns(a, b, cols[_KEY_COLUMNS[attr]])
            a, b = a[si], b[ri]
            if attr in _INERTIA_PAIRS.values():
                continue  # compared with its moments, as one tensor
            if attr in _INERTIA_PAIRS:
                quat = _INERTIA_PAIRS[attr]
                a = _tensors(a, getattr(source, quat)[si])
                b = _tensors(b, getattr(result, quat)[ri])
            elif attr in ("body_ipos", "body_invweight0"):
                # A body without mass or inertia has no centre of mass to place (MuJoCo
                # keeps the position it was given, or its geoms' centre, and computes
                # the inverse weight there).
                empty = _massless(source, si) & _massless(result, ri)
                b = np.where(empty.reshape((-1,) + (1,) * (b.ndim - 1)), a, b)
            elif attr.endswith("quat"):
                # q and -q are the same rotation.
                flip = (a.reshape(len(a), -1) * b.reshape(len(b), -1)).sum(axis=1) < 0
                b = np.where(flip.reshape((-1,) + (1,) * (b.ndim - 1)), -b, b)
            if attr == "actuator_plugin":
                a, b = _plugin_keys(source, a), _plugin_keys(result, b)
            if attr in ("geom_size", "site_size"):
                a, b = (
                    _used_sizes(a, getattr(source, attr[:-4] + "type")[si]),
                    _used_sizes(b, getattr(result, attr[:-4] + "type")[ri]),
                )
            if attr in _ID_FIELDS:
                a = _ids(a, maps[_ID_FIELDS[attr]])
            elif attr in _POLY_ID_FIELDS:
                a, b = _poly_ids(source, result, attr, si, ri, a, b, maps)
            if attr in _ID_FIELDS or attr in _POLY_ID_FIELDS:
                # An id of an object the result lacks: that absence is the difference
                # (reported as the missing object), not every id that points at it.
                gone = (np.asarray(a).reshape(len(a), -1) == -2).any(axis=1)
                b = np.where(gone.reshape((-1,) + (1,) * (np.ndim(b) - 1)), a, b)
            if a.shape[1:] != b.shape[1:]:
                diffs += [
                    _diff(
                        src,
                        fam,
                        attr,
                        int(s),
                        _fmt(getattr(source, attr)[s]),
                        _fmt(getattr(result, attr)[r]),
                    )  # fmt: skip
                    for s, r in zip(si, ri, strict=True)
                ]
                continue
            for row in _bad_rows(a, b):
                shown = (_fmt(a[row]), _fmt(b[row]))
                if attr == "actuator_plugin":  # the plugin and its configuration, not a key
                    shown = (
                        _plugin_text(source, int(source.actuator_plugin[si[row]])),
                        _plugin_text(result, int(result.actuator_plugin[ri[row]])),
                    )
                diffs.append(_diff(src, fam, attr, int(si[row]), *shown))
    if geom_order and "geom" in wanted:
        diffs += _geom_order(src, res, maps["geom"])
    if families is None:  # what simulates beyond the per-object arrays
        diffs += _contacts(src, res, maps)
        diffs += _tendon_paths(src, res, maps)
    if "geom" in wanted:
        diffs += _mesh_data(src, res, maps["geom"])
        diffs += _collision_hulls(src, res, maps["geom"])
    primary = [d for d in diffs if not _stem(d.field).endswith(_DERIVED)]
    # A derived value (a subtree mass, an inverse weight) differs because an input did:
    # that input is the difference to report; derived ones alone are reported as such.
    return primary if primary else diffs


def _matched(
    source: mujoco.MjModel, result: mujoco.MjModel, root_body: str | None
) -> tuple[_Side, _Side, dict[str, dict[int, int]], dict[str, dict[int, int]]]:
    """The two sides, the source's objects matched to the result's by family
    (``maps``), and the keyframe columns matched (``cols``: joint positions, degrees of
    freedom, actuators, activations)."""
    src = _Side(source, _robot_bodies(source, root_body))
    res = _Side(result, None)
    maps: dict[str, dict[int, int]] = {"body": _match_bodies(src, res)}
    for fam in ("jnt", "geom", "site", "actuator", "sensor", "tendon", "eq", "key"):
        maps[fam] = _match(src, res, fam, maps["body"])
    maps["dof"] = _dof_map(src, res, maps["jnt"])
    maps["cam"] = {}
    cols = {
        "qpos": _qpos_map(src, res, maps["jnt"]),
        "dof": maps["dof"],
        "actuator": maps["actuator"],
        "act": _act_map(src, res, maps["actuator"]),
    }
    return src, res, maps, cols


#: principal moments -> the rotation of their axes: compared as the one tensor they make
#: in the object's frame (MuJoCo orders and signs principal axes as its eigen-solver
#: returns them; an import and our writer may differ there and hold the same inertia).
_INERTIA_PAIRS = {"body_inertia": "body_iquat"}

#: values the compiler derives from the others (and from every body of a subtree).
_DERIVED = ("invweight0", "subtreemass", "M0", "acc0", "length0", "lengthrange")


def _key_columns(a: np.ndarray, b: np.ndarray, cmap: dict[int, int]) -> tuple:
    """A keyframe array's columns of the source and, in the same order, the result's."""
    if not cmap or a.ndim != 2:
        return a[:, :0], b[:, :0]
    s = np.fromiter(cmap.keys(), dtype=int)
    r = np.fromiter(cmap.values(), dtype=int)
    return a[:, s], b[:, r]


def _ids(a: np.ndarray, m: dict[int, int]) -> np.ndarray:
    """Source ids mapped to result ids (-2: no counterpart; negative ids kept)."""
    flat = a.reshape(-1)
    mapped = np.fromiter(
        (m.get(int(x), -2) if x >= 0 else int(x) for x in flat), dtype=int, count=flat.size
    )
    return mapped.reshape(a.shape)


def _poly_ids(source, result, attr, si, ri, a, b, maps) -> tuple[np.ndarray, np.ndarray]:
    type_attr = _POLY_ID_FIELDS[attr]
    ts = np.asarray(getattr(source, type_attr))[si]
    out = np.array(a, dtype=int, copy=True)
    for k in range(out.shape[0]):
        t = int(ts[k]) if ts.ndim == 1 else int(ts[k, 0])
        if attr == "actuator_trnid":
            fam = _TRN_FAMILY.get(t)
        elif attr.startswith("eq_"):
            fam = _OBJ_FAMILY.get(t) or _EQ_FAMILY.get(int(source.eq_type[si[k]]))
        else:
            fam = _OBJ_FAMILY.get(t)
        mp = maps.get(fam or "", {})
        row = out[k].reshape(-1)
        for c in range(row.size):
            if row[c] >= 0:
                row[c] = mp.get(int(row[c]), -2) if fam else row[c]
        out[k] = row.reshape(out[k].shape)
    return out, np.asarray(b, dtype=int)


def _compare_options(source: mujoco.MjModel, result: mujoco.MjModel) -> list[Difference]:
    out = []
    for attr in option_fields(source):
        if not hasattr(result.opt, attr):
            continue
        a = np.atleast_1d(np.asarray(getattr(source.opt, attr)))[None, :]
        b = np.atleast_1d(np.asarray(getattr(result.opt, attr)))[None, :]
        if a.shape != b.shape or _bad_rows(a, b).size:
            out.append(Difference(f"opt.{attr}", "opt", "<option>", _fmt(a[0]), _fmt(b[0])))
    return out


def prove(
    source: Path,
    kind: str,
    hrdf: HRDF,
    out_kind: str,
    notes: Sequence[str],
    *,
    options: dict | None = None,
    work_dir: Path | None = None,
    simulate: bool = False,
) -> list[Problem]:
    """The proof of converting ``source`` (``kind``: ``"mjcf"`` or ``"urdf"``) into
    ``hrdf`` and writing it as ``out_kind`` (``"hrdf"``, ``"mjcf"``, ``"urdf"``): one
    conversion note per difference that no note in ``notes`` reports (see
    :func:`as_problems`). Empty when MuJoCo does not compile the source.

    A URDF source is compared with MuJoCo's own import of it (every link a body, visual
    geoms discarded as that import does; the output compiled the same way). A URDF
    output is proved in two steps: the source against our MJCF of ``hrdf`` (what the
    robot holds), and MuJoCo's import of our URDF against that MJCF
    (:func:`robotwright.proof.urdf_output.prove_urdf_output`: what a URDF holds).

    ``simulate``: the source and the output are also stepped side by side
    (:mod:`robotwright.proof.rollout`; not with ``root_body``; a URDF source as MuJoCo
    imports it, the output without its visual geoms, as that import leaves them out)."""
    options = dict(options or {})
    from robotwright.generators.compiles import too_deep_for_mjcf

    deep = too_deep_for_mjcf(hrdf)
    if deep is not None:
        # The robot is written (HRDF and URDF files are flat), but MuJoCo cannot compile
        # an MJCF of it to compare with: say so instead of refusing the conversion.
        return [Problem(str(source), f"proof: not made: {deep}", severity="warning")]
    found: list[Problem] = []
    if out_kind == "urdf":
        # The URDF form against our MJCF of the same robot (what a URDF can hold), and
        # that MJCF against the source (what the robot holds) below.
        from robotwright.proof.urdf_output import prove_urdf_output

        found = prove_urdf_output(hrdf, str(source), notes)
        out_kind = "mjcf"
    if kind == "urdf" and options.get("fixed_joints", "keep") == "site":
        # Massless leaf links become sites, others stay bodies: MuJoCo's import has no
        # such choice to compare with (it keeps every link, or fuses every fixed one).
        return found
    src = source_model(source, kind, options)
    if src is None:
        return found
    res, written = result_model(hrdf, out_kind, work_dir, discard_visual=kind == "urdf", source=src)
    root = options.get("root_body")
    families = None
    if out_kind == "urdf" or kind == "urdf":
        # URDF has no sites, sensors, actuators, tendons, equalities or keyframes, and no
        # <option>: what the parser or generator drops of them is in its notes.
        families = ("body", "jnt", "dof", "geom")
    # A URDF has no geom order of its own (MuJoCo's import of it puts a link's geoms in
    # one order, a reader may pair visual and collision elements in another).
    diffs = compare_models(
        src,
        res,
        root_body=root,
        families=families,
        options=families is None,
        geom_order=kind != "urdf",
    )
    if simulate and root is None:
        from robotwright.proof.rollout import RolloutNotMade

        try:
            diffs += _rollouts(src, res) or []
        except RolloutNotMade as why:
            found.append(
                Problem(str(source), f"proof: simulation not compared: {why}", severity="warning")
            )
    return found + as_problems(str(source), uncovered(diffs, [*notes, *written]))


def _rollouts(source: mujoco.MjModel, result: mujoco.MjModel) -> list[Difference] | None:
    """The two models simulated side by side (:mod:`robotwright.proof.rollout`); None
    when they cannot be (:func:`~robotwright.proof.rollout.can_roll_out`). Raises
    :class:`~robotwright.proof.rollout.RolloutNotMade` where the source cannot be
    simulated (too many contacts at rest, or MuJoCo stops stepping it)."""
    from robotwright._mujoco_log import gathered
    from robotwright.proof.rollout import can_roll_out, rollout_differences

    _, _, maps, cols = _matched(source, result, None)
    if not can_roll_out(source, result, cols["qpos"], maps["actuator"]):
        return None
    # A source that goes unstable under the pseudo-random control makes MuJoCo warn at
    # each reset; that is the source's behaviour, which the output shares, not a note.
    with gathered():
        return rollout_differences(source, result, cols["qpos"], maps["actuator"])
