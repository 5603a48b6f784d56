"""OpenUSD -> HRDF: a robot written for Isaac Lab or Newton, read by Newton's USD importer.

Newton's ``ModelBuilder.add_usd`` reads the physics (rigid bodies with their mass,
centre of mass and inertia tensor; joints with their frames, axes, limits, armature,
friction and damping; collision shapes, visual shapes and sites, meshes included).
From that an MJCF is built with MuJoCo's ``MjSpec`` and read by the MJCF parser, so the
robot arrives as every MJCF does. What comes back from the prims themselves:

* names: each body, joint, geom and site is named after its prim (the last element of
  the prim path; a name used twice gets ``_2``, ``_3``, ... and a note); a floating
  body's free joint after ``robotwright:freeJointName`` where ``robotwright export``
  wrote it (else it is unnamed, noted);
* actuators: ``MjcActuator`` prims (written by ``mujoco-usd-converter`` and by
  ``robotwright export``) in prim order, with their names, gains, biases and ranges.
  A USD without them gets one actuator per driven joint from its ``PhysicsDriveAPI``
  (stiffness -> position actuator ``kp``, damping -> ``kv``, max force -> force range;
  noted);
* the velocity limit (``newton:velocityLimit`` / ``physxJoint:maxJointVelocity``) as the
  HRDF actuator's ``peak_velocity``.

Values are USD's single-precision floats: a robot exported and read back differs from
its source by float32 rounding (1e-7 relative).

Containment: before Newton opens the file, every layer it would compose (sublayers,
references, payloads) and every asset path in them must lie inside the file's folder
(or a trusted ``asset_roots`` folder); each layer is opened alone to list them.

Needs Newton and usd-core (Isaac Lab's environment: ``pip install "robotwright[isaaclab]"``
on Python 3.12).
"""

from __future__ import annotations

import functools
import hashlib
import os
import tempfile
import warnings
from collections import Counter
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import mujoco
import numpy as np

from robotwright._names import file_stem, shown
from robotwright._paths import check_regular
from robotwright._rotations import compose_pose
from robotwright._temporaries import prefix
from robotwright._usd_format import FREE_JOINT_ATTR, USD_SUFFIXES, prim_name
from robotwright._usd_names import display_names, joint_dof_prims, name_of
from robotwright.errors import ConversionError, InputFileError, Problem, UnsafePathError
from robotwright.parsers.report import ParseResult, Reporter

__all__ = ["USD_SUFFIXES", "USDOptions", "parse_usd", "prepare_confined_read"]


_MISSING = (
    "reading USD needs Newton and usd-core (Python 3.12, as Isaac Lab: pip install "
    "'robotwright[usd]', or 'robotwright[isaaclab]' in Isaac Lab's environment); not "
    "importable here: {error}"
)
#: Newton's limits at or beyond this magnitude mean "unlimited".
_UNLIMITED = 1e5


@dataclass(frozen=True)
class USDOptions:
    """How a USD file is read.

    Attributes:
        work_dir: folder where meshes are staged (default: a new temp folder).
        asset_roots: folders outside the file's folder that its layers and assets may
            point into.
    """

    work_dir: Path | None = None
    asset_roots: tuple[str | os.PathLike, ...] = ()


def _newton(file: str = "") -> Any:
    try:
        from robotwright._warp import quiet_warp

        quiet_warp()  # before Newton initialises warp
        import newton
        from pxr import Sdf, Usd  # noqa: F401
    except ImportError as exc:
        raise ConversionError([Problem(file, _MISSING.format(error=exc))]) from None
    return newton


@functools.cache
def prepare_confined_read() -> None:
    """Load, in this process, the warp kernels that Newton's USD import and the proof
    run, by building and posing a small model with a mesh; a confined reader forked
    afterwards has them in memory. It cannot load them itself: it may not read warp's
    kernel cache, and must not write it (a reader could plant code there). Does nothing
    where Newton is not installed (the reader then says what to install)."""
    try:
        newton = _newton()
    except ConversionError:
        return
    box = np.array([[x, y, z] for x in (0, 1) for y in (0, 1) for z in (0, 1)], dtype=np.float32)
    faces = np.array(
        [0, 1, 3, 0, 3, 2, 4, 6, 7, 4, 7, 5, 0, 4, 5, 0, 5, 1,
         2, 3, 7, 2, 7, 6, 0, 2, 6, 0, 6, 4, 1, 5, 7, 1, 7, 3],
        dtype=np.int32,
    )  # fmt: skip
    builder = newton.ModelBuilder()
    body = builder.add_link(mass=1.0)
    builder.add_shape_mesh(body, mesh=newton.Mesh(box, faces))
    builder.add_shape_box(body, hx=0.1, hy=0.1, hz=0.1)
    builder.add_joint_revolute(-1, body, axis=(0.0, 0.0, 1.0))
    model = builder.finalize(device="cpu")
    newton.eval_fk(model, model.joint_q, model.joint_qd, model.state())


