"""Hostile MJCF and URDF files (issue 11): file paths that leave the model's folder
(``..``, absolute paths, ``meshdir``, symbolic links, includes, textures) are refused by
the parsers, ``convert`` and ``things`` with an error naming the file and element, and
nothing is written; trusted folders are an explicit opt-in."""

from __future__ import annotations

import os
import re
import threading
from pathlib import Path

import mujoco
import pytest
import trimesh

from robotwright.cli import main
from robotwright.errors import ConversionError
from robotwright.parsers import mjcf_to_hrdf, urdf_to_hrdf

MODEL = """<mujoco model="m">
  <compiler angle="radian"{compiler}/>
  <asset>{assets}<mesh name="part" file="{file}"/></asset>
  <worldbody>
    <body name="base">
      <joint name="j" type="hinge"/>
      <geom type="mesh" mesh="part" mass="1"/>
    </body>
  </worldbody>
</mujoco>
"""


def _stl(path: Path, size: float = 0.05) -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    trimesh.creation.box(extents=(size, size, size)).export(str(path), file_type="stl")
    return path


@pytest.fixture
def outside(tmp_path: Path) -> Path:
    folder = tmp_path / "outside"
    _stl(folder / "secret.stl", size=0.3)
    return folder


@pytest.fixture
def robot(tmp_path: Path) -> Path:
    folder = tmp_path / "robot"
    _stl(folder / "part.stl")
    return folder


def _model(folder: Path, *, file: str = "part.stl", compiler: str = "", assets: str = "") -> Path:
    path = folder / "model.xml"
    path.write_text(MODEL.format(file=file, compiler=compiler, assets=assets))
    return path


def _refused_everywhere(model: Path, tmp_path: Path, capsys, element: str) -> str:
    """The parser raises; convert (three targets) and things exit 2 and write nothing."""
    with pytest.raises(ConversionError) as exc:
        mjcf_to_hrdf(model)
    message = str(exc.value)
    assert str(model) in message and element in message, message
    assert "outside the robot folder" in message
    outs = tmp_path / "outs"
    outs.mkdir()
    for argv in (
        ["convert", str(model), "-o", str(outs / "hrdf")],
        ["convert", str(model), "-o", str(outs / "r.xml")],
        ["convert", str(model), "-o", str(outs / "r.urdf")],
        ["things", str(model), str(outs / "t.xml")],
        ["things", str(model), str(outs / "t_hrdf")],
    ):
        assert main(argv) == 2, argv
        err = capsys.readouterr().err
        assert element in err and "outside the robot folder" in err, (argv, err)
    assert list(outs.iterdir()) == []
    return message


def test_plain_model_converts(robot: Path, tmp_path: Path) -> None:
    assert len(mjcf_to_hrdf(_model(robot)).meshes) == 1


def test_dotdot_mesh_file_is_refused(robot, outside, tmp_path, capsys) -> None:
    model = _model(robot, file="../outside/secret.stl")
    _refused_everywhere(model, tmp_path, capsys, '<mesh name="part" file="../outside/secret.stl">')


def test_absolute_mesh_file_is_refused(robot, outside, tmp_path, capsys) -> None:
    secret = outside / "secret.stl"
    model = _model(robot, file=str(secret))
    text = _refused_everywhere(model, tmp_path, capsys, f'file="{secret}"')
    assert f"resolves to {secret}" in text


@pytest.mark.parametrize("meshdir", ["absolute", "../outside", "assetdir"])
def test_meshdir_leading_out_is_refused(robot, outside, tmp_path, capsys, meshdir) -> None:
    attr = {
        "absolute": f' meshdir="{outside}"',
        "../outside": ' meshdir="../outside"',
        "assetdir": f' assetdir="{outside}"',
    }[meshdir]
    model = _model(robot, file="secret.stl", compiler=attr)
    _refused_everywhere(model, tmp_path, capsys, '<mesh name="part" file="secret.stl">')


def test_symlinked_mesh_is_refused(robot, outside, tmp_path, capsys) -> None:
    (robot / "part.stl").unlink()
    (robot / "part.stl").symlink_to(outside / "secret.stl")
    text = _refused_everywhere(_model(robot), tmp_path, capsys, '<mesh name="part"')
    assert "through a symbolic link" in text


