"""Opt-in collision-mesh repairs: decimation to a face budget (fast-simplification) and
convex decomposition (CoACD), each reported with face counts and volume change; visual
meshes untouched. Compared on compiled MuJoCo models."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import mujoco
import numpy as np
import pytest
import trimesh

from robotwright.cli import main
from robotwright.errors import ConversionError
from robotwright.hrdf.model import HRDF, Body, Joint, MeshGeom
from robotwright.parsers import urdf_to_hrdf
from robotwright.parsers.collision import CollisionMeshConfig, repair_collision_meshes
from robotwright.proof.roundtrip.run import our_mjcf_model

ERD = Path(
    __import__("sysconfig").get_paths()["purelib"],
    "cmeel.prefix/share/example-robot-data/robots",
)
#: CoACD settings small enough for a unit test (a ring: a few parts in well under 1 s).
FAST = {"resolution": 300, "mcts_iterations": 20, "preprocess_resolution": 20}


def _need(module: str) -> None:
    pytest.importorskip(module, reason=f"{module} (meshfix extra) is not installed")


def _mesh_faces(model: mujoco.MjModel, geom: int) -> np.ndarray:
    mesh = model.geom_dataid[geom]
    start, n = model.mesh_faceadr[mesh], model.mesh_facenum[mesh]
    return model.mesh_face[start : start + n]


def _mesh_verts(model: mujoco.MjModel, geom: int) -> np.ndarray:
    mesh = model.geom_dataid[geom]
    start, n = model.mesh_vertadr[mesh], model.mesh_vertnum[mesh]
    return model.mesh_vert[start : start + n]


IDENTITY = (1.0, 0.0, 0.0, 0.0)
ORIGIN = {
    "pos": (0.0, 0.0, 0.0),
    "quat": IDENTITY,
    "inertial_pos": (0, 0, 0),
    "inertial_quat": IDENTITY,
}
LINK = {**ORIGIN, "pos": (0.0, 0.0, 0.2)}


def _ring_robot(tmp_path: Path) -> HRDF:
    """A two-body robot whose link carries one ring mesh twice: visual and collision."""
    ring = trimesh.creation.annulus(r_min=0.05, r_max=0.1, height=0.04, sections=48)
    path = tmp_path / "ring.stl"
    ring.export(str(path))
    common = {"body": "link", "file": str(path), "pos": (0.0, 0.0, 0.1)}
    return HRDF(
        name="ring",
        bodies=[
            Body(name="base", parent=-1, mass=1.0, diag_inertia=(0.01, 0.01, 0.01), **ORIGIN),
            Body(name="link", parent=0, mass=0.5, diag_inertia=(1e-3, 1e-3, 1e-3), **LINK),
        ],
        joints=[Joint(name="hinge", body="link", axis=(0.0, 1.0, 0.0))],
        meshes=[
            MeshGeom(name="ring_visual", contact_type=0, contact_affinity=0, group=2, **common),
            MeshGeom(name="ring", geom_name="ring_collision", **common),
        ],
    )


def test_decimation_to_a_face_budget_leaves_visuals(tmp_path: Path) -> None:
    _need("fast_simplification")
    robot = _ring_robot(tmp_path)
    repaired, report = repair_collision_meshes(robot, CollisionMeshConfig(max_faces=64))
    (rep,) = report
    assert rep.action == "decimated" and rep.faces_before == 384 and rep.faces_after <= 64
    ring = trimesh.load(str(tmp_path / "ring.stl"), force="mesh")
    assert rep.volume_before == pytest.approx(ring.volume, rel=1e-9)
    assert rep.volume_after is not None and abs(rep.volume_after / rep.volume_before - 1) < 0.5
    assert "384 -> " in str(rep) and "m^3" in str(rep) and "%" in str(rep)
    before, after = our_mjcf_model(robot), our_mjcf_model(repaired)
    assert before.ngeom == after.ngeom
    for g in range(before.ngeom):
        if before.geom_contype[g] == 0 and before.geom_conaffinity[g] == 0:  # visual
            np.testing.assert_array_equal(_mesh_verts(after, g), _mesh_verts(before, g))
            np.testing.assert_array_equal(_mesh_faces(after, g), _mesh_faces(before, g))
        elif before.geom_type[g] == mujoco.mjtGeom.mjGEOM_MESH:
            assert len(_mesh_faces(after, g)) == rep.faces_after < len(_mesh_faces(before, g))
    np.testing.assert_array_equal(after.body_mass, before.body_mass)
    assert str(robot.meshes[1].file).endswith("ring.stl")  # the input robot is unchanged


def test_decimation_skips_meshes_within_the_budget(tmp_path: Path) -> None:
    _need("fast_simplification")
    robot = _ring_robot(tmp_path)
    same, report = repair_collision_meshes(robot, CollisionMeshConfig(max_faces=1000))
    assert report == [] and same is robot


def test_convex_decomposition_of_a_ring(tmp_path: Path) -> None:
    _need("coacd")
    robot = _ring_robot(tmp_path)
    config = CollisionMeshConfig(convex_decomposition=True, **FAST)
    repaired, report = repair_collision_meshes(robot, config, out_dir=tmp_path / "parts")
    (rep,) = report
    assert rep.action == "decomposed" and rep.parts >= 3  # a ring is not convex
    parts = [m for m in repaired.meshes if m.contact_type or m.contact_affinity]
    assert len(parts) == rep.parts
    assert all(Path(m.file).parent == (tmp_path / "parts").resolve() for m in parts)
    assert [m.geom_name for m in parts] == [f"ring_collision_part{k}" for k in range(rep.parts)]
    model = our_mjcf_model(repaired)
    original = our_mjcf_model(robot)
    assert model.ngeom == original.ngeom - 1 + rep.parts
    # each part is convex: its compiled hull has as many faces as the part itself
    total = 0
    for g in range(model.ngeom):
        if model.geom_contype[g] and model.geom_type[g] == mujoco.mjtGeom.mjGEOM_MESH:
            hull = trimesh.Trimesh(_mesh_verts(model, g)).convex_hull
            part = trimesh.Trimesh(_mesh_verts(model, g), _mesh_faces(model, g))
            assert part.volume == pytest.approx(hull.volume, rel=1e-6)
            total += part.volume
    assert rep.volume_after == pytest.approx(total, rel=1e-6)
    # the parts fill the ring, not its hole: far less than the ring's convex hull (a disc)
    ring = trimesh.load(str(tmp_path / "ring.stl"), force="mesh")
    assert total < 0.8 * ring.convex_hull.volume
    assert abs(total / ring.volume - 1) < 0.5


@pytest.mark.realdata
def test_ur5_collision_meshes_decimated_real(tmp_path: Path) -> None:
    _need("fast_simplification")
    path = ERD / "ur_description/urdf/ur5_robot.urdf"
    if not path.is_file():
        pytest.skip(f"example-robot-data absent: {path}")
    robot = urdf_to_hrdf(path)
    repaired, report = repair_collision_meshes(robot, CollisionMeshConfig(max_faces=400))
    assert len(report) == 7  # every link: its collision mesh has 446 to 1176 faces
    assert all(r.faces_before > 400 >= r.faces_after for r in report)
    before, after = our_mjcf_model(robot), our_mjcf_model(repaired)
    np.testing.assert_array_equal(after.body_mass, before.body_mass)
    np.testing.assert_array_equal(after.body_inertia, before.body_inertia)
    visual = (before.geom_contype == 0) & (before.geom_conaffinity == 0)
    rng = np.random.default_rng(3)
    da, db = mujoco.MjData(before), mujoco.MjData(after)
    for _ in range(5):
        da.qpos[:] = db.qpos[:] = rng.uniform(-1, 1, before.nq)
        mujoco.mj_kinematics(before, da)
        mujoco.mj_kinematics(after, db)
        np.testing.assert_array_equal(da.xpos, db.xpos)
        # visual geoms in place; a collision mesh's frame is its (new) centroid in MuJoCo
        np.testing.assert_array_equal(da.geom_xpos[visual], db.geom_xpos[visual])
    for g in np.flatnonzero(visual):
        np.testing.assert_array_equal(_mesh_faces(after, g), _mesh_faces(before, g))
    for g in np.flatnonzero(~visual & (before.geom_type == mujoco.mjtGeom.mjGEOM_MESH)):
        assert len(_mesh_faces(after, g)) <= 400


def test_config_is_validated() -> None:
    with pytest.raises(ValueError, match="max_faces=2"):
        CollisionMeshConfig(max_faces=2)
    with pytest.raises(ValueError, match="threshold"):
        CollisionMeshConfig(convex_decomposition=True, threshold=0)
    with pytest.raises(ValueError, match="resolution"):
        CollisionMeshConfig(convex_decomposition=True, resolution=0)
    assert not CollisionMeshConfig().active


def test_missing_package_is_named(tmp_path: Path, monkeypatch) -> None:
    import sys

    monkeypatch.setitem(sys.modules, "fast_simplification", None)  # import fails
    with pytest.raises(ConversionError, match=r"fast-simplification.*robotwright\[meshfix\]"):
        repair_collision_meshes(_ring_robot(tmp_path), CollisionMeshConfig(max_faces=64))


def test_cli_convert_reports_the_repair(tmp_path: Path, capsys) -> None:
    _need("fast_simplification")
    folder = tmp_path / "ring_hrdf"
    _ring_robot(tmp_path).save(folder)  # copies the mesh files into the folder
    out = tmp_path / "ring.xml"
    argv = ["convert", str(folder), "--collision-max-faces", "64", "-v", "-o", str(out)]
    assert main(argv) == 0
    err = capsys.readouterr().err
    assert "collision mesh 'ring' of body 'link' decimated: 384 -> " in err
    model = mujoco.MjModel.from_xml_path(str(out))
    mesh = mujoco.mjtGeom.mjGEOM_MESH
    collision = [
        g for g in range(model.ngeom) if model.geom_contype[g] and model.geom_type[g] == mesh
    ]
    assert [len(_mesh_faces(model, g)) <= 64 for g in collision] == [True]
    assert main([*argv[:3], "2", *argv[4:-1], str(tmp_path / "bad.xml")]) == 2
    assert "max_faces=2" in capsys.readouterr().err and not (tmp_path / "bad.xml").exists()


def test_a_mesh_shared_by_collision_geoms_is_repaired_once(tmp_path: Path) -> None:
    _need("fast_simplification")
    robot = _ring_robot(tmp_path)
    twin = replace(robot.meshes[1], body="base", geom_name="base_ring")
    robot = replace(robot, meshes=[*robot.meshes, twin])
    out = tmp_path / "out"
    repaired, report = repair_collision_meshes(robot, CollisionMeshConfig(max_faces=64), out)
    assert [r.body for r in report] == ["link", "base"]
    assert report[0].faces_after == report[1].faces_after
    assert len(list(out.iterdir())) == 1  # one decimated file, used by both geoms
    collision = [m for m in repaired.meshes if m.contact_type]
    assert len({m.file for m in collision}) == 1 and len(collision) == 2
    assert [m.geom_name for m in collision] == ["ring_collision", "base_ring"]
