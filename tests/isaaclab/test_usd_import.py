"""USD in: a robot exported to USD reads back (Newton's USD importer) as the same robot,
names and actuator order included; a USD that is not ours reads from its drives; a file
that reaches outside its folder is refused.

Runs in Isaac Lab's environment (Newton, usd-core, mujoco-usd-converter); skipped elsewhere.
"""

from __future__ import annotations

import math
import os
import re
import subprocess
import sys
import warnings
from pathlib import Path

import pytest

if os.environ.get("ROBOTWRIGHT_REQUIRE_ISAACLAB") != "1":
    pytest.importorskip(
        "mujoco_usd_converter", reason="mujoco-usd-converter not installed (Isaac Lab stage)"
    )

import mujoco  # noqa: E402
import numpy as np  # noqa: E402
from pxr import Gf, Usd, UsdGeom, UsdPhysics  # noqa: E402
from usd_robots import ROBOTS, robot  # noqa: E402

from robotwright.generators.mjcf import MJCFHumanoidGenerator  # noqa: E402
from robotwright.generators.usd import to_usd  # noqa: E402
from robotwright.parsers.api import usd_to_hrdf_with_warnings  # noqa: E402
from robotwright.proof.compare import compare_models  # noqa: E402

_NUMBER = re.compile(r"-?\d+(?:\.\d*)?(?:e[-+]?\d+)?")


def _compiled(hrdf, folder):
    path = folder / f"{hrdf.name}.xml"
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # peak_velocity has no MJCF form: said elsewhere
        MJCFHumanoidGenerator.from_hrdf(hrdf).export(path, copy_meshes=True, add_scene=False)
    return mujoco.MjModel.from_xml_path(str(path))


def _float32_rounding(diff) -> bool:
    """A difference of values only, each within single-precision rounding of the field's
    scale (USD stores masses, inertias, limits and meshes as 32-bit floats); the bound is
    1e-5 because a difference prints the result with 6 significant digits, plus 1e-7 for
    values near zero)."""
    a = np.array([float(x) for x in _NUMBER.findall(diff.source)])
    b = np.array([float(x) for x in _NUMBER.findall(diff.result)])
    if a.shape != b.shape or not a.size:
        return False
    return bool(np.all(np.abs(a - b) <= 1e-5 * float(np.abs(a).max()) + 1e-7))


@pytest.mark.parametrize("name", ROBOTS)
def test_exported_robot_reads_back_as_itself(name, tmp_path):
    hrdf = robot(name)
    usd = tmp_path / f"{name}.usd"
    with warnings.catch_warnings(record=True):
        warnings.simplefilter("always")
        done = to_usd(hrdf, usd)
    back, notes = usd_to_hrdf_with_warnings(usd, work_dir=tmp_path / "work")

    # Names and order: every body, joint and actuator, actuators in the source's order.
    assert {b.name for b in back.bodies} == {b.name for b in hrdf.bodies}
    named = {j.name for j in hrdf.joints if j.name}
    assert named <= {j.name for j in back.joints}
    if len(named) < len(hrdf.joints):  # an unnamed free joint gets a name, said in a note
        assert len(back.joints) == len(hrdf.joints)
        assert any("unnamed joint named" in str(n) for n in notes)
    # (an unnamed actuator has the name of its prim, which the converter made up)
    assert [a.name for a in back.actuators if a.name] != [] or not hrdf.actuators
    for got, want in zip(back.actuators, hrdf.actuators, strict=True):
        assert want.name is None or got.name == want.name
    assert [a.joint for a in back.actuators] == [a.joint for a in hrdf.actuators]
    for got, want in zip(back.actuators, hrdf.actuators, strict=True):
        if want.peak_velocity is not None:  # the value MJCF cannot hold, carried by USD
            assert got.peak_velocity == pytest.approx(want.peak_velocity, rel=1e-6)

    # The compiled models: equal but for float32 rounding, the sensors USD cannot hold,
    # and the zero-inertia bodies the export noted (talos' F/T links).
    source, result = _compiled(hrdf, tmp_path / "a"), _compiled(back, tmp_path / "b")
    for fam in ("nbody", "njnt", "ngeom", "nsite", "nu", "nmesh", "nq", "nv"):
        assert getattr(source, fam) == getattr(result, fam), fam
    zero = {n.split("'")[1] for n in done.notes if "zero inertia" in n}
    unexplained = [
        d
        for d in compare_models(source, result)
        if not _float32_rounding(d)
        and not (d.family == "sensor" and d.field == "(object)")
        and not (d.family == "body" and any(f"'{b}'" in d.obj for b in zero))
        and d.field not in ("body_subtreemass", "dof_invweight0", "body_invweight0")
    ]
    assert not unexplained, "\n".join(map(str, unexplained[:10]))
    # Meshes are the authored ones, not Newton's convex hulls.
    if source.nmesh:
        assert result.nmeshvert == source.nmeshvert


