"""The proof of a URDF output: MuJoCo's import of our URDF against our MJCF of the same
robot, in every value a URDF can hold.

A URDF writes a robot in other terms than MJCF: a body with several joints becomes a
chain of dummy links (1e-9 kg each), a joint's anchor becomes its child link's origin, a
site a massless link, a capsule a cylinder and two spheres, a ball joint three hinges.
So the two models are compared where those terms agree, at their reference pose
(``qpos0``; our URDF bakes a joint's ``ref`` into its origin) and in the world frame:

- per body (by name; the links the URDF form adds left out): mass, world position and
  orientation, centre of mass (bodies with mass) and inertia tensor in the world frame;
- per joint (by name): type, world anchor and axis, whether limited, range, and per
  degree of freedom damping, friction loss and armature, stiffness, force range;
- per colliding geom (matched within its body by type, world pose and size): type,
  size, world pose and the contact fields (``friction``, ``condim``, ``contype``,
  ``conaffinity``, ``solref``, ``solimp``, ``margin``, ``gap``, ``priority``,
  ``solmix``), which URDF cannot hold.

Tolerance: :data:`RTOL` relative (the URDF text writes rotations as roll-pitch-yaw),
:data:`robotwright.proof.objects.ATOL` absolute. Each difference that no note of the
URDF writer reports becomes a note (:func:`robotwright.proof.notes.as_problems`).
"""

from __future__ import annotations

from collections.abc import Iterable

import mujoco
import numpy as np

from robotwright.proof.match import _used_sizes
from robotwright.proof.objects import ATOL, Difference, _fmt

#: relative tolerance of the URDF form (as the round trip's URDF rows).
RTOL = 1e-6

_JOINT_FIELDS = ("jnt_type", "jnt_limited", "jnt_range", "jnt_stiffness", "jnt_actfrclimited",
                 "jnt_actfrcrange")  # fmt: skip
_DOF_FIELDS = ("dof_damping", "dof_frictionloss", "dof_armature")
_GEOM_CONTACT = ("geom_friction", "geom_condim", "geom_contype", "geom_conaffinity",
                 "geom_solref", "geom_solimp", "geom_margin", "geom_gap", "geom_priority",
                 "geom_solmix")  # fmt: skip


def _bad(a, b) -> bool:
    a = np.atleast_1d(np.asarray(a, dtype=float)).ravel()
    b = np.atleast_1d(np.asarray(b, dtype=float)).ravel()
    if a.shape != b.shape:
        return True
    both_nan = np.isnan(a) & np.isnan(b)
    with np.errstate(invalid="ignore"):
        scale = max(float(np.nanmax(np.abs(np.concatenate([a, b])), initial=0.0)), 0.0)
        ok = (np.abs(a - b) <= RTOL * scale + ATOL) | both_nan | (a == b)
    return not bool(ok.all())


def _quat_bad(a, b) -> bool:
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    return _bad(a, b) and _bad(a, -b)


def _tensor(data: mujoco.MjData, model: mujoco.MjModel, i: int) -> np.ndarray:
    r = data.ximat[i].reshape(3, 3)
    t = r @ np.diag(model.body_inertia[i]) @ r.T
    return np.array([t[0, 0], t[1, 1], t[2, 2], t[0, 1], t[0, 2], t[1, 2]])


def _id(model: mujoco.MjModel, obj: mujoco.mjtObj, name: str) -> int:
    return mujoco.mj_name2id(model, obj, name) if name else -1


