"""HRDF -> OpenUSD for Isaac Lab and Newton, on the maintained converter.

The robot goes out as our MJCF (robot only: no floor, light or sky), which
``mujoco-usd-converter`` (the library behind Isaac Lab 3's kit-less MJCF importer) turns
into USD; then usd-core's API authors what the converter leaves out:

* joint drives (``UsdPhysics.DriveAPI``, ``angular`` or ``linear``) from MuJoCo's
  compile of the robot's actuators (:mod:`robotwright.generators.usd_drives`: gains and
  max force in joint units, gear included; USD's angular drive units are per degree:
  N m/deg, N m s/deg), and a note naming each actuator no drive can hold;
* the velocity limit MJCF cannot hold, ``peak_velocity``, as Newton's
  ``newton:velocityLimit`` (deg/s or m/s) and PhysX's ``physxJoint:maxJointVelocity``
  (deg/s);
* the robot's name: the articulation's root prim is named after the robot;
* a floating body's free joint name (USD has no prim for it) as the custom attribute
  ``robotwright:freeJointName`` on the body's prim.

The written file is one flattened layer (``.usd``, ``.usda`` or ``.usdc``): meshes are
in it, nothing refers back to the temporary conversion folder.

Needs the converter (Python 3.12, Isaac Lab's environment: ``pip install
"isaacsim-asset-isolated==6.2.0.0" "tinyobjloader==2.0.0rc13"``, which brings
mujoco-usd-converter 0.6.1 beside MuJoCo 3.12).
"""

from __future__ import annotations

import functools
import math
import re
import tempfile
import warnings
from dataclasses import dataclass, field
from pathlib import Path

import mujoco
import numpy as np

from robotwright._atomic import copy_file_atomic
from robotwright._names import file_stem
from robotwright._rotations import quat_angles
from robotwright._temporaries import prefix
from robotwright._usd_format import FREE_JOINT_ATTR, USD_SUFFIXES
from robotwright._usd_names import display_names
from robotwright.errors import ConversionWarning, GeneratorError
from robotwright.hrdf.model import HRDF

__all__ = ["USD_LAYOUTS", "USD_SUFFIXES", "UsdExport", "to_usd"]

_MISSING = (
    "USD export needs Python 3.12 (as Isaac Lab) and the usd extra: pip install "
    "'robotwright[usd]' (mujoco-usd-converter through isaacsim-asset-isolated 6.2.0.0 and "
    "tinyobjloader 2.0.0rc13, usd-core, and Newton with warp and scipy, which read the USD "
    "back); not importable here: {error}"
)

#: Lines the converter and warp print that say nothing about the robot: progress of
#: usd-core's saves, and warp finding no GPU (the export and its proof run on the CPU).
_CHATTER = ("Status: ", "Warp CUDA warning: Could not find or load the NVIDIA CUDA driver")


@dataclass
class UsdExport:
    """What :func:`to_usd` wrote.

    Attributes:
        path: the USD file.
        root: prim path of the articulation's root prim (``/<robot name>``).
        drives: joint name -> (stiffness, damping, max force) as authored, in USD units
            (angular: N m/deg, N m s/deg, N m).
        velocity_limits: joint name -> velocity limit authored (rad/s or m/s).
        joint_prims: joint name -> prim path.
        notes: what was not carried, one line each.
        proof: the read-back comparison (:class:`~robotwright.generators.usd_proof.UsdProof`),
            ``None`` when not asked for.
        mjcf_model: MuJoCo's compile of the MJCF the USD was converted from (what the
            proof compares against: bodies, inertias, joints, actuators, poses); its mesh
            geoms are left out unless :func:`to_usd` was asked for ``geometry``.
    """

    path: Path
    root: str
    drives: dict[str, tuple[float, float, float]] = field(default_factory=dict)
    velocity_limits: dict[str, float] = field(default_factory=dict)
    joint_prims: dict[str, str] = field(default_factory=dict)
    notes: list[str] = field(default_factory=list)
    proof: object | None = None
    mjcf_model: mujoco.MjModel | None = None


def _converter(prove: bool):
    """The converter module, once everything the export needs imports (the proof's
    Newton too, when asked): a missing piece is named before anything is written."""
    try:
        import mujoco_usd_converter
        from pxr import Usd, UsdPhysics  # noqa: F401

        if prove:
            from robotwright._warp import quiet_warp

            quiet_warp()  # before Newton initialises warp
            import newton  # noqa: F401
            import scipy  # noqa: F401  (Newton's mesh import)
    except ImportError as exc:
        raise GeneratorError(_MISSING.format(error=exc)) from None
    return mujoco_usd_converter