def test_command_line_reads_usd_and_proves_it(tmp_path):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        to_usd(robot("arm6"), tmp_path / "arm6.usda")
    run = subprocess.run(
        [sys.executable, "-m", "robotwright", "convert", "arm6.usda", "-o", "out", "--strict"],
        capture_output=True,
        text=True,
        cwd=tmp_path,
    )
    assert run.returncode == 0, run.stderr[-2000:]
    assert (tmp_path / "out" / "meta.yaml").is_file()
    info = subprocess.run(
        [sys.executable, "-m", "robotwright", "info", "arm6.usda"],
        capture_output=True,
        text=True,
        cwd=tmp_path,
    )
    assert info.returncode == 0, info.stderr[-2000:]
    assert "shoulder_pan_joint" in info.stdout


def _two_link_usd(path, *, stiffness=400.0, damping=8.0):
    """A robot written with UsdPhysics alone (no mjc: attributes, no MjcActuator): a
    fixed base and one link on a revolute joint with an angular drive (per degree)."""
    stage = Usd.Stage.CreateNew(str(path))
    UsdGeom.SetStageUpAxis(stage, UsdGeom.Tokens.z)
    root = UsdGeom.Xform.Define(stage, "/bot").GetPrim()
    stage.SetDefaultPrim(root)
    bodies = {}
    for name, z in (("base", 0.0), ("link", 0.5)):
        xf = UsdGeom.Xform.Define(stage, f"/bot/{name}")
        xf.AddTranslateOp().Set(Gf.Vec3d(0, 0, z))
        UsdPhysics.RigidBodyAPI.Apply(xf.GetPrim())
        mass = UsdPhysics.MassAPI.Apply(xf.GetPrim())
        mass.CreateMassAttr(2.0)
        mass.CreateDiagonalInertiaAttr(Gf.Vec3f(0.02, 0.03, 0.04))
        mass.CreateCenterOfMassAttr(Gf.Vec3f(0, 0, 0.1))
        box = UsdGeom.Cube.Define(stage, f"/bot/{name}/box")
        box.CreateSizeAttr(0.2)
        UsdPhysics.CollisionAPI.Apply(box.GetPrim())
        bodies[name] = xf.GetPrim()
    UsdPhysics.ArticulationRootAPI.Apply(bodies["base"])
    fixed = UsdPhysics.FixedJoint.Define(stage, "/bot/base/anchor")
    fixed.CreateBody1Rel().SetTargets([bodies["base"].GetPath()])
    joint = UsdPhysics.RevoluteJoint.Define(stage, "/bot/link/elbow")
    joint.CreateBody0Rel().SetTargets([bodies["base"].GetPath()])
    joint.CreateBody1Rel().SetTargets([bodies["link"].GetPath()])
    joint.CreateAxisAttr("Y")
    joint.CreateLocalPos0Attr(Gf.Vec3f(0, 0, 0.5))
    joint.CreateLocalPos1Attr(Gf.Vec3f(0, 0, 0))
    joint.CreateLowerLimitAttr(-90.0)
    joint.CreateUpperLimitAttr(45.0)
    drive = UsdPhysics.DriveAPI.Apply(joint.GetPrim(), "angular")
    drive.CreateStiffnessAttr(stiffness)
    drive.CreateDampingAttr(damping)
    drive.CreateMaxForceAttr(30.0)
    stage.Save()


