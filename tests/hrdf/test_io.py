"""Reading and writing HRDF folders: hurodes fixtures, round trips, determinism."""

from __future__ import annotations

import csv
import math
import shutil
from pathlib import Path

import mujoco
import numpy as np
import pytest

from robotwright.hrdf import HRDF, Actuator, Joint
from robotwright.hrdf.assets import BUNDLED_ROBOTS_DIR, RobotNotFoundError, bundled_robot_names
from robotwright.hrdf.io import HRDFWarning

pytestmark = pytest.mark.filterwarnings("ignore::robotwright.hrdf.io.HRDFWarning")

HURODES_TABLES = ("body", "joint", "actuator", "mesh", "simple_geom")


def _csv_rows(path: Path) -> list[dict[str, str]]:
    with path.open(newline="") as f:
        return list(csv.DictReader(f))


def test_g1_counts_and_mass(g1_hrdf_dir: Path, g1_source_mjcf: Path) -> None:
    """What hurodes wrote is the source G1 as MuJoCo compiles it: counts, masses, tree."""
    src = mujoco.MjModel.from_xml_path(str(g1_source_mjcf))
    hrdf = HRDF.from_dir(g1_hrdf_dir)
    assert src.nu == 29 and src.body_jntnum[1] == 1  # the 29-motor G1, floating base
    assert len(hrdf.bodies) == src.nbody - 1
    assert math.isclose(hrdf.total_mass, src.body_subtreemass[0], rel_tol=1e-12)
    csv_total = math.fsum(float(r["mass"]) for r in _csv_rows(g1_hrdf_dir / "body.csv"))
    assert math.isclose(hrdf.total_mass, csv_total, rel_tol=1e-15)
    hinges = [j for j in hrdf.joints if j.type == "hinge"]
    assert len(hinges) == int(np.sum(src.jnt_type == mujoco.mjtJoint.mjJNT_HINGE))
    free = [j for j in hrdf.joints if j.type == "free"]
    assert len(free) == 1 and free[0].body == src.body(1).name and free[0].name is None
    assert hrdf.floating_base
    assert len(hrdf.actuators) == src.nu
    is_mesh = src.geom_type == mujoco.mjtGeom.mjGEOM_MESH
    assert len(hrdf.meshes) == int(np.sum(is_mesh)) and src.nmesh > 30
    assert len(hrdf.simple_geoms) == int(np.sum(~is_mesh))
    assert hrdf.dof == src.nv


def test_g1_values_identical_to_csv(g1_hrdf_dir: Path, g1_source_mjcf: Path) -> None:
    hrdf = HRDF.from_dir(g1_hrdf_dir)
    for i, row in enumerate(_csv_rows(g1_hrdf_dir / "body.csv")):
        b = hrdf.bodies[i]
        assert b.name == row["name"]
        assert b.mass == float(row["mass"])
        assert b.diag_inertia == tuple(float(row[f"diag_inertia{k}"]) for k in range(3))
        assert b.inertial_quat == tuple(float(row[f"inertial_quat{k}"]) for k in range(4))
        assert b.pos == tuple(float(row[f"pos{k}"]) for k in range(3))
    joints = [j for j in hrdf.joints if j.type != "free"]
    for j, row in zip(joints, _csv_rows(g1_hrdf_dir / "joint.csv"), strict=True):
        assert j.name == row["name"] and j.body == row["body_name"]
        assert j.range == (float(row["range0"]), float(row["range1"]))
        assert j.armature == float(row["armature"])
        assert j.dynamic_friction == float(row["dynamic_friction"])
    for a, row in zip(hrdf.actuators, _csv_rows(g1_hrdf_dir / "actuator.csv"), strict=True):
        assert a.joint == row["joint_name"]
        assert a.peak_torque == float(row["peak_torque"])
        assert a.p_gain is None and a.d_gain is None and a.peak_velocity is None
    src = mujoco.MjModel.from_xml_path(str(g1_source_mjcf))
    assert [b.name for b in hrdf.bodies] == [src.body(i).name for i in range(1, src.nbody)]
    assert [b.parent for b in hrdf.bodies] == (src.body_parentid[1:] - 1).tolist()
    assert hrdf.meta.simulator_config.timestep == 0.002
    assert hrdf.meta.imu_config_list[0].body_name == "pelvis"
    assert hrdf.meta.body_name_config.torso_name == "torso_link"
    assert hrdf.meta.format_version is None