#: usd-core's diagnostic heading: "Warning: in FUNCTION at line N of FILE -- message".
_DIAGNOSTIC = re.compile(r"^(?:Warning|Error|Coding Error|Runtime Error): (?:in .*? -- )?")


def _library_notes(lines: list[str], who: str) -> list[str]:
    """The lines a library printed while it worked, as notes (its chatter dropped, the
    place in its own source cut from usd-core's diagnostics)."""
    notes = [
        f"{who}: {_DIAGNOSTIC.sub('', line.strip())}"
        for line in lines
        if not line.startswith(_CHATTER)
    ]
    return list(dict.fromkeys(notes))


def converter_model_name(name: str) -> str:
    """The MJCF model name handed to mujoco-usd-converter for a robot named ``name``: the
    converter names its output file and the root prim after the model, so the name is
    made a safe file name (:func:`~robotwright._names.file_stem`) and a USD identifier
    (what the converter's ``getValidPrimName`` would make of it: the root prim keeps the
    name it always had for an ordinary robot name)."""
    stem = re.sub(r"\W", "_", file_stem(name, "robot"), flags=re.ASCII)
    return f"_{stem}" if stem[0].isdigit() else stem


def _robot_mjcf(hrdf: HRDF, folder: Path, root_at_origin: bool = False) -> tuple[Path, list[str]]:
    """Our MJCF of the robot alone (its model named by :func:`converter_model_name`), its
    meshes referred to where they are (read while ``hrdf`` is held), and the values the
    MJCF could not hold that the USD does not get either (``peak_velocity`` it does
    get). ``root_at_origin``: a free base's body is put at the model's origin (see
    :func:`to_usd`)."""
    import dataclasses
    import warnings

    from robotwright.generators.mjcf import MJCFHumanoidGenerator

    model = converter_model_name(hrdf.name)
    path = folder / "mjcf" / f"{model}.xml"
    robot = dataclasses.replace(_usd_robot(hrdf, root_at_origin), name=model)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        # Read at once, while the robot (and a parser's staging folder) is held: the
        # meshes are referenced where they are, not copied (the G1's 35: 0.035 s).
        MJCFHumanoidGenerator.from_hrdf(robot).export(path, meshes_in_place=True, add_scene=False)
    lost = []
    for w in caught:
        lines = str(w.message).splitlines()
        items = [ln.strip()[2:] for ln in lines[1:] if ln.strip().startswith("- ")] or lines
        lost += [ln for ln in items if "'peak_velocity'" not in ln]
    return path, lost


def _usd_robot(hrdf: HRDF, root_at_origin: bool) -> HRDF:
    """The robot as the USD holds it: ``root_at_origin`` puts a free base's body at the
    model's origin (see :func:`to_usd`)."""
    import dataclasses

    if not (root_at_origin and hrdf.floating_base and any(hrdf.root_body.pos)):
        return hrdf
    bodies = [
        dataclasses.replace(b, pos=(0.0, 0.0, 0.0)) if b is hrdf.root_body else b
        for b in hrdf.bodies
    ]
    return dataclasses.replace(hrdf, bodies=bodies)


def _robot_text(hrdf: HRDF, root_at_origin: bool) -> str:
    """Our MJCF of the robot as the USD holds it, as text: the file :func:`_robot_mjcf`
    writes, under the robot's own name and with its mesh folder given absolute. The text
    the export's compile check parses
    (:func:`~robotwright.generators.compiles.require_compiles` of the robot alone), so
    MuJoCo parses it once (:mod:`robotwright._mjspec_cache`)."""
    from robotwright.generators.compiles import robot_xml

    return robot_xml(_usd_robot(hrdf, root_at_origin))


def _kinematic_model(text: str) -> mujoco.MjModel:
    """MuJoCo's compile of our MJCF (``text``) without its mesh geoms: the same bodies,
    masses, inertias (each body's is explicit in our MJCF, so no geom contributes),
    joints, actuators and keyframes, without reading or hulling a mesh (the G1's 35
    meshes took 0.3-1.1 s of a 2 s export). Nothing the export or its proof reads is in
    a mesh. A model in which something refers to a mesh geom (a contact pair, a sensor)
    is compiled whole."""
    from robotwright._mjspec_cache import compiled

    def without_meshes(spec: mujoco.MjSpec) -> None:
        for geom in [g for g in spec.geoms if g.type == mujoco.mjtGeom.mjGEOM_MESH]:
            spec.delete(geom)
        for mesh in list(spec.meshes):
            spec.delete(mesh)

    try:
        return compiled(text, without_meshes)
    except ValueError:
        return compiled(text)