# -- containment ----------------------------------------------------------------------


def check_usd_dependencies(path: Path, roots: list[Path]) -> None:
    """Refuse a layer or asset path of ``path`` (followed through every layer it
    composes) that resolves outside ``roots``; each layer is opened on its own, never
    composed, so nothing outside is read.

    Raises:
        InputFileError: naming the layer, the path and where it points.
    """
    from pxr import Sdf, UsdUtils

    seen: set[Path] = set()
    todo = [path.resolve()]
    while todo:
        layer_path = todo.pop()
        if layer_path in seen:
            continue
        seen.add(layer_path)
        try:  # usd-core opens it with a blocking open(): a FIFO would hang the reader
            check_regular(layer_path)
        except UnsafePathError as exc:
            raise InputFileError(layer_path, exc.reason) from None
        if Sdf.Layer.FindOrOpen(str(layer_path)) is None:
            raise InputFileError(layer_path, "usd-core cannot read this file as a USD layer")
        sub, refs, payloads = UsdUtils.ExtractExternalReferences(str(layer_path))
        for asset in [*sub, *refs, *payloads]:
            text = str(asset)
            if not text or text.startswith("@"):
                continue
            if "://" in text or text.startswith("anon:"):
                raise InputFileError(
                    layer_path, f"asset path {shown(text)}: only files inside the folder are read"
                )
            target = (layer_path.parent / text).resolve()
            if not any(target.is_relative_to(r) for r in roots):
                raise InputFileError(
                    layer_path,
                    f"asset path {shown(text)} points outside the file's folder ({target}); "
                    "trust its folder with --asset-root to read it",
                )
            if target.suffix.lower() in (*USD_SUFFIXES, ".usdz"):
                todo.append(target)  # a layer: its own paths are checked in turn


# -- reading --------------------------------------------------------------------------


class _Names:
    """Unique MJCF names per kind from the names prims show (their ``displayName``
    where one is authored, as converters keep a name a prim cannot have, else the prim's
    name; a repeat gets ``_2``, ``_3``...)."""

    def __init__(self, shown: dict[str, str] | None = None) -> None:
        self.shown = shown or {}
        self.used: dict[str, Counter[str]] = {}
        self.renamed: dict[str, list[tuple[str, str]]] = {}

    def __call__(self, kind: str, label: str) -> str:
        base = name_of(self.shown, label) or kind
        used = self.used.setdefault(kind, Counter())
        used[base] += 1
        if used[base] == 1:
            return base
        name = f"{base}_{used[base]}"
        while used[name]:
            name += "_"
        used[name] += 1
        self.renamed.setdefault(kind, []).append((label, name))
        return name

    def report(self, rep: Reporter) -> None:
        """Renamed bodies, joints and actuators one line each; geoms and sites (which
        converters often name after their mesh) one line per kind; mesh assets (file
        names) not at all."""
        for kind, pairs in self.renamed.items():
            if kind in ("body", "joint", "actuator"):
                for label, name in pairs:
                    rep.warn(
                        f"{kind} name {shown(name_of(self.shown, label))} is used by several prims; {label} "
                        f"becomes {shown(name)}"
                    )
            elif kind != "mesh":
                listed = ", ".join(f"{label} -> {shown(name)}" for label, name in pairs[:3])
                rep.warn(
                    f"{len(pairs)} {kind}(s) share a prim name with another and get a "
                    f"suffix: {listed}{', ...' if len(pairs) > 3 else ''}"
                )


def _pose(t: Any) -> tuple[np.ndarray, np.ndarray]:
    """(pos, wxyz quaternion) of a warp transform (xyz, xyzw)."""
    v = np.asarray([float(x) for x in t], dtype=np.float64)
    return v[:3], np.array([v[6], v[3], v[4], v[5]])


def _inverse(t: tuple) -> tuple[np.ndarray, np.ndarray]:
    quat, pos = np.empty(4), np.empty(3)
    mujoco.mju_negQuat(quat, t[1])
    mujoco.mju_rotVecQuat(pos, -t[0], quat)
    return pos, quat