def compare_urdf_form(
    mjcf: mujoco.MjModel, urdf: mujoco.MjModel, added_links: Iterable[str] = ()
) -> list[Difference]:
    """Every difference between our MJCF (``mjcf``, compiled with visual geoms
    discarded, as MuJoCo's URDF import does) and MuJoCo's import of our URDF
    (``urdf``) of one robot; ``added_links``: the links the URDF form adds (dummy and
    site links), not compared."""
    added = set(added_links)
    dm, du = mujoco.MjData(mjcf), mujoco.MjData(urdf)
    # The same joint coordinates on both sides: our URDF bakes a joint's ref into its
    # origin, so MJCF's reference pose is the URDF at q = ref.
    for i in range(mjcf.njnt):
        if int(mjcf.jnt_type[i]) in (2, 3):  # slide, hinge
            j = _id(urdf, mujoco.mjtObj.mjOBJ_JOINT, mjcf.joint(i).name)
            if j >= 0 and int(urdf.jnt_type[j]) == int(mjcf.jnt_type[i]):
                du.qpos[urdf.jnt_qposadr[j]] = mjcf.qpos0[mjcf.jnt_qposadr[i]]
    mujoco.mj_kinematics(mjcf, dm)
    mujoco.mj_kinematics(urdf, du)
    out: list[Difference] = []

    def diff(field, fam, obj, labels, a, b) -> None:
        out.append(Difference(field, fam, obj, _fmt(np.asarray(a)), _fmt(np.asarray(b)), labels))

    body_of: dict[int, int] = {0: 0}
    for i in range(1, mjcf.nbody):
        name = mjcf.body(i).name
        obj, labels = f"body '{name}'", (f'"{name}"', f"'{name}'")
        j = _id(urdf, mujoco.mjtObj.mjOBJ_BODY, name)
        if j < 0:
            out.append(Difference("(object)", "body", obj, "present", "absent", labels))
            continue
        body_of[i] = j
        if _bad(mjcf.body_mass[i], urdf.body_mass[j]):
            diff("body_mass", "body", obj, labels, mjcf.body_mass[i], urdf.body_mass[j])
        if _bad(dm.xpos[i], du.xpos[j]):
            diff("body_pos", "body", obj, labels, dm.xpos[i], du.xpos[j])
        if _quat_bad(dm.xquat[i], du.xquat[j]):
            diff("body_quat", "body", obj, labels, dm.xquat[i], du.xquat[j])
        if mjcf.body_mass[i] > 0 and _bad(dm.xipos[i], du.xipos[j]):
            diff("body_ipos", "body", obj, labels, dm.xipos[i], du.xipos[j])
        a, b = _tensor(dm, mjcf, i), _tensor(du, urdf, j)
        if _bad(a, b):
            diff("body_inertia", "body", obj, labels, a, b)
    for j in range(1, urdf.nbody):
        name = urdf.body(j).name
        if name not in added and j not in body_of.values():
            labels = (f'"{name}"', f"'{name}'")
            out.append(
                Difference("(object)", "body", f"body '{name}'", "absent", "present", labels)
            )
    for i in range(mjcf.njnt):
        name = mjcf.joint(i).name
        obj, labels = f"joint '{name}'", (f'"{name}"', f"'{name}'")
        if mjcf.jnt_type[i] == mujoco.mjtJoint.mjJNT_FREE:
            # The URDF form has no free joint: the root link floats in MuJoCo's import
            # only when the URDF says so (the writer reports it).
            continue
        j = _id(urdf, mujoco.mjtObj.mjOBJ_JOINT, name)
        if j < 0:
            out.append(Difference("(object)", "jnt", obj, "present", "absent", labels))
            continue
        for f in _JOINT_FIELDS:
            if hasattr(mjcf, f) and _bad(getattr(mjcf, f)[i], getattr(urdf, f)[j]):
                diff(f, "jnt", obj, labels, getattr(mjcf, f)[i], getattr(urdf, f)[j])
        if int(mjcf.jnt_type[i]) != 2 and _bad(dm.xanchor[i], du.xanchor[j]):  # (a slide: any)
            diff("jnt_pos", "jnt", obj, labels, dm.xanchor[i], du.xanchor[j])
        if _bad(dm.xaxis[i], du.xaxis[j]):
            diff("jnt_axis", "jnt", obj, labels, dm.xaxis[i], du.xaxis[j])
        a, b = int(mjcf.jnt_dofadr[i]), int(urdf.jnt_dofadr[j])
        for f in _DOF_FIELDS:
            if _bad(getattr(mjcf, f)[a], getattr(urdf, f)[b]):
                diff(f, "dof", obj, labels, getattr(mjcf, f)[a], getattr(urdf, f)[b])
    out += _compare_geoms(mjcf, urdf, dm, du, body_of)
    return out