def _zero_inertia_bodies(model: mujoco.MjModel) -> list[str]:
    """Bodies with mass but an all-zero inertia: USD reads a zero ``diagonalInertia`` as
    "not given" and readers compute one from the colliders instead."""
    return [
        mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_BODY, b)
        for b in range(1, model.nbody)
        if model.body_mass[b] > 0 and not model.body_inertia[b].any()
    ]


def _keyframe_notes(model: mujoco.MjModel) -> list[str]:
    """A note for the keyframes, which no USD joint state carries, each named."""
    if not model.nkey:
        return []
    names = [model.key(k).name or f"#{k}" for k in range(model.nkey)]
    more = ", ..." if len(names) > 5 else ""
    return [
        f"{model.nkey} keyframe(s) not carried ({', '.join(names[:5])}{more}): the USD "
        "holds no keyframes; it starts in the model's reference pose"
    ]


def _author_drives(
    stage, shown: dict[str, str], hrdf: HRDF, model: mujoco.MjModel, out: UsdExport
) -> None:
    """One ``UsdPhysics.DriveAPI`` per actuated hinge or slide joint, as
    :func:`~robotwright.generators.usd_drives.joint_drives` derives it from MuJoCo's
    compile, and each joint's rated velocity (the HRDF's ``peak_velocity``, which MJCF
    cannot hold); a note for each actuator no drive holds."""
    from pxr import Sdf, UsdPhysics

    from robotwright.generators.usd_drives import joint_drives

    joints = {shown[str(p.GetPath())]: p for p in stage.Traverse() if p.IsA(UsdPhysics.Joint)}
    out.joint_prims = {name: str(p.GetPath()) for name, p in joints.items()}
    drives, lost = joint_drives(model)
    out.notes += lost
    for name, d in drives.items():
        prim = joints.get(name)
        if prim is None:
            out.notes.append(
                f"actuator(s) {', '.join(map(repr, d.actuators))}: joint {name!r} has no joint "
                "prim in the USD; no drive written"
            )
            continue
        per = math.pi / 180.0 if d.axis == "angular" else 1.0  # USD angular units: degrees
        drive = UsdPhysics.DriveAPI.Apply(prim, d.axis)
        drive.CreateTypeAttr("force")
        drive.CreateStiffnessAttr(d.stiffness * per)
        drive.CreateDampingAttr(d.damping * per)
        drive.CreateMaxForceAttr(d.max_force)
        out.drives[name] = (d.stiffness * per, d.damping * per, d.max_force)
    kinds = {name: d.axis for name, d in drives.items()}
    for act in hrdf.actuators:
        prim, axis = joints.get(act.joint), kinds.get(act.joint)
        if act.peak_velocity is None or prim is None or axis is None:
            continue
        v = float(act.peak_velocity)
        value = v * 180.0 / math.pi if axis == "angular" else v
        prim.CreateAttribute("newton:velocityLimit", Sdf.ValueTypeNames.Float).Set(value)
        prim.CreateAttribute("physxJoint:maxJointVelocity", Sdf.ValueTypeNames.Float).Set(value)
        out.velocity_limits[act.joint] = v


def _quat(q) -> list[float]:
    """A Gf quaternion as (w, x, y, z). Indexed, not iterated: a Gf vector iterates by
    catching IndexError, about ten times slower."""
    im = q.GetImaginary()
    return [q.GetReal(), im[0], im[1], im[2]]


def _set_joint_frame(joint, pos, rot) -> None:
    """Set a joint's frame in its parent body (``localPos0``, ``localRot0``)."""
    joint.GetLocalRot0Attr().Set(rot)
    joint.GetLocalPos0Attr().Set(pos)