def test_texture_file_leading_out_is_refused(robot, outside, tmp_path, capsys) -> None:
    (outside / "t.png").write_bytes(b"not read")
    assets = '<texture name="t" type="2d" file="../outside/t.png"/>'
    model = _model(robot, assets=assets)
    _refused_everywhere(model, tmp_path, capsys, '<texture name="t" file="../outside/t.png">')


def test_include_leading_out_is_refused(robot, outside, tmp_path, capsys) -> None:
    (outside / "inc.xml").write_text("<mujoco><option timestep='0.01'/></mujoco>")
    model = _model(robot)
    model.write_text(
        model.read_text().replace("<asset>", '<include file="../outside/inc.xml"/><asset>')
    )
    _refused_everywhere(model, tmp_path, capsys, '<include file="../outside/inc.xml">')


def test_nested_include_is_checked_and_read_safely(robot, outside) -> None:
    """An included file inside the folder may not include a file outside, nor hide
    entities from the safe reader (MuJoCo's own reader would expand them)."""
    (robot / "a.xml").write_text('<mujoco><include file="../outside/inc.xml"/></mujoco>')
    (outside / "inc.xml").write_text("<mujoco/>")
    model = _model(robot)
    model.write_text(model.read_text().replace("<asset>", '<include file="a.xml"/><asset>'))
    with pytest.raises(ConversionError, match=r"a\.xml: <include file=\"\.\./outside/inc\.xml\">"):
        mjcf_to_hrdf(model)
    (robot / "a.xml").write_text(
        '<?xml version="1.0"?><!DOCTYPE m [<!ENTITY e "x">]><mujoco model="&e;"/>'
    )
    with pytest.raises(ConversionError, match="cannot be read as safe XML"):
        mjcf_to_hrdf(model)


def test_trusted_asset_root_is_an_explicit_opt_in(robot, outside, tmp_path, capsys) -> None:
    model = _model(robot, file=str(outside / "secret.stl"))
    hrdf = mjcf_to_hrdf(model, asset_roots=(outside,))
    assert len(hrdf.meshes) == 1
    out = tmp_path / "copy"
    assert main(["convert", str(model), "-o", str(out), "--asset-root", str(outside)]) == 0
    assert (out / "meshes" / "secret.stl").is_file()
    assert main(["things", str(model), str(tmp_path / "t.xml"), "--asset-root", str(outside)]) == 0


# ------------------------------------------------------------------------------- URDF

URDF = """<robot name="r">
  <link name="base"><inertial><mass value="1"/><inertia ixx="1" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/></inertial>
    <visual><geometry><mesh filename="{uri}"/></geometry></visual></link>
</robot>
"""


def test_urdf_package_found_among_ancestors_must_be_a_package(tmp_path: Path) -> None:
    """``package://outside/secret.stl`` used to name any folder called ``outside`` next to
    an ancestor (``package://etc/passwd`` named ``/etc``)."""
    _stl(tmp_path / "outside" / "secret.stl")
    path = tmp_path / "robot" / "urdf" / "r.urdf"
    path.parent.mkdir(parents=True)
    path.write_text(URDF.format(uri="package://outside/secret.stl"))
    with pytest.raises(ConversionError, match="package 'outside' not found") as exc:
        urdf_to_hrdf(path)
    assert '<link name="base">' in str(exc.value)
    # A real ROS package (package.xml) beside the robot is a sibling: found only when the
    # user names it (package_map / --package).
    (tmp_path / "outside" / "package.xml").write_text("<package><name>outside</name></package>")
    with pytest.raises(ConversionError, match="package 'outside' not found"):
        urdf_to_hrdf(path)
    named = urdf_to_hrdf(path, package_map={"outside": tmp_path / "outside"})
    assert len(named.meshes) == 1


def test_urdf_symlinked_mesh_is_refused(tmp_path: Path, capsys) -> None:
    secret = _stl(tmp_path / "outside" / "secret.stl")
    path = tmp_path / "robot" / "urdf" / "r.urdf"
    (tmp_path / "robot" / "meshes").mkdir(parents=True)
    (tmp_path / "robot" / "meshes" / "m.stl").symlink_to(secret)
    path.parent.mkdir(parents=True)
    (tmp_path / "robot" / "package.xml").write_text("<package><name>robot</name></package>")
    path.write_text(URDF.format(uri="../meshes/m.stl"))
    with pytest.raises(ConversionError, match="through a symbolic link") as exc:
        urdf_to_hrdf(path)
    assert "outside the robot folder" in str(exc.value)
    assert main(["convert", str(path), "-o", str(tmp_path / "out.xml")]) == 2
    assert not (tmp_path / "out.xml").exists()
    assert len(urdf_to_hrdf(path, asset_roots=(tmp_path / "outside",)).meshes) == 1