def _rotate(quat: np.ndarray, v: Any) -> np.ndarray:
    out = np.empty(3)
    mujoco.mju_rotVecQuat(out, np.asarray([float(x) for x in v], dtype=np.float64), quat)
    return out


class _Builder:
    """Newton's builder of one USD file -> an MjSpec (bodies, joints, geoms, sites)."""

    def __init__(
        self, newton: Any, nb: Any, stage: Any, rep: Reporter, mesh_dir: Path, found: dict
    ) -> None:
        self.newton, self.nb, self.stage, self.rep, self.mesh_dir = newton, nb, stage, rep, mesh_dir
        self._xforms: Any = None  # pxr's cache of world transforms, made when first needed
        self.order = {str(p.GetPath()): i for i, p in enumerate(stage.Traverse())}
        self.unread: Counter[str] = Counter()
        self.names = _Names(display_names(stage))
        # Newton joint -> the prim of each of its axes (a D6 merged from several prims).
        self.dof_prims = joint_dof_prims(found.get("path_joint_map", {}), stage)
        self.prim_joint: dict[str, str] = {}  # joint prim -> MJCF joint
        self.spec = mujoco.MjSpec()
        self.spec.compiler.autolimits = True
        self.spec.compiler.degree = False  # Newton gives radians
        self.spec.compiler.inertiafromgeom = mujoco.mjtInertiaFromGeom.mjINERTIAFROMGEOM_FALSE
        self.joint_names: dict[int, str] = {}  # Newton joint -> first MJCF joint
        self.dof_joint: dict[int, str] = {}  # Newton dof -> MJCF joint
        self.meshes: dict[tuple, str] = {}
        self.by_child: dict[int, int] = {}  # Newton body -> the joint whose child it is

    def build(self) -> mujoco.MjSpec:
        nb = self.nb
        self.by_child = by_child = {int(c): j for j, c in enumerate(nb.joint_child)}
        children: dict[int, list[int]] = {}
        for b in range(nb.body_count):
            j = by_child.get(b)
            parent = int(nb.joint_parent[j]) if j is not None else -1
            children.setdefault(parent, []).append(b)
        for b in children.get(-1, []):
            self._body(self.spec.worldbody, b, by_child.get(b), children)
        world = [s for s in range(nb.shape_count) if int(nb.shape_body[s]) == -1]
        if world:
            labels = ", ".join(prim_name(nb.shape_label[s]) for s in world[:5])
            self.rep.warn(
                f"{len(world)} shape(s) of the world, not of a body ({labels}): a robot file "
                "holds the robot only; not carried"
            )
        return self.spec

    def _body(self, parent_spec: Any, b: int, j: int | None, children: dict) -> None:
        nb, newton = self.nb, self.newton
        JT = newton.JointType
        jtype = int(nb.joint_type[j]) if j is not None else None
        if j is None or jtype == int(JT.FREE):
            pose = _pose(nb.body_q[b])  # a free or unjointed body: where it starts
        else:
            pose = compose_pose(*_pose(nb.joint_X_p[j]), *_inverse(_pose(nb.joint_X_c[j])))
        name = self.names("body", nb.body_label[b])
        body = parent_spec.add_body(name=name, pos=pose[0], quat=pose[1])
        inertia = np.asarray(nb.body_inertia[b], dtype=np.float64).reshape(3, 3)
        body.mass = float(nb.body_mass[b])
        body.ipos = np.asarray([float(x) for x in nb.body_com[b]])
        if inertia.any():
            body.fullinertia = [
                inertia[0, 0], inertia[1, 1], inertia[2, 2],
                inertia[0, 1], inertia[0, 2], inertia[1, 2],
            ]  # fmt: skip
        else:  # a massless frame (MuJoCo refuses an all-zero full inertia, not a diagonal)
            body.inertia = [0.0, 0.0, 0.0]
        body.explicitinertial = True
        self._mjc(body, nb.body_label[b], {"mjc:body:gravcomp": "gravcomp"})
        if j is not None:
            self._joints(body, j, jtype)
        for s in sorted(
            (s for s in range(nb.shape_count) if int(nb.shape_body[s]) == b),
            key=lambda s: self.order.get(nb.shape_label[s], s),
        ):  # prim order (Newton reads colliders before visuals): contact order is kept
            self._shape(body, s)
        for child in children.get(b, []):
            self._body(body, child, self.by_child.get(child), children)

    def _joints(self, body: Any, j: int, jtype: int) -> None:
        nb, JT = self.nb, self.newton.JointType
        label = nb.joint_label[j]
        if jtype == int(JT.FIXED):
            return
        if jtype == int(JT.FREE):
            if self.stage.GetPrimAtPath(label) if label.startswith("/") else None:
                self.joint_names[j] = name = self.names("joint", label)
                body.add_freejoint(name=name)
            elif named := _attr(self.stage.GetPrimAtPath(nb.body_label[int(nb.joint_child[j])]),
                                FREE_JOINT_ATTR):  # fmt: skip
                self.joint_names[j] = name = self.names("joint", str(named))
                body.add_freejoint(name=name)
            else:  # a floating articulation: USD has no joint prim, so no name
                body.add_freejoint()
                self.rep.warn(
                    f"body {shown(body.name)} floats: USD holds no free joint prim, so the free "
                    "joint's name is not in the file; left unnamed"
                )
            return
        anchor = _pose(nb.joint_X_c[j])
        d0 = int(nb.joint_qd_start[j])
        lin, ang = (int(x) for x in nb.joint_dof_dim[j])
        if jtype == int(JT.BALL):
            kinds = [mujoco.mjtJoint.mjJNT_BALL]
        elif jtype in (int(JT.REVOLUTE), int(JT.PRISMATIC), int(JT.D6)):
            kinds = [mujoco.mjtJoint.mjJNT_SLIDE] * lin + [mujoco.mjtJoint.mjJNT_HINGE] * ang
        else:
            raise ConversionError(
                [
                    Problem(
                        self.rep.file,
                        f"Newton joint type {jtype} has no MuJoCo joint",
                        element=label,
                    )
                ]
            )
        prims = self.dof_prims.get(j, [])
        for k, kind in enumerate(kinds):
            d = d0 + k
            if len(kinds) == 1:
                name = self.names("joint", label)
            elif len(prims) == len(kinds):  # each axis after the prim it was authored on
                name = self.names("joint", prims[k])
                self.prim_joint[prims[k]] = name
            else:  # one multi-axis prim: its axes numbered
                name = self.names("joint", f"{name_of(self.names.shown, label)}_{k}")
            self.joint_names.setdefault(j, name)
            joint = body.add_joint(name=name, type=kind, pos=anchor[0])
            if kind != mujoco.mjtJoint.mjJNT_BALL:
                joint.axis = _rotate(anchor[1], nb.joint_axis[d])
                lo, hi = float(nb.joint_limit_lower[d]), float(nb.joint_limit_upper[d])
                if abs(lo) < _UNLIMITED and abs(hi) < _UNLIMITED and lo <= hi:
                    joint.range = [lo, hi]
                    joint.limited = mujoco.mjtLimited.mjLIMITED_TRUE
                else:
                    joint.limited = mujoco.mjtLimited.mjLIMITED_FALSE
            joint.armature = float(nb.joint_armature[d])
            joint.frictionloss = float(nb.joint_friction[d])
            joint.damping[0] = float(nb.joint_damping[d])
            self._mjc(joint, label, _JOINT_ATTRS, kind == mujoco.mjtJoint.mjJNT_HINGE)
            self.dof_joint[d] = name

    def _shape(self, body: Any, s: int) -> None:
        nb, GT, flags = self.nb, self.newton.GeoType, self.newton.ShapeFlags
        gtype, label = int(nb.shape_type[s]), nb.shape_label[s]
        scale = np.asarray([float(x) for x in nb.shape_scale[s]])
        pos, quat = _pose(nb.shape_transform[s])
        f = int(nb.shape_flags[s])
        kinds = {
            int(GT.SPHERE): (mujoco.mjtGeom.mjGEOM_SPHERE, scale[:1]),
            int(GT.CAPSULE): (mujoco.mjtGeom.mjGEOM_CAPSULE, scale[:2]),
            int(GT.CYLINDER): (mujoco.mjtGeom.mjGEOM_CYLINDER, scale[:2]),
            int(GT.BOX): (mujoco.mjtGeom.mjGEOM_BOX, scale[:3]),
            int(GT.ELLIPSOID): (mujoco.mjtGeom.mjGEOM_ELLIPSOID, scale[:3]),
            int(GT.PLANE): (mujoco.mjtGeom.mjGEOM_PLANE, np.array([*scale[:2], 1.0])),
            int(GT.MESH): (mujoco.mjtGeom.mjGEOM_MESH, None),
            int(GT.CONVEX_MESH): (mujoco.mjtGeom.mjGEOM_MESH, None),
        }
        if gtype not in kinds:
            self.rep.warn(f"shape of Newton type {gtype} has no MuJoCo geom; not carried", label)
            return
        kind, size = kinds[gtype]
        if f & int(flags.SITE):
            if kind == mujoco.mjtGeom.mjGEOM_MESH:
                self.rep.warn("a mesh site has no MuJoCo site; not carried", label)
                return
            site = body.add_site(name=self.names("site", label), type=kind, pos=pos, quat=quat)
            site.size[: len(size)] = size
            self._mjc(site, label, _SITE_ATTRS)
            return
        if size is None:
            scale, quat = self._mirror_kept(s, scale, quat)
        geom = body.add_geom(name=self.names("geom", label), type=kind, pos=pos, quat=quat)
        if size is not None:
            geom.size[: len(size)] = size
        else:
            geom.meshname = self._mesh(s, scale)
        if not f & int(flags.COLLIDE_SHAPES):
            geom.contype = geom.conaffinity = 0
        self._mjc(geom, label, _GEOM_ATTRS)
        geom.friction = [
            float(nb.shape_material_mu[s]),
            float(nb.shape_material_mu_torsional[s]),
            float(nb.shape_material_mu_rolling[s]),
        ]
        color = nb.shape_color[s] if s < len(nb.shape_color) else None
        if color is not None:
            opacity = float(nb.shape_opacity[s]) if s < len(nb.shape_opacity) else 1.0
            geom.rgba = [*(float(c) for c in color), opacity]

    def _mjc(self, obj: Any, label: str, table: dict, hinge: bool = False) -> None:
        """MuJoCo's own attributes (``mjc:*``, as mujoco-usd-converter authors them) of
        the prim ``label`` onto ``obj``; any other authored ``mjc:`` attribute is counted
        for one note per name (see :meth:`report_unread`)."""
        prim = self.stage.GetPrimAtPath(label) if label.startswith("/") else None
        if not prim:
            return
        for attr in prim.GetAttributes():
            name = attr.GetName()
            if not name.startswith("mjc:") or not attr.HasAuthoredValue():
                continue
            key = name.rsplit(":", 1)[0] if name.endswith((":min", ":max")) else name
            if key in _READ_BY_NEWTON:
                continue
            field = table.get(key)
            if field is None:
                self.unread[name] += 1
                continue
            value = attr.Get()
            if key in ("mjc:ref", "mjc:springref") and hinge and value:
                self.unread[f"{name} (hinge angle: unit not stated)"] += 1
                continue
            if name.endswith((":min", ":max")):
                getattr(obj, field)[int(name.endswith(":max"))] = float(value)
            elif isinstance(value, str):  # a limited token: true / false / auto
                setattr(obj, field, getattr(mujoco.mjtLimited, "mjLIMITED_" + value.upper()))
            elif hasattr(value, "__len__"):
                arr = getattr(obj, field)
                arr[: len(value)] = list(value)[: len(arr)]
            else:
                current = getattr(obj, field)
                if isinstance(current, np.ndarray):  # MuJoCo >= 3.5 keeps polynomials
                    current[0] = float(value)
                else:
                    setattr(obj, field, type(current)(value))

    def report_unread(self) -> None:
        for name, n in sorted(self.unread.items()):
            self.rep.warn(f"{name} on {n} prim(s): not carried")

    def _mirror_kept(
        self, s: int, scale: np.ndarray, quat: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray]:
        """A mesh shape's scale and orientation in its body, its mirror kept as authored.

        Newton folds a collision mesh's mirror into its scale and rotation (``1 -1 1``
        reads as ``-1 -1 -1`` turned half a turn: the same mesh, another frame), and
        splits a visual mesh's transform into a rotation and positive scales, which loses
        the mirror. Where the prim's transform in its body is a rotation times its own
        authored scale, that scale and rotation are taken (the source's, as written);
        otherwise, where the prim mirrors and Newton's scale does not, the scale is
        negated and the rotation taken from the USD to match."""
        label = self.nb.shape_label[s]
        prim = self.stage.GetPrimAtPath(label) if label.startswith("/") else None
        if not prim:
            return scale, quat
        from pxr import UsdGeom

        authored = np.ones(3)
        for op in UsdGeom.Xformable(prim).GetOrderedXformOps():
            if op.GetOpType() == UsdGeom.XformOp.TypeScale:
                authored = authored * np.asarray(op.Get(), dtype=float)
        if np.all(authored > 0) and np.prod(scale) > 0:
            return scale, quat  # no mirror anywhere: Newton's reading as it is
        if self._xforms is None:
            self._xforms = UsdGeom.XformCache()
        # Gf matrices act on row vectors: the transpose is the usual linear map.
        linear = np.array(self._xforms.GetLocalToWorldTransform(prim), dtype=float)[:3, :3].T
        b = int(self.nb.shape_body[s])
        body_prim = self.stage.GetPrimAtPath(self.nb.body_label[b]) if b >= 0 else None
        if body_prim:
            frame = np.array(self._xforms.GetLocalToWorldTransform(body_prim), dtype=float)
            frame = frame[:3, :3].T
            linear = (frame / np.linalg.norm(frame, axis=0)).T @ linear
        for factors in (authored, -np.abs(scale)):
            if not np.all(np.abs(factors) > 0):
                continue  # a zero scale: no rotation to find (validation names it)
            rotation = linear @ np.diag(1.0 / factors)
            if (
                np.abs(rotation.T @ rotation - np.eye(3)).max() < 1e-5
                and np.linalg.det(rotation) > 0
            ):
                turned = np.zeros(4)
                mujoco.mju_mat2Quat(turned, rotation.reshape(-1))
                return factors, turned
        return scale, quat

    def _mesh(self, s: int, scale: np.ndarray) -> str:
        import trimesh

        src = self.nb.shape_source[s]
        label = self.nb.shape_label[s]
        points = _mesh_prim(self.stage, label)
        if points is None:  # Newton's copy
            points = (src.vertices, np.asarray(src.indices).reshape(-1, 3))
        vertices = np.asarray(points[0], dtype=np.float64)
        faces = np.asarray(points[1], dtype=np.int64)
        # The scale stays the mesh's, not the file's: a negative one mirrors the mesh,
        # and MuJoCo mirrors the hull it made of the points as authored.
        scale = np.asarray(scale, dtype=np.float64)
        # One asset per distinct mesh: a flattened USD repeats the points of each use.
        key = (hashlib.sha1(vertices.tobytes() + faces.tobytes() + scale.tobytes()).hexdigest(),)
        if key in self.meshes:
            return self.meshes[key]
        name = self.names("mesh", label)
        file = f"{file_stem(name, 'mesh')}.stl"  # prim names are identifiers: unique still
        trimesh.Trimesh(vertices, faces, process=False).export(self.mesh_dir / file)
        self.spec.add_mesh(name=name, file=file, scale=scale.tolist())
        self.meshes[key] = name
        return name