def _geom_key(model: mujoco.MjModel, data: mujoco.MjData, g: int) -> np.ndarray:
    size = _used_sizes(model.geom_size[g : g + 1], model.geom_type[g : g + 1])[0]
    return np.concatenate([[model.geom_type[g]], data.geom_xpos[g], data.geom_xmat[g], size])


def _compare_geoms(mjcf, urdf, dm, du, body_of: dict[int, int]) -> list[Difference]:
    out: list[Difference] = []
    ours: dict[int, list[int]] = {}
    for g in range(urdf.ngeom):
        ours.setdefault(int(urdf.geom_bodyid[g]), []).append(g)
    for g in range(mjcf.ngeom):
        b = int(mjcf.geom_bodyid[g])
        if b == 0 or b not in body_of:
            continue  # the world's geoms are scene; a missing body is reported
        bname = mjcf.body(b).name
        name = mjcf.geom(g).name
        obj = f"geom '{name}'" if name else f"geom #{g} of body '{bname}'"
        labels = tuple(x for x in (f'"{name}"', f"'{name}'") if name) + (
            f'geom #{g} of body "{bname}"',
            f"geom on '{bname}'",
        )
        cands = ours.get(body_of[b], [])
        key = _geom_key(mjcf, dm, g)
        same = [k for k, h in enumerate(cands) if not _bad(key, _geom_key(urdf, du, h))]
        if not same:
            out.append(Difference("(object)", "geom", obj, "present", "absent", labels))
            continue
        h = cands.pop(same[0])
        for f in _GEOM_CONTACT:
            if hasattr(mjcf, f) and _bad(getattr(mjcf, f)[g], getattr(urdf, f)[h]):
                a, c = getattr(mjcf, f)[g], getattr(urdf, f)[h]
                out.append(Difference(f, "geom", obj, _fmt(a), _fmt(c), labels))
    return out


def prove_urdf_output(hrdf, file: str, notes: Iterable[str] = ()) -> list:
    """The proof of writing ``hrdf`` as URDF (``file`` names it in the notes): our MJCF
    and MuJoCo's import of our URDF compared (:func:`compare_urdf_form`); one
    conversion note per difference that neither ``notes`` nor the URDF writer's own
    notes report. A URDF MuJoCo does not import is one note saying so."""
    import warnings
    from pathlib import Path

    from robotwright.errors import Problem
    from robotwright.generators import URDFHumanoidGenerator
    from robotwright.parsers.reference import compile_urdf, urdf_for_mujoco
    from robotwright.proof.models import _compile_with_same_files, _mesh_sources
    from robotwright.proof.notes import as_problems, uncovered
    from robotwright.proof.roundtrip.sides import our_mjcf_text

    gen = URDFHumanoidGenerator.from_hrdf(hrdf)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        root = gen.generate(relative_mesh_path=False)
    text = urdf_for_mujoco(Path(f"{hrdf.name}.urdf"), root=root)
    added = set(gen.dummy_links) | set(gen.frame_links.values())
    try:
        urdf = compile_urdf(text)
    except ValueError as exc:
        first = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
        return [Problem(file, f"proof: MuJoCo does not import the URDF: {first}",
                        severity="warning")]  # fmt: skip
    originals = _mesh_sources(hrdf)
    mjcf = _compile_with_same_files(our_mjcf_text(hrdf), originals, discard_visual=True)
    # A writer reports its losses in one note of many lines: each line is one report.
    lines = [line for n in [*notes, *(str(w.message) for w in caught)] for line in n.splitlines()]
    found = uncovered(compare_urdf_form(mjcf, urdf, added), lines)
    return as_problems(file, found, ("our MJCF", "MuJoCo's import of our URDF"))
