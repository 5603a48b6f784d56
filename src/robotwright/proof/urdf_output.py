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


def _bad_rows(a, b) -> np.ndarray:
    """Per row of ``a`` and ``b`` (``(n, k)``, or ``(n,)`` for one value a row): True where
    the rows differ beyond ``RTOL`` times the row's largest magnitude plus ``ATOL`` (NaN
    equals NaN). Whole families at once: a robot of thousands of links has hundreds of
    thousands of values to compare."""
    a = np.asarray(a, dtype=float)
    b = np.asarray(b, dtype=float)
    a = a.reshape(len(a), -1)
    b = b.reshape(len(b), -1)
    if a.shape != b.shape:
        return np.ones(len(a), dtype=bool)
    # fmax ignores NaN (as nanmax did) and never warns on a row of NaN.
    scale = np.fmax.reduce(np.abs(np.concatenate([a, b], axis=1)), axis=1, initial=0.0)
    with np.errstate(invalid="ignore"):
        ok = (np.abs(a - b) <= RTOL * scale[:, None] + ATOL) | (np.isnan(a) & np.isnan(b))
        ok |= a == b
    return ~ok.all(axis=1)


def _tensors(data: mujoco.MjData, model: mujoco.MjModel, ids: np.ndarray) -> np.ndarray:
    """World inertia tensors ``(n, 6)`` (xx, yy, zz, xy, xz, yz) of bodies ``ids``."""
    r = data.ximat[ids].reshape(-1, 3, 3)
    t = np.einsum("nij,nj,nkj->nik", r, model.body_inertia[ids], r)
    return np.stack(
        [t[:, 0, 0], t[:, 1, 1], t[:, 2, 2], t[:, 0, 1], t[:, 0, 2], t[:, 1, 2]], axis=1
    )


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
    # (object index, order of the check, difference): sorted at the end so that the
    # differences come object by object, each object's checks in the order below.
    found: list[tuple[int, int, Difference]] = []
    fam_word = {"body": "body", "jnt": "joint", "dof": "joint"}

    def flag(rank: int, field, fam, bad, rows, names, a, b) -> None:
        for k in np.flatnonzero(bad):
            name = names[k]
            labels = (f'"{name}"', f"'{name}'")
            found.append(
                (
                    int(rows[k]),
                    rank,
                    Difference(
                        field,
                        fam,
                        f"{fam_word[fam]} '{name}'",
                        _fmt(np.asarray(a[k])),
                        _fmt(np.asarray(b[k])),
                        labels,
                    ),  # fmt: skip
                )
            )

    body_of: dict[int, int] = {0: 0}
    pairs: list[tuple[int, int]] = []
    for i in range(1, mjcf.nbody):
        name = mjcf.body(i).name
        j = _id(urdf, mujoco.mjtObj.mjOBJ_BODY, name)
        if j < 0:
            labels = (f'"{name}"', f"'{name}'")
            found.append(
                (
                    i,
                    0,
                    Difference("(object)", "body", f"body '{name}'", "present", "absent", labels),
                )
            )
            continue
        body_of[i] = j
        pairs.append((i, j))
    if pairs:
        bi, bj = (np.array(x) for x in zip(*pairs))
        names = [mjcf.body(int(i)).name for i in bi]
        m_a, m_b = mjcf.body_mass[bi], urdf.body_mass[bj]
        flag(1, "body_mass", "body", _bad_rows(m_a, m_b), bi, names, m_a, m_b)
        p_a, p_b = dm.xpos[bi], du.xpos[bj]
        flag(2, "body_pos", "body", _bad_rows(p_a, p_b), bi, names, p_a, p_b)
        q_a, q_b = dm.xquat[bi], du.xquat[bj]
        flag(3, "body_quat", "body", _bad_rows(q_a, q_b) & _bad_rows(q_a, -q_b), bi, names,
             q_a, q_b)  # fmt: skip
        i_a, i_b = dm.xipos[bi], du.xipos[bj]
        flag(4, "body_ipos", "body", (m_a > 0) & _bad_rows(i_a, i_b), bi, names, i_a, i_b)
        t_a, t_b = _tensors(dm, mjcf, bi), _tensors(du, urdf, bj)
        flag(5, "body_inertia", "body", _bad_rows(t_a, t_b), bi, names, t_a, t_b)
    out = [d for _, _, d in sorted(found, key=lambda t: (t[0], t[1]))]
    found.clear()
    matched = set(body_of.values())
    for j in range(1, urdf.nbody):
        name = urdf.body(j).name
        if name not in added and j not in matched:
            labels = (f'"{name}"', f"'{name}'")
            out.append(
                Difference("(object)", "body", f"body '{name}'", "absent", "present", labels)
            )
    joints: list[tuple[int, int]] = []
    for i in range(mjcf.njnt):
        if mjcf.jnt_type[i] == mujoco.mjtJoint.mjJNT_FREE:
            # The URDF form has no free joint: the root link floats in MuJoCo's import
            # only when the URDF says so (the writer reports it).
            continue
        name = mjcf.joint(i).name
        j = _id(urdf, mujoco.mjtObj.mjOBJ_JOINT, name)
        if j < 0:
            labels = (f'"{name}"', f"'{name}'")
            found.append(
                (
                    i,
                    0,
                    Difference("(object)", "jnt", f"joint '{name}'", "present", "absent", labels),
                )
            )
            continue
        joints.append((i, j))
    if joints:
        ji, jj = (np.array(x) for x in zip(*joints))
        names = [mjcf.joint(int(i)).name for i in ji]
        rank = 1
        for f in _JOINT_FIELDS:
            if hasattr(mjcf, f):
                a, b = getattr(mjcf, f)[ji], getattr(urdf, f)[jj]
                flag(rank, f, "jnt", _bad_rows(a, b), ji, names, a, b)
            rank += 1
        a, b = dm.xanchor[ji], du.xanchor[jj]
        not_slide = mjcf.jnt_type[ji] != 2  # a slide's anchor may be anywhere
        flag(rank, "jnt_pos", "jnt", not_slide & _bad_rows(a, b), ji, names, a, b)
        a, b = dm.xaxis[ji], du.xaxis[jj]
        flag(rank + 1, "jnt_axis", "jnt", _bad_rows(a, b), ji, names, a, b)
        da, db = mjcf.jnt_dofadr[ji], urdf.jnt_dofadr[jj]
        for k, f in enumerate(_DOF_FIELDS):
            a, b = getattr(mjcf, f)[da], getattr(urdf, f)[db]
            flag(rank + 2 + k, f, "dof", _bad_rows(a, b), ji, names, a, b)
    out += [d for _, _, d in sorted(found, key=lambda t: (t[0], t[1]))]
    out += _compare_geoms(mjcf, urdf, dm, du, body_of)
    return out