def test_synth_fixture(synth_hrdf_dir: Path) -> None:
    hrdf = HRDF.from_dir(synth_hrdf_dir)
    assert [b.name for b in hrdf.bodies] == ["base", "l1"]
    assert hrdf.joints[1] == Joint(
        name="j1", body="l1", type="hinge", axis=(0.0, 1.0, 0.0), range=(-1.0, 1.0)
    )
    assert hrdf.simple_geoms[0].type == "capsule" and hrdf.simple_geoms[0].size == (0.02, 0.1, 0.0)
    assert hrdf.mesh_path(hrdf.meshes[0]).is_file()


def test_hurodes_tables_written_byte_identical(g1_hrdf_dir: Path, tmp_path: Path) -> None:
    hrdf = HRDF.from_dir(g1_hrdf_dir)
    out = hrdf.save(tmp_path / "g1")
    for stem in HURODES_TABLES:
        assert (out / f"{stem}.csv").read_bytes() == (g1_hrdf_dir / f"{stem}.csv").read_bytes(), (
            stem
        )
    assert sorted(p.name for p in (out / "meshes").iterdir()) == sorted(
        p.name for p in (g1_hrdf_dir / "meshes").iterdir()
    )


def test_load_save_load_equal_and_deterministic(g1_hrdf_dir: Path, tmp_path: Path) -> None:
    first = HRDF.from_dir(g1_hrdf_dir)
    a = HRDF.from_dir(first.save(tmp_path / "a"))
    b = HRDF.from_dir(a.save(tmp_path / "b"))
    for field in ("bodies", "joints", "actuators", "meshes", "simple_geoms", "sites", "sensors"):
        assert getattr(a, field) == getattr(first, field), field
        assert getattr(b, field) == getattr(a, field), field
    assert a.meta == b.meta
    for f in sorted(p.name for p in (tmp_path / "a").iterdir() if p.is_file()):
        assert (tmp_path / "a" / f).read_bytes() == (tmp_path / "b" / f).read_bytes(), f


@pytest.mark.parametrize("name", ["mini_humanoid", "arm6"])
def test_bundled_robots_round_trip(name: str, tmp_path: Path) -> None:
    hrdf = HRDF.from_robot_name(name)
    again = HRDF.from_dir(hrdf.save(tmp_path / name))
    assert again.bodies == hrdf.bodies
    assert again.joints == hrdf.joints
    assert again.actuators == hrdf.actuators
    assert again.sites == hrdf.sites and again.sensors == hrdf.sensors
    assert again.simple_geoms == hrdf.simple_geoms


def test_extension_columns_round_trip(tmp_path: Path) -> None:
    hrdf = HRDF.from_robot_name("arm6")
    assert not hrdf.floating_base
    servo = hrdf.actuators[0]
    assert servo.type == "position" and servo.p_gain == 200.0 and servo.ctrl_range == (-2.9, 2.9)
    joints = list(hrdf.joints)
    joints[0] = Joint(
        name=joints[0].name, body=joints[0].body, type="slide", axis=(0.0, 0.0, 1.0), range=None
    )
    joints.append(Joint(name="extra_hinge", body=joints[0].body, axis=(1.0, 0.0, 0.0), ref=0.1))
    hrdf.joints = joints
    hrdf.actuators = [
        *hrdf.actuators,
        Actuator(joint="extra_hinge", name="v", type="velocity", d_gain=3.0, gear=2.5),
    ]
    again = HRDF.from_dir(hrdf.save(tmp_path / "ext"))
    assert again.joints == hrdf.joints
    assert again.joints[0].range is None
    assert again.actuators[-1] == hrdf.actuators[-1]


