"""Every command that reads a robot takes each kind of source: a name, an HRDF folder, a
URDF, a xacro and an MJCF file (made small in tmp_path), with the shared options."""

from __future__ import annotations

import shutil
from pathlib import Path

import mujoco
import pytest

from robotwright.cli import main
from robotwright.hrdf.assets import BUNDLED_ROBOTS_DIR

_INERTIA = '<inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/>'
URDF = f"""<robot name="two">
  <link name="base"><inertial><mass value="1"/>{_INERTIA}</inertial>
    <collision><geometry><box size="0.2 0.2 0.2"/></geometry></collision></link>
  <link name="arm"><inertial><mass value="0.5"/>{_INERTIA}</inertial>
    <visual><geometry><cylinder radius="0.03" length="0.3"/></geometry></visual></link>
  <link name="tool"/>
  <joint name="j1" type="revolute"><parent link="base"/><child link="arm"/>
    <origin xyz="0 0 0.2"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" effort="5" velocity="2"/></joint>
  <joint name="fix" type="fixed"><parent link="arm"/><child link="tool"/>
    <origin xyz="0 0 0.3"/></joint>
</robot>
"""
XACRO = """<robot name="xtwo" xmlns:xacro="http://www.ros.org/wiki/xacro">
  <xacro:arg name="len" default="0.3"/>
  <link name="base"><inertial><mass value="1"/>
    <inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>
    <visual><geometry><box size="0.2 0.2 $(arg len)"/></geometry></visual></link>
</robot>
"""
MJCF = """<mujoco model="mtwo">
  <worldbody>
    <body name="a" pos="0 0 0.5">
      <joint name="ja" type="hinge"/>
      <geom type="capsule" size="0.05 0.2" mass="1"/>
    </body>
  </worldbody>
</mujoco>
"""


@pytest.fixture
def sources(tmp_path: Path) -> dict[str, str]:
    (tmp_path / "two.urdf").write_text(URDF)
    (tmp_path / "xtwo.urdf.xacro").write_text(XACRO)
    (tmp_path / "mtwo.xml").write_text(MJCF)
    shutil.copytree(BUNDLED_ROBOTS_DIR / "arm6", tmp_path / "arm_copy")
    return {
        "name": "arm6",
        "hrdf": str(tmp_path / "arm_copy"),
        "urdf": str(tmp_path / "two.urdf"),
        "xacro": str(tmp_path / "xtwo.urdf.xacro"),
        "mjcf": str(tmp_path / "mtwo.xml"),
    }


KINDS = ("name", "hrdf", "urdf", "xacro", "mjcf")


@pytest.mark.parametrize("kind", KINDS)
def test_info_and_validate_take_every_kind(sources, kind, capsys):
    assert main(["info", sources[kind]]) == 0
    assert "robot " in capsys.readouterr().out
    assert main(["validate", sources[kind]]) == 0
    assert "valid" in capsys.readouterr().out


@pytest.mark.parametrize("kind", KINDS)
def test_export_takes_every_kind_and_the_output_compiles(sources, kind, tmp_path):
    out = tmp_path / "out" / f"{kind}.xml"
    out.parent.mkdir()
    assert main(["export", sources[kind], "-o", str(out)]) == 0
    model = mujoco.MjModel.from_xml_path(str(out))
    assert model.nbody >= 2


def test_compose_takes_a_file_next_to_a_name(sources, tmp_path):
    out = tmp_path / "scene.xml"
    assert main(["compose", f"u={sources['urdf']}", "arm6@1,0,0", "-o", str(out)]) == 0
    model = mujoco.MjModel.from_xml_path(str(out))
    names = {model.body(i).name for i in range(model.nbody)}
    assert any(n.startswith("u_") for n in names) and any(n.startswith("arm6_") for n in names)


@pytest.mark.parametrize("kind", KINDS)
def test_things_takes_every_kind(sources, kind, tmp_path):
    out = tmp_path / f"things_{kind}.xml"
    assert main(["things", sources[kind], str(out)]) == 0
    assert mujoco.MjModel.from_xml_path(str(out)).nbody >= 2


@pytest.mark.parametrize("kind", KINDS)
def test_render_takes_every_kind(sources, kind, tmp_path):
    out = tmp_path / f"{kind}.png"
    assert main(["render", sources[kind], "-o", str(out), "--size", "64x48"]) == 0
    assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


@pytest.mark.parametrize("kind", ("name", "urdf", "mjcf"))
def test_convert_and_lidar_take_a_source(sources, kind, tmp_path):
    out = tmp_path / f"conv_{kind}.xml"
    assert main(["convert", sources[kind], "-o", str(out)]) == 0
    assert out.is_file()
    body = {"name": "base_link", "urdf": "arm", "mjcf": "a"}[kind]
    scan = tmp_path / f"scan_{kind}.npz"
    code = main(["lidar", sources[kind], "--sensor", body, "--include-robot", "-o", str(scan)])
    assert code == 0 and scan.is_file()