# ----------------------------------------------------------- unreadable sources


def _run_in_thread(argv: list[str]) -> int:
    done: dict = {}
    thread = threading.Thread(target=lambda: done.update(code=main(argv)), daemon=True)
    thread.start()
    thread.join(20)
    assert not thread.is_alive(), f"hung: {argv}"
    return done["code"]


@pytest.mark.parametrize("command", ["convert", "roundtrip", "things"])
def test_fifo_source_is_refused_without_hanging(tmp_path, capsys, command) -> None:
    source = tmp_path / "robot.xml"
    os.mkfifo(source)
    argv = {
        "convert": ["convert", str(source), "-o", str(tmp_path / "out.xml")],
        "roundtrip": ["roundtrip", str(source)],
        "things": ["things", str(source), str(tmp_path / "out.xml")],
    }[command]
    assert _run_in_thread(argv) == 2
    captured = capsys.readouterr()
    assert str(source) in captured.err and ("FIFO" in captured.err or "regular" in captured.err)
    assert captured.out == ""
    assert not (tmp_path / "out.xml").exists()


@pytest.mark.parametrize("command", ["convert", "roundtrip", "things"])
def test_non_utf8_source_is_exit_2_on_stderr(tmp_path, capsys, command) -> None:
    source = tmp_path / "robot.xml"
    source.write_bytes(b'<?xml version="1.0" encoding="utf-8"?><mujoco model="\xff"/>')
    argv = {
        "convert": ["convert", str(source), "-o", str(tmp_path / "out.xml")],
        "roundtrip": ["roundtrip", str(source)],
        "things": ["things", str(source), str(tmp_path / "out.xml")],
    }[command]
    assert main(argv) == 2
    captured = capsys.readouterr()
    assert str(source) in captured.err and "line 1" in captured.err
    assert captured.out == ""


def test_warning_about_many_joints_stays_one_short_line(tmp_path: Path, caplog) -> None:
    """A warning naming the joints of a 300-joint robot lists a few and counts the rest."""
    n = 300
    links = "".join(
        f'<link name="l{i}"><inertial><mass value="1"/>'
        '<inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial></link>'
        for i in range(n + 1)
    )
    joints = "".join(
        f'<joint name="j{i}" type="revolute"><parent link="l{i - 1}"/><child link="l{i}"/>'
        '<axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="3" velocity="2"/></joint>'
        for i in range(1, n + 1)
    )
    urdf = tmp_path / "many.urdf"
    urdf.write_text(f'<robot name="many">{links}{joints}</robot>')
    with caplog.at_level("WARNING"):
        urdf_to_hrdf(urdf)
    limits = [r.getMessage() for r in caplog.records if "effort/velocity limits" in r.getMessage()]
    assert len(limits) == 1
    assert f"of {n} joint(s)" in limits[0]
    assert f"({n - 12} more)" in limits[0]
    assert "j1, j2" in limits[0] and "j299" not in limits[0]


_LINK = (
    '<link name="a"><inertial><origin xyz="{xyz}"/><mass value="{mass}"/>'
    '<inertia ixx="{ixx}" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/></inertial>'
    '<collision><geometry><box size="{box}"/></geometry></collision></link>'
    '<link name="b"><inertial><mass value="1"/>'
    '<inertia ixx="1" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/></inertial></link>'
    '<joint name="j" type="revolute"><parent link="a"/><child link="b"/>'
    '<limit lower="{lower}" upper="1" effort="1" velocity="1"/></joint>'
)
_SANE = {"xyz": "0 0 0", "mass": "1", "ixx": "1", "box": "1 1 1", "lower": "-1"}