def test_floats_written_back_identically(tmp_path: Path) -> None:
    hrdf = HRDF.from_robot_name("arm6")
    body = hrdf.bodies[1]
    odd = (0.1 + 0.2, 1e-17, 123456.789012345678)
    from dataclasses import replace

    hrdf.bodies[1] = replace(body, pos=odd)
    again = HRDF.from_dir(hrdf.save(tmp_path / "f"))
    assert again.bodies[1].pos == odd


def test_save_refuses_existing_without_overwrite(tmp_path: Path) -> None:
    hrdf = HRDF.from_robot_name("arm6")
    hrdf.save(tmp_path / "x")
    with pytest.raises(FileExistsError):
        hrdf.save(tmp_path / "x")
    hrdf.save(tmp_path / "x", overwrite=True)
    assert (tmp_path / "x" / "meta.yaml").is_file()


def test_failed_save_leaves_nothing(tmp_path: Path) -> None:
    hrdf = HRDF.from_robot_name("arm6")
    from dataclasses import replace

    hrdf.bodies[2] = replace(hrdf.bodies[2], mass=-1.0)
    from robotwright.errors import HRDFError

    with pytest.raises(HRDFError, match="mass"):
        hrdf.save(tmp_path / "bad")
    assert list(tmp_path.iterdir()) == []


def test_failed_mesh_copy_leaves_nothing(synth_hrdf_dir: Path, tmp_path: Path) -> None:
    src = tmp_path / "src"
    shutil.copytree(synth_hrdf_dir, src)
    hrdf = HRDF.from_dir(src)
    # The mesh disappears after loading: the copy fails half-way through the save.
    (src / "meshes" / "box.stl").unlink()
    with pytest.raises(Exception, match="box.stl"):
        hrdf.save(tmp_path / "out")
    assert not (tmp_path / "out").exists()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["src"]


def test_from_robot_name_env_then_bundled(
    synth_hrdf_dir: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    assets = tmp_path / "assets"
    shutil.copytree(synth_hrdf_dir, assets / "robots" / "arm6")
    monkeypatch.setenv("HURODES_ASSETS_PATH", str(assets))
    # The user's assets root shadows the bundled robot of the same name.
    assert [b.name for b in HRDF.from_robot_name("arm6").bodies] == ["base", "l1"]
    monkeypatch.delenv("HURODES_ASSETS_PATH")
    assert HRDF.from_robot_name("arm6").bodies[0].name == "base_link"
    with pytest.raises(RobotNotFoundError, match="no robot named 'nope'"):
        HRDF.from_robot_name("nope")


def test_bundled_robot_names() -> None:
    assert {"mini_humanoid", "arm6"} <= set(bundled_robot_names())
    assert (BUNDLED_ROBOTS_DIR / "mini_humanoid" / "meta.yaml").is_file()


def test_unknown_file_warns(synth_hrdf_dir: Path, tmp_path: Path) -> None:
    src = tmp_path / "r"
    shutil.copytree(synth_hrdf_dir, src)
    (src / "notes.txt").write_text("hi")
    with pytest.warns(HRDFWarning, match="notes.txt"):
        HRDF.from_dir(src)


def test_hurodes_export_folder_is_ignored_quietly(synth_hrdf_dir: Path, tmp_path: Path) -> None:
    """hurodes exports a robot into ``<folder>/exported/`` by default: not robot data,
    and no warning on every load."""
    import warnings

    src = tmp_path / "r"
    shutil.copytree(synth_hrdf_dir, src)
    (src / "exported").mkdir()
    (src / "exported" / "robot.xml").write_text("<mujoco/>")
    with warnings.catch_warnings():
        warnings.simplefilter("error", HRDFWarning)
        loaded = HRDF.from_dir(src)
    assert loaded.bodies == HRDF.from_dir(synth_hrdf_dir).bodies


def test_schemas_cover_every_record_field() -> None:
    # The reader builds records from schema rows without calling __init__.
    import dataclasses

    from robotwright.hrdf.io import _RECORD_TYPES
    from robotwright.hrdf.tables import TABLES

    for stem, cls in _RECORD_TYPES.items():
        fields = {f.name for f in dataclasses.fields(cls)}
        schema = {c.field for c in TABLES[stem]}
        if stem == "body":
            fields, schema = fields - {"parent"}, schema - {"id"}
        assert fields == schema, stem