def _exact_frames(stage, shown: dict[str, str], model: mujoco.MjModel) -> None:
    """Each body's orientation and each joint's frame in its parent body, from MuJoCo's
    compile in double precision, where the converter's values are the same rotation
    rounded: it passes them through a 32-bit ``Gf.Rotation``, which for a slightly
    tilted body (Gymnasium's humanoid's 0.004 rad) is off by ~3e-5 rad. Only a body
    whose prim sits in its parent body's prim, and a joint between a body and its
    parent, is set; each must already be within 1e-3 rad and 1e-4 m of the compile
    (the angles are checked at once, after every frame is gathered)."""
    from pxr import UsdGeom, UsdPhysics

    def body_of(prim) -> int:
        if prim is None or not prim.IsValid():
            return -1
        if not prim.HasAPI(UsdPhysics.RigidBodyAPI):
            return 0  # the world, or the scope the root body's prim sits in
        return mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, shown[str(prim.GetPath())])

    # (value as written, the exact value, what sets it) for each frame found
    found: list[tuple[object, object, object]] = []
    for prim in stage.Traverse():
        if prim.HasAPI(UsdPhysics.RigidBodyAPI):
            b = body_of(prim)
            if b <= 0 or body_of(prim.GetParent()) != int(model.body_parentid[b]):
                continue
            w, x, y, z = (float(v) for v in model.body_quat[b])
            for op in UsdGeom.Xformable(prim).GetOrderedXformOps():
                if op.GetOpType() == UsdGeom.XformOp.TypeOrient:
                    now = op.Get()
                    found.append((now, type(now)(w, x, y, z), op.Set))
        elif prim.IsA(UsdPhysics.Joint):
            joint = UsdPhysics.Joint(prim)
            t0, t1 = joint.GetBody0Rel().GetTargets(), joint.GetBody1Rel().GetTargets()
            if len(t0) != 1 or len(t1) != 1:
                continue
            c = body_of(stage.GetPrimAtPath(t1[0]))
            if c <= 0 or body_of(stage.GetPrimAtPath(t0[0])) != int(model.body_parentid[c]):
                continue
            rot1, pos1 = joint.GetLocalRot1Attr().Get(), joint.GetLocalPos1Attr().Get()
            rot0, pos0 = joint.GetLocalRot0Attr().Get(), joint.GetLocalPos0Attr().Get()
            if None in (rot1, pos1, rot0, pos0):
                continue
            q0, p0 = np.empty(4), np.empty(3)
            mujoco.mju_mulQuat(q0, model.body_quat[c], np.array(_quat(rot1), dtype=np.float64))
            mujoco.mju_rotVecQuat(p0, np.array(pos1, dtype=np.float64), model.body_quat[c])
            p0 += model.body_pos[c]
            if np.abs(np.array(pos0, dtype=np.float64) - p0).max() >= 1e-4:
                continue
            exact_pos = type(pos0)(*p0.tolist())
            set_frame = functools.partial(_set_joint_frame, joint, exact_pos)
            found.append((rot0, type(rot0)(*q0.tolist()), set_frame))
    if not found:
        return
    angles = quat_angles(
        np.array([_quat(now) for now, _, _ in found], dtype=np.float64),
        np.array([_quat(exact) for _, exact, _ in found], dtype=np.float64),
    )
    for (_, exact, set_exact), angle in zip(found, angles, strict=True):
        if angle < 1e-3:
            set_exact(exact)


def _author_free_joint_names(stage, shown: dict[str, str], model: mujoco.MjModel) -> None:
    from pxr import Sdf, UsdPhysics

    bodies = {
        shown[str(p.GetPath())]: p for p in stage.Traverse() if p.HasAPI(UsdPhysics.RigidBodyAPI)
    }
    for j in range(model.njnt):
        name = mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_JOINT, j)
        if model.jnt_type[j] != mujoco.mjtJoint.mjJNT_FREE or not name:
            continue
        body = mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_BODY, int(model.jnt_bodyid[j]))
        if body in bodies:
            attr = bodies[body].CreateAttribute(FREE_JOINT_ATTR, Sdf.ValueTypeNames.String)
            attr.Set(name)


USD_LAYOUTS = ("nested", "flat")