def _mesh_prim(stage: Any, label: str) -> tuple[np.ndarray, np.ndarray] | None:
    """The vertices and triangles (polygons split into fans) of the ``UsdGeom.Mesh`` at
    ``label`` as authored, or ``None`` where there is none."""
    from pxr import UsdGeom

    prim = stage.GetPrimAtPath(label) if label.startswith("/") else None
    if not prim or not prim.IsA(UsdGeom.Mesh):
        return None
    mesh = UsdGeom.Mesh(prim)
    points = np.asarray(mesh.GetPointsAttr().Get() or [], dtype=np.float64).reshape(-1, 3)
    counts = np.asarray(mesh.GetFaceVertexCountsAttr().Get() or [], dtype=np.int64)
    indices = np.asarray(mesh.GetFaceVertexIndicesAttr().Get() or [], dtype=np.int64)
    if not len(points) or counts.sum() != len(indices) or (indices >= len(points)).any():
        return None
    faces, start = [], 0
    for n in counts:
        poly = indices[start : start + n]
        faces += [(poly[0], poly[k], poly[k + 1]) for k in range(1, n - 1)]
        start += n
    return points, np.asarray(faces, dtype=np.int64).reshape(-1, 3)


#: ``mjc:`` attributes (MJCF names) -> MjSpec fields; ranges end in ``:min``/``:max``.
_JOINT_ATTRS = {
    "mjc:actuatorfrclimited": "actfrclimited",
    "mjc:actuatorfrcrange": "actfrcrange",
    "mjc:actuatorgravcomp": "actgravcomp",
    "mjc:group": "group",
    "mjc:margin": "margin",
    "mjc:ref": "ref",
    "mjc:springref": "springref",
    "mjc:stiffness": "stiffness",
    "mjc:solimpfriction": "solimp_friction",
    "mjc:solimplimit": "solimp_limit",
    "mjc:solreffriction": "solref_friction",
    "mjc:solreflimit": "solref_limit",
    "mjc:springdamper": "springdamper",
}
_GEOM_ATTRS = {
    "mjc:condim": "condim",
    "mjc:group": "group",
    "mjc:priority": "priority",
    "mjc:solimp": "solimp",
    "mjc:solmix": "solmix",
    "mjc:solref": "solref",
}
_SITE_ATTRS = {"mjc:group": "group"}
#: Read through Newton's own attributes (``newton:armature``, ``physics:mass``, ...).
_READ_BY_NEWTON = {"mjc:damping", "mjc:armature", "mjc:frictionloss", "mjc:inertia"}