def test_a_usd_not_written_by_us_reads_from_its_drives(tmp_path):
    _two_link_usd(tmp_path / "bot.usda")
    back, notes = usd_to_hrdf_with_warnings(tmp_path / "bot.usda", work_dir=tmp_path / "w")
    assert [b.name for b in back.bodies] == ["base", "link"]
    (joint,) = back.joints
    assert joint.name == "elbow" and joint.type == "hinge"
    assert joint.range == pytest.approx((-math.pi / 2, math.pi / 4), rel=1e-6)
    (act,) = back.actuators
    # USD's angular drive gains are per degree; MuJoCo's per radian.
    assert act.type == "position"
    assert act.p_gain == pytest.approx(400.0 * 180.0 / math.pi, rel=1e-6)
    assert act.d_gain == pytest.approx(8.0 * 180.0 / math.pi, rel=1e-6)
    assert act.force_range == pytest.approx((-30.0, 30.0))
    assert any("made from the joints' drives" in str(n) for n in notes)
    link = next(b for b in back.bodies if b.name == "link")
    assert link.mass == pytest.approx(2.0)


@pytest.mark.parametrize("how", ["sublayer", "reference"])
def test_a_layer_outside_the_folder_is_refused(tmp_path, how):
    """An untrusted USD never makes us read outside its folder: a sublayer or reference
    pointing out is refused by name, exit 2, nothing written."""
    outside = tmp_path / "outside.usda"
    Usd.Stage.CreateNew(str(outside)).Save()
    inner = tmp_path / "robot"
    inner.mkdir()
    _two_link_usd(inner / "bot.usda")
    stage = Usd.Stage.Open(str(inner / "bot.usda"))
    if how == "sublayer":
        stage.GetRootLayer().subLayerPaths.append("../outside.usda")
    else:
        stage.GetPrimAtPath("/bot/base").GetReferences().AddReference("../outside.usda")
    stage.Save()
    run = subprocess.run(
        [sys.executable, "-m", "robotwright", "convert", "robot/bot.usda", "-o", "out"],
        capture_output=True,
        text=True,
        cwd=tmp_path,
    )
    assert run.returncode == 2, run.stderr[-2000:]
    assert "outside.usda" in run.stderr and "outside the file's folder" in run.stderr
    assert "Traceback" not in run.stderr
    assert not (tmp_path / "out").exists()


def test_a_mirrored_mesh_reads_back_mirrored_with_its_hull(tmp_path):
    """A negatively scaled mesh (talos' ``arm_6`` collision mesh, ``scale="1 -1 1"``)
    goes to USD as the prim's scale and comes back as the mesh's scale, not as mirrored
    points: the compiled mesh, its place and its hull (200 polygons; a mirrored copy of
    the points gets 198) are the source's."""
    from robotwright.catalog import find_entry
    from robotwright.parsers.api import mjcf_to_hrdf

    entry = find_entry("talos")
    if entry is None:
        pytest.skip("talos comes from example-robot-data (not installed)")
    stl = Path(entry.path).resolve().parents[1] / "meshes" / "arm" / "arm_6_collision.STL"
    (tmp_path / "arm_6.stl").write_bytes(stl.read_bytes())
    src = tmp_path / "mirrored.xml"
    src.write_text(
        '<mujoco><asset><mesh name="m" file="arm_6.stl" scale="1 -1 1"/></asset><worldbody>'
        '<body name="base"><geom type="box" size=".05 .05 .05"/><body name="arm" pos="0 0 .1">'
        '<joint name="j" axis="0 1 0"/><geom name="gm" type="mesh" mesh="m"/></body></body>'
        "</worldbody></mujoco>"
    )
    hrdf = mjcf_to_hrdf(src)
    with warnings.catch_warnings(record=True):
        warnings.simplefilter("always")
        to_usd(hrdf, tmp_path / "mirrored.usda")
    back, _ = usd_to_hrdf_with_warnings(tmp_path / "mirrored.usda", work_dir=tmp_path / "work")
    # Newton reads it as -1 -1 -1 turned half a turn; the prim's own scale is kept
    assert [m.scale for m in back.meshes] == [(1.0, -1.0, 1.0)]
    source = mujoco.MjModel.from_xml_path(str(src))
    result = _compiled(back, tmp_path / "b")
    assert result.mesh_polynum.tolist() == source.mesh_polynum.tolist() == [200]

    def world_vertices(model):
        data = mujoco.MjData(model)
        mujoco.mj_forward(model, data)
        g = model.geom("gm")
        v = model.mesh_vert[model.mesh_vertadr[0] : model.mesh_vertadr[0] + model.mesh_vertnum[0]]
        return v @ data.geom_xmat[g.id].reshape(3, 3).T + data.geom_xpos[g.id]

    a, b = world_vertices(source), world_vertices(result)
    nearest = np.linalg.norm(a[:, None] - b[None], axis=2).min(axis=1)
    assert nearest.max() < 1e-6  # float32 points