def _geom_keys(model: mujoco.MjModel, data: mujoco.MjData) -> np.ndarray:
    """Per geom: type, world position, world rotation and the sizes its type uses."""
    size = _used_sizes(model.geom_size, model.geom_type)
    return np.concatenate([model.geom_type[:, None], data.geom_xpos, data.geom_xmat, size], axis=1)


def _compare_geoms(mjcf, urdf, dm, du, body_of: dict[int, int]) -> list[Difference]:
    # (geom, order of the check, difference): geom by geom, as the model lists them.
    found: list[tuple[int, int, Difference]] = []
    ours: dict[int, list[int]] = {}
    for g in range(urdf.ngeom):
        ours.setdefault(int(urdf.geom_bodyid[g]), []).append(g)
    keys_a, keys_b = _geom_keys(mjcf, dm), _geom_keys(urdf, du)
    pairs: list[tuple[int, int, str, tuple[str, ...]]] = []
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
        same = (
            np.flatnonzero(~_bad_rows(np.repeat(keys_a[g : g + 1], len(cands), 0), keys_b[cands]))
            if cands
            else ()
        )
        if not len(same):
            found.append((g, -1, Difference("(object)", "geom", obj, "present", "absent", labels)))
            continue
        pairs.append((g, cands.pop(int(same[0])), obj, labels))
    ga = np.array([p[0] for p in pairs], dtype=int)
    gb = np.array([p[1] for p in pairs], dtype=int)
    for rank, f in enumerate(_GEOM_CONTACT):
        if not pairs or not hasattr(mjcf, f):
            continue
        a, c = getattr(mjcf, f)[ga], getattr(urdf, f)[gb]
        for k in np.flatnonzero(_bad_rows(a, c)):
            _, _, obj, labels = pairs[k]
            found.append(
                (int(ga[k]), rank, Difference(f, "geom", obj, _fmt(a[k]), _fmt(c[k]), labels))
            )
    return [d for _, _, d in sorted(found, key=lambda t: (t[0], t[1]))]


def prove_urdf_output(hrdf, file: str, notes: Iterable[str] = ()) -> list:
    """The proof of writing ``hrdf`` as URDF (``file`` names it in the notes): our MJCF
    and MuJoCo's import of our URDF compared (:func:`compare_urdf_form`); one
    conversion note per difference that neither ``notes`` nor the URDF writer's own
    notes report. A URDF MuJoCo does not import is one note saying so."""
    import warnings
    from pathlib import Path

    from robotwright.errors import Problem
    from robotwright.generators import URDFHumanoidGenerator
    from robotwright.generators.compiles import too_deep_for_mjcf
    from robotwright.parsers.reference import compile_urdf, urdf_for_mujoco
    from robotwright.proof.models import _compile_with_same_files, _mesh_sources
    from robotwright.proof.notes import as_problems, uncovered
    from robotwright.proof.roundtrip.sides import our_mjcf_text

    deep = too_deep_for_mjcf(hrdf)
    if deep is not None:
        # The URDF is written (its file is flat), but there is no MJCF to compare it with.
        return [Problem(file, f"proof: not made: {deep}", severity="warning")]
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