# -- actuators ------------------------------------------------------------------------

_TOKENS = {
    "gainType": ("gaintype", mujoco.mjtGain, "mjGAIN_"),
    "biasType": ("biastype", mujoco.mjtBias, "mjBIAS_"),
    "dynType": ("dyntype", mujoco.mjtDyn, "mjDYN_"),
}
_LIMITED = {
    "ctrlLimited": "ctrllimited",
    "forceLimited": "forcelimited",
    "actLimited": "actlimited",
}
_RANGES = {"ctrlRange": "ctrlrange", "forceRange": "forcerange", "actRange": "actrange"}
_ARRAYS = {"gainPrm": "gainprm", "biasPrm": "biasprm", "dynPrm": "dynprm", "gear": "gear"}


def _attr(prim: Any, name: str) -> Any:
    a = prim.GetAttribute(name)
    return a.Get() if a and a.HasAuthoredValue() else None


def _actuators(stage: Any, b: _Builder, rep: Reporter) -> list[str]:
    """``MjcActuator`` prims -> MjSpec actuators, in prim order; the names written."""
    joints = dict(b.prim_joint)  # the axes of merged joints, by their own prims
    for j, label in enumerate(b.nb.joint_label):
        if j in b.joint_names:
            joints.setdefault(label, b.joint_names[j])
    names = []
    for prim in stage.Traverse():
        if prim.GetTypeName() != "MjcActuator":
            continue
        where = str(prim.GetPath())
        targets = prim.GetRelationship("mjc:target").GetTargets()
        joint = joints.get(str(targets[0])) if targets else None
        if joint is None:
            rep.warn("actuator whose target is not a joint of the robot; not carried", where)
            continue
        act = b.spec.add_actuator(name=b.names("actuator", where), target=joint)
        act.trntype = mujoco.mjtTrn.mjTRN_JOINT
        for usd_name, (field, enum, enum_prefix) in _TOKENS.items():
            token = _attr(prim, f"mjc:{usd_name}")
            if token is not None:
                setattr(act, field, getattr(enum, enum_prefix + str(token).upper()))
        for usd_name, field in _LIMITED.items():
            token = _attr(prim, f"mjc:{usd_name}")
            if token is not None:
                setattr(act, field, getattr(mujoco.mjtLimited, "mjLIMITED_" + str(token).upper()))
        for usd_name, field in _RANGES.items():
            lo, hi = _attr(prim, f"mjc:{usd_name}:min"), _attr(prim, f"mjc:{usd_name}:max")
            if lo is not None or hi is not None:
                setattr(act, field, [lo or 0.0, hi or 0.0])
        for usd_name, field in _ARRAYS.items():
            values = _attr(prim, f"mjc:{usd_name}")
            if values is not None:
                arr = getattr(act, field)
                arr[: len(values)] = list(values)[: len(arr)]
        names.append(act.name)
    return names