@pytest.mark.parametrize(
    ("field", "value", "expected"),
    [
        ("mass", "1e400", "mass '1e400': expected a finite number"),
        ("mass", "nan", "mass 'nan': expected a finite number"),
        ("ixx", "inf", "inertia: expected finite numbers ixx..izz"),
        ("xyz", "0 0 -inf", "expected 3 finite numbers"),
        ("box", "1 nan 1", "<box size> = '1 nan 1': expected 3 finite numbers"),
        ("lower", "-inf", "<limit lower='-inf'>: expected a finite number"),
    ],
)
def test_urdf_numbers_must_be_finite(tmp_path, capsys, field, value, expected) -> None:
    """Python reads "1e400", "inf" and "nan" as floats; MuJoCo's URDF reader refuses the
    first and takes the others (a mass of inf compiles). An HRDF cannot hold them: the
    parser refuses all three, naming the element, instead of writing an infinite mass."""
    path = tmp_path / "r.urdf"
    path.write_text(f'<robot name="r">{_LINK.format(**{**_SANE, field: value})}</robot>')
    with pytest.raises(ConversionError, match=re.escape(expected)):
        urdf_to_hrdf(path)
    out = tmp_path / "out"
    assert main(["convert", str(path), "-o", str(out)]) == 2
    err = capsys.readouterr().err
    assert expected in err and "r.urdf" in err and not out.exists()


@pytest.mark.parametrize(
    ("field", "value", "expected"),
    [
        ("mass", "2.5e-310", "mass '2.5e-310': expected a finite number (MuJoCo"),
        ("ixx", "1e-320", "inertia: expected finite numbers ixx..izz (MuJoCo"),
        ("xyz", "0 5e-324 0", "<origin xyz> = '0 5e-324 0': expected 3 finite numbers (MuJoCo"),
        ("box", "1 2.2e-308 1", "<box size> = '1 2.2e-308 1': expected 3 finite numbers (MuJoCo"),
        ("lower", "-1e-310", "<limit lower='-1e-310'>: expected a finite number (MuJoCo"),
    ],
)
def test_urdf_subnormal_numbers_as_the_installed_mujoco_reads_them(
    tmp_path, capsys, field, value, expected
) -> None:
    """A subnormal number (nonzero, below 2.2250738585072014e-308 in magnitude): where
    MuJoCo's XML reader takes it (4.x), the URDF converts and keeps it; where it refuses
    it (3.11: "number is too large"), the parser refuses it too, naming the element and
    why, instead of an HRDF no MJCF of this MuJoCo can hold."""
    path = tmp_path / "r.urdf"
    path.write_text(f'<robot name="r">{_LINK.format(**{**_SANE, field: value})}</robot>')
    try:
        mujoco.MjModel.from_xml_string(
            '<mujoco><worldbody><geom size="0.1" pos="1e-310 0 0"/></worldbody></mujoco>'
        )
        reads = True
    except ValueError:
        reads = False
    out = tmp_path / "out"
    if reads:
        hrdf = urdf_to_hrdf(path)
        if field == "lower":
            assert hrdf.joints[0].range[0] == float(value)
        assert main(["convert", str(path), "-o", str(out)]) == 0
        return
    with pytest.raises(ConversionError, match=re.escape(expected)):
        urdf_to_hrdf(path)
    assert main(["convert", str(path), "-o", str(out)]) == 2
    err = capsys.readouterr().err
    assert expected in err and "r.urdf" in err and not out.exists()


def test_urdf_with_finite_numbers_still_converts(tmp_path) -> None:
    path = tmp_path / "r.urdf"
    path.write_text(f'<robot name="r">{_LINK.format(**_SANE)}</robot>')
    assert urdf_to_hrdf(path).bodies[0].mass == 1.0


@pytest.mark.parametrize(
    ("element", "expected"),
    [
        ("<joint name='j' damping='inf'/>", "column 'viscous_friction': expected a finite number"),
        ("<joint name='j' armature='nan'/>", "column 'armature': expected a finite number"),
    ],
)
def test_mjcf_values_a_folder_cannot_hold_are_refused_by_convert(
    tmp_path, capsys, element, expected
) -> None:
    """MuJoCo takes inf and nan in these attributes; an HRDF folder cannot hold them (its
    reader refuses them), so ``convert`` refuses to write a folder that would not load."""
    source = tmp_path / "m.xml"
    source.write_text(
        f"<mujoco><worldbody><body name='a'>{element}<geom size='0.1'/></body></worldbody></mujoco>"
    )
    out = tmp_path / "out"
    assert main(["convert", str(source), "-o", str(out)]) == 2
    err = capsys.readouterr().err
    assert "joint.csv: row 0" in err and expected in err
    assert not out.exists()