def test_fixed_joints_merge_changes_the_bodies(sources, capsys):
    assert main(["info", sources["urdf"]]) == 0
    kept = capsys.readouterr().out
    assert main(["info", sources["urdf"], "--fixed-joints", "merge"]) == 0
    merged = capsys.readouterr().out
    assert "tool" in kept.split("joint  ")[0]
    assert "tool" not in merged.split("joint  ")[0]


def test_xacro_arg_reaches_the_expansion(sources, tmp_path):
    out = tmp_path / "x.xml"
    assert main(["export", sources["xacro"], "--xacro-arg", "len:=0.8", "-o", str(out)]) == 0
    model = mujoco.MjModel.from_xml_path(str(out))
    assert model.geom_size[:, 2].max() == pytest.approx(0.4)


def test_root_body_picks_the_mjcf_robot(tmp_path, capsys):
    two = MJCF.replace(
        "</worldbody>",
        '<body name="other" pos="1 0 0.5"><geom type="box" size="0.1 0.1 0.1"/></body></worldbody>',
    )
    (tmp_path / "w.xml").write_text(two)
    # The whole world is a scene of two roots; --root-body takes one robot out of it.
    assert main(["info", str(tmp_path / "w.xml")]) == 0
    whole = capsys.readouterr().out
    assert "a scene of 2 roots: " in whole and "other (fixed)" in whole
    assert main(["info", str(tmp_path / "w.xml"), "--root-body", "other"]) == 0
    out = capsys.readouterr().out
    assert "robot " in out and " 0 joints" in out


def test_an_option_for_another_kind_is_refused(sources, capsys):
    assert main(["info", sources["mjcf"], "--bound-mass", "0.1"]) == 2
    err = capsys.readouterr().err
    assert err.startswith("error:") and "--bound-mass" in err and len(err.splitlines()) == 1


@pytest.mark.parametrize("text", ["no_such_robot_xyz", "missing.urdf", "./nothing_here"])
def test_unknown_source_is_one_line(text, capsys):
    assert main(["info", text]) == 2
    err = capsys.readouterr().err
    assert err.startswith("error:") and len(err.splitlines()) == 1


def test_package_option_on_info_resolves_meshes(tmp_path, capsys):
    pkg = tmp_path / "meshpkg" / "meshes"
    pkg.mkdir(parents=True)
    import trimesh

    trimesh.creation.box((0.1, 0.1, 0.1)).export(pkg / "b.stl")
    robot = tmp_path / "r"
    robot.mkdir()
    (robot / "r.urdf").write_text(
        URDF.replace(
            '<box size="0.2 0.2 0.2"/>', '<mesh filename="package://meshpkg/meshes/b.stl"/>'
        )
    )
    assert main(["info", str(robot / "r.urdf")]) == 2
    assert "--package meshpkg=DIR" in capsys.readouterr().err
    assert (
        main(["info", str(robot / "r.urdf"), "--package", f"meshpkg={tmp_path / 'meshpkg'}"]) == 0
    )


def test_unfound_package_is_one_line_per_package(tmp_path, capsys):
    links = "".join(
        f'<link name="l{i}"><inertial><mass value="1"/>{_INERTIA}</inertial><visual><geometry>'
        f'<mesh filename="package://{"pa" if i % 2 else "pb"}/m{i}.stl"/></geometry></visual></link>'
        for i in range(9)
    )
    joints = "".join(
        f'<joint name="j{i}" type="fixed"><parent link="l{i - 1}"/><child link="l{i}"/></joint>'
        for i in range(1, 9)
    )
    (tmp_path / "r.urdf").write_text(f'<robot name="r">{links}{joints}</robot>')
    assert main(["render", str(tmp_path / "r.urdf"), "-o", str(tmp_path / "r.png")]) == 2
    err = capsys.readouterr().err
    items = [line for line in err.splitlines() if line.startswith("  - ")]
    assert len(items) == 2  # pa and pb, not nine meshes
    for name in ("pa", "pb"):
        (line,) = [i for i in items if f"'{name}'" in i]
        assert f"--package {name}=DIR" in line and "ROS_PACKAGE_PATH" in line
    assert not (tmp_path / "r.png").exists()


def test_render_shows_a_robot_whose_physics_is_refused(tmp_path, capsys):
    bad = URDF.replace(
        '<inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>\n'
        "    <visual>",
        '<inertia ixx="0.0" iyy="0.0" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>\n'
        "    <visual>",
    )
    assert bad != URDF
    (tmp_path / "bad.urdf").write_text(bad)
    assert main(["export", str(tmp_path / "bad.urdf"), "-o", str(tmp_path / "bad.xml")]) == 2
    capsys.readouterr()
    assert not (tmp_path / "bad.xml").exists()
    out = tmp_path / "bad.png"
    assert main(["render", str(tmp_path / "bad.urdf"), "-o", str(out), "--size", "64x48"]) == 0
    err = capsys.readouterr().err
    assert "physics refused" in err and "arm" in err
    assert out.is_file()


def test_the_python_loader_takes_every_kind(sources):
    from robotwright.sources import load_robot

    names = {k: load_robot(v).name for k, v in sources.items()}
    assert names["urdf"] == "two" and names["mjcf"] == "mtwo" and names["name"] == "arm6"