def _drive_actuators(b: _Builder, rep: Reporter) -> list[str]:
    """One actuator per driven degree of freedom, from Newton's reading of the drives."""
    nb = b.nb
    names = []
    for d, joint in b.dof_joint.items():
        ke, kd = float(nb.joint_target_ke[d]), float(nb.joint_target_kd[d])
        effort = float(nb.joint_effort_limit[d])
        if ke == 0.0 and kd == 0.0:
            continue
        act = b.spec.add_actuator(name=b.names("actuator", joint), target=joint)
        act.trntype = mujoco.mjtTrn.mjTRN_JOINT
        act.gaintype = mujoco.mjtGain.mjGAIN_FIXED
        act.biastype = mujoco.mjtBias.mjBIAS_AFFINE
        act.gainprm[0] = ke if ke else kd
        act.biasprm[:3] = [0.0, -ke, -kd] if ke else [0.0, 0.0, -kd]
        if abs(effort) < _UNLIMITED:
            act.forcerange = [-effort, effort]
            act.forcelimited = mujoco.mjtLimited.mjLIMITED_TRUE
        names.append(act.name)
    if names:
        rep.warn(
            f"no MjcActuator prims: {len(names)} actuator(s) made from the joints' drives "
            "(stiffness -> position kp, damping -> kv, max force -> force range)"
        )
    return names