def _flatten_bodies(stage) -> None:
    """Move every rigid body to a direct child of the default prim (``/<robot>/<body>``)
    at its pose relative to it, and point every relationship (joint bodies, actuator
    targets) at the moved prims. The
    converter nests bodies as the kinematic tree (``/<robot>/Geometry/base/hip/...``);
    Isaac Lab's importers write them flat, which its body expressions and PhysX contact
    sensors expect."""
    from pxr import Gf, Sdf, UsdGeom, UsdPhysics

    root = stage.GetDefaultPrim()
    layer = stage.GetRootLayer()
    bodies = [p for p in stage.Traverse() if p.HasAPI(UsdPhysics.RigidBodyAPI)]
    cache = UsdGeom.XformCache()
    poses = {p.GetPath(): cache.ComputeRelativeTransform(p, root)[0] for p in bodies}
    moved = {p.GetPath(): root.GetPath().AppendChild(p.GetName()) for p in bodies}
    taken = {c.GetName() for c in root.GetChildren()}
    clash = sorted(taken & {p.GetName() for p in bodies})
    if clash:
        raise GeneratorError(
            f"--usd-layout flat: body name(s) {clash} equal a prim of the robot's own "
            f"(/{root.GetName()}/{clash[0]}); rename the body or use the nested layout"
        )
    for old, new in moved.items():
        Sdf.CopySpec(layer, old, layer, new)
        spec = layer.GetPrimAtPath(new)
        for child in list(spec.nameChildren):
            if old.AppendChild(child.name) in moved:  # a body of its own: moved itself
                del spec.nameChildren[child.name]
    tops = [old for old in moved if old.GetParentPath() not in moved]
    for old in tops:
        parent = layer.GetPrimAtPath(old.GetParentPath())
        del parent.nameChildren[old.name]
        if parent.path != root.GetPath() and not parent.nameChildren:
            del layer.GetPrimAtPath(parent.path.GetParentPath()).nameChildren[parent.name]
    for old, new in moved.items():
        xf = UsdGeom.Xformable(stage.GetPrimAtPath(new))
        m = poses[old]
        xf.ClearXformOpOrder()
        xf.AddTranslateOp().Set(m.ExtractTranslation())
        xf.AddOrientOp().Set(Gf.Quatf(m.ExtractRotationQuat()))
        xf.AddScaleOp().Set(Gf.Vec3f(1.0, 1.0, 1.0))
    by_depth = sorted(moved, key=lambda p: -p.pathElementCount)

    def retarget(path):
        for old in by_depth:  # the deepest body holding the path
            if path.HasPrefix(old):
                return path.ReplacePrefix(old, moved[old])
        return path

    for prim in stage.Traverse():
        for rel in prim.GetRelationships():
            targets = rel.GetTargets()
            new_targets = [retarget(t) for t in targets]
            if new_targets != targets:
                rel.SetTargets(new_targets)