# -- the parse ------------------------------------------------------------------------


def parse_usd(
    path: str | os.PathLike, options: USDOptions | None = None, *, strict: bool = False
) -> ParseResult:
    """Read a USD robot into an HRDF (see the module docstring).

    Raises:
        ConversionError: Newton or usd-core is missing, the file has no rigid body, a
            joint MuJoCo has no equivalent for, or with ``strict`` any note.
        InputFileError: a layer or asset path outside the file's folder.
    """
    from robotwright._paths import trusted_roots
    from robotwright.parsers.mjcf.reader import MJCFOptions, parse_mjcf_spec

    path = Path(path)
    opt = options or USDOptions()
    newton = _newton(str(path))
    from pxr import Usd

    rep = Reporter(str(path))
    roots = [path.resolve().parent, *trusted_roots(opt.asset_roots)]
    check_usd_dependencies(path, roots)
    nb = newton.ModelBuilder()
    try:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            found = nb.add_usd(str(path), skip_mesh_approximation=True) or {}  # meshes as authored
    except Exception as exc:  # noqa: BLE001 - Newton's reason, with the file's name
        raise InputFileError(path, f"Newton's USD importer refused it: {exc}") from None
    for w in caught:  # Newton's remarks on the file are notes of this read
        rep.warn(f"Newton's USD importer: {w.message}")
    if nb.body_count == 0:
        raise InputFileError(path, "no rigid body (UsdPhysics.RigidBodyAPI) in the file")
    stage = Usd.Stage.Open(str(path))
    with tempfile.TemporaryDirectory(prefix=prefix("usd")) as tmp:
        folder = Path(tmp)
        builder = _Builder(newton, nb, stage, rep, folder, found)
        spec = builder.build()
        default = str(stage.GetDefaultPrim().GetPath())
        spec.modelname = name_of(builder.names.shown, default) or path.stem
        if not _actuators(stage, builder, rep):
            _drive_actuators(builder, rep)
        _note_unread(stage, rep)
        builder.names.report(rep)
        builder.report_unread()
        spec.modelfiledir = str(folder)  # mesh files are named relative to it
        mjcf = folder / f"{file_stem(spec.modelname, 'robot')}.xml"
        try:
            parsed = parse_mjcf_spec(spec, mjcf, MJCFOptions(work_dir=opt.work_dir))
        except ConversionError as exc:  # MuJoCo's compiler names the element
            raise InputFileError(
                path, f"MuJoCo refuses the robot read from it: {exc.problems[0].message}"
            ) from None
    hrdf = parsed.hrdf
    hrdf = _peak_velocities(hrdf, nb, builder)
    for p in parsed.warnings:
        rep.warn(p.message.replace(str(mjcf), str(path)), p.element)
    rep.finish(strict)
    return ParseResult(hrdf, rep.problems, str(path))


def _peak_velocities(hrdf: Any, nb: Any, b: _Builder) -> Any:
    """``hrdf`` with each actuator's ``peak_velocity`` from its joint's velocity limit."""
    from dataclasses import replace

    by_joint = {name: d for d, name in b.dof_joint.items()}
    acts = []
    for act in hrdf.actuators:
        d = by_joint.get(act.joint)
        if d is not None and float(nb.joint_velocity_limit[d]) < _UNLIMITED:
            act = replace(act, peak_velocity=float(nb.joint_velocity_limit[d]))
        acts.append(act)
    return replace(hrdf, actuators=acts)


def _note_unread(stage: Any, rep: Reporter) -> None:
    """Prims the reader does not carry: cameras, lights, and anything else typed that is
    not physics, geometry or a transform."""
    skipped = Counter()
    for prim in stage.Traverse():
        kind = prim.GetTypeName()
        if kind in ("Camera", "DistantLight", "SphereLight", "DomeLight", "RectLight", "DiskLight"):
            skipped[kind] += 1
    for kind, n in sorted(skipped.items()):
        rep.warn(f"{n} {kind} prim(s) not carried: HRDF holds no {kind.lower()}s")