def to_usd(
    hrdf: HRDF,
    output: str | Path,
    *,
    overwrite: bool = False,
    prove: bool = True,
    strict: bool = False,
    layout: str = "nested",
    root_at_origin: bool = False,
    geometry: bool = False,
) -> UsdExport:
    """Write ``hrdf`` as one USD file (see the module docstring for what is authored).

    With ``prove`` (the default), Newton reads the file back and it is compared with
    MuJoCo's compile of the same MJCF (:func:`~robotwright.generators.usd_proof.prove_usd`):
    each difference and each note is a :class:`~robotwright.errors.ConversionWarning`,
    under ``strict`` a :class:`~robotwright.errors.ConversionError` before the file is
    put in place.

    ``layout``: ``"nested"`` (the converter's: bodies nested as the kinematic tree under
    ``/<robot>/Geometry``) or ``"flat"`` (every body a child of ``/<robot>``, as Isaac
    Lab's importers write and its PhysX contact sensors expect).

    ``root_at_origin``: a free base's body sits at its prim's origin instead of at its
    reference position (which the USD then does not hold: for a config that gives the
    initial position itself, as :func:`~robotwright.generators.isaaclab_cfg.write_articulation_cfg`
    does). Isaac Lab places the prim at the config's initial position when it spawns and
    the root body there when it resets, so an offset of the body inside its prim would
    count twice at spawn.

    ``geometry``: ``mjcf_model`` is compiled with its mesh geoms (what a standing height
    or a sensor mount needs); by default they are left out, which the export and its
    proof do not need and which costs the hull of every collision mesh.

    Raises:
        GeneratorError: the converter is missing, the suffix is not a USD one, the
            layout is unknown, or the output exists without ``overwrite``.
        ConversionError: ``strict`` and the proof or a note found a difference.
    """
    out_path = Path(output)
    if out_path.suffix.lower() not in USD_SUFFIXES:
        raise GeneratorError(
            f"{out_path}: expected a file name ending in {', '.join(USD_SUFFIXES)}"
        )
    if out_path.exists() and not overwrite:
        raise GeneratorError(f"{out_path} exists (pass overwrite=True / --overwrite)")
    if layout not in USD_LAYOUTS:
        raise GeneratorError(f"layout={layout!r}: expected one of {', '.join(USD_LAYOUTS)}")
    converter = _converter(prove)
    from robotwright._library_output import captured_library_output
    from robotwright._mjspec_cache import compiled, parsed_spec
    from robotwright.generators.usd_converted import converted_stage

    with tempfile.TemporaryDirectory(prefix=prefix("usd")) as tmp:
        mjcf, lost = _robot_mjcf(hrdf, Path(tmp), root_at_origin)
        # MuJoCo parses our MJCF once: the export's check, the proof's model, the
        # converter's spec (named for it) are that parse compiled or copied
        text = _robot_text(hrdf, root_at_origin)
        model = compiled(text) if geometry else _kinematic_model(text)
        given = parsed_spec(text)
        given.modelname = converter_model_name(hrdf.name)
        # The converter's own layered asset, in our private folder, flattened once in
        # memory: what is authored next goes straight into the one layer written (an
        # edit of the layered asset would recompose its payload; the converter's own
        # one-file output writes, reopens and saves that layer, in the system's
        # temporary folder, before we could open it).
        with captured_library_output() as printed:
            stage = converted_stage(converter, mjcf, Path(tmp) / "usd", given)
        # What the libraries said is passed on as notes, never as a difference: --strict
        # refuses what the proof finds, not another library's remarks.
        said = _library_notes(printed, "mujoco-usd-converter")
        # usd-core's own note named the converter's temporary folder
        stage.GetRootLayer().documentation = (
            "Written by robotwright (to_usd) through mujoco-usd-converter"
        )
        root = stage.GetDefaultPrim()
        if root.GetName() != hrdf.name:  # the robot's own name, as data, for the user
            root.SetDisplayName(hrdf.name)
        result = UsdExport(path=out_path, root=str(root.GetPath()), notes=lost, mjcf_model=model)
        for body in _zero_inertia_bodies(model):
            result.notes.append(
                f"body {body!r}: mass with zero inertia; USD reads a zero diagonalInertia as "
                "'not given', so Newton and PhysX compute one from the body's colliders"
            )
        if hrdf.sensors:
            names = ", ".join(sn.name for sn in hrdf.sensors[:5])
            result.notes.append(
                f"{len(hrdf.sensors)} sensor(s) not carried ({names}"
                f"{', ...' if len(hrdf.sensors) > 5 else ''}): mujoco-usd-converter writes no "
                "sensors; add Isaac Lab sensors in the scene config"
            )
        result.notes += _keyframe_notes(model)
        shown = display_names(stage)  # prim path -> the robot's name for it
        _author_drives(stage, shown, hrdf, model, result)
        _exact_frames(stage, shown, model)
        _author_free_joint_names(stage, shown, model)
        if layout == "flat":
            from pxr import UsdPhysics

            _flatten_bodies(stage)
            result.joint_prims = {
                p.GetName(): str(p.GetPath())
                for p in stage.Traverse()
                if p.IsA(UsdPhysics.Joint) and p.GetName() in result.joint_prims
            }
        # Written and proven in the private temporary folder, then copied into place
        # through the output gate (a temporary of its own, renamed: nothing planted in
        # the user's folder is followed, and a refused proof leaves nothing there).
        written = Path(tmp) / f"robot{out_path.suffix.lower()}"
        if not stage.GetRootLayer().Export(str(written)):
            raise GeneratorError(f"{out_path}: usd-core could not write the file")
        found = list(result.notes)
        if prove:
            from robotwright.generators.usd_proof import prove_usd

            with (
                captured_library_output() as printed,
                warnings.catch_warnings(record=True) as caught,
            ):
                warnings.simplefilter("always")
                result.proof = prove_usd(written, model, hrdf)
            for w in caught:  # Newton's warnings about the file are notes of the export
                if issubclass(w.category, (DeprecationWarning, PendingDeprecationWarning)):
                    warnings.warn_explicit(w.message, w.category, w.filename, w.lineno)
                else:
                    printed.append(str(w.message))
            found += result.proof.differences
            said += _library_notes(printed, "Newton reading it back")
        _report(found, out_path, strict)
        for line in said:
            warnings.warn(f"{out_path}: {line}", ConversionWarning, stacklevel=2)
        copy_file_atomic(written, out_path)
    return result


def _report(found: list[str], out_path: Path, strict: bool) -> None:
    import warnings

    from robotwright.errors import ConversionError, ConversionWarning, Problem

    if strict and found:
        raise ConversionError(
            [Problem(str(out_path), line) for line in found],
            summary=f"strict USD export of {out_path}: {len(found)} difference(s) between "
            "the USD read back by Newton and the robot",
        )
    for line in found:
        warnings.warn(f"{out_path}: {line}", ConversionWarning, stacklevel=3)
