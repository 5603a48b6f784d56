"""One containment rule per source kind (issue 19, item 2).

A URDF or xacro file may read from its *root*: the ROS package folder holding it (the
nearest ancestor with a ``package.xml``), else its own folder. Sibling and parent
folders are reachable only when the user names them (``--asset-root``,
``--package NAME=DIR`` / ``package_map``). The same rule holds for every reader of the
file: ``convert`` and the parser API, the loader of ``render``/``view``, ``roundtrip``.

The layout of each test is a shared folder (``tmp_path``, as ``/tmp`` or ``~/Downloads``)
holding the robot's folder and a private folder beside it:

    tmp_path/robot/robot.urdf      the untrusted file
    tmp_path/robot/part.stl        its own mesh
    tmp_path/private/secret.stl    what it must not reach (also creds.yaml, package.xml)
    tmp_path/top.stl               a file in the shared folder itself
"""

from __future__ import annotations

import os
import random
import tempfile
from pathlib import Path
from urllib.parse import quote

import pytest
import trimesh

from robotwright.cli import main
from robotwright.errors import RobotwrightError
from robotwright.parsers import urdf_to_hrdf
from robotwright.parsers.packages import robot_root
from robotwright.proof.roundtrip.run import roundtrip
from robotwright.render import load_model

URDF = """<robot name="r">
  <link name="base">
    <inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>
    <visual><geometry><mesh filename="{uri}"/></geometry></visual>
  </link>
</robot>
"""

XACRO = """<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro">
  {pre}
  <link name="{name}">
    <inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>
  </link>
</robot>
"""


def _stl(path: Path, size: float = 0.05) -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    trimesh.creation.box(extents=(size, size, size)).export(str(path), file_type="stl")
    return path


@pytest.fixture
def shared(tmp_path: Path) -> Path:
    """The shared folder: a robot folder, a private package beside it, a loose file."""
    _stl(tmp_path / "robot" / "part.stl")
    _stl(tmp_path / "private" / "secret.stl", size=0.3)
    (tmp_path / "private" / "package.xml").write_text("<package><name>private</name></package>")
    (tmp_path / "private" / "creds.yaml").write_text("user: alice\ntoken: s3cr3t\n")
    (tmp_path / "private" / "inc.xacro").write_text(
        '<robot xmlns:xacro="http://www.ros.org/wiki/xacro">'
        '<xacro:property name="stolen" value="s3cr3t"/></robot>'
    )
    _stl(tmp_path / "top.stl", size=0.2)
    return tmp_path


def _urdf(folder: Path, uri: str, name: str = "robot.urdf") -> Path:
    path = folder / name
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(URDF.format(uri=uri))
    return path


def _escape_uris(shared: Path) -> list[str]:
    """Mesh URIs of ``shared/robot/robot.urdf`` that name a file outside ``robot/``:
    ``..`` chains, absolute paths, ``file://`` (percent-encoded too), ``package://``
    with ``..``, a sibling package, the shared folder named as a package."""
    secret = shared / "private" / "secret.stl"
    rng = random.Random(19)
    uris = ["../private/secret.stl", "../top.stl", "./../private/secret.stl"]
    uris += ["sub/../../private/secret.stl", "part.stl/../../private/secret.stl"]
    for _ in range(6):  # random detours that all end outside the folder
        hops = rng.randint(1, 4)
        detour = "/".join(rng.choice(["a", "b", "."]) for _ in range(hops))
        ups = "/".join([".."] * (hops - detour.count(".") + 1))
        uris.append(f"{detour}/{ups}/private/secret.stl".replace("//", "/"))
    depth = len(shared.parts)
    uris += ["/".join([".."] * k) + str(secret) for k in (depth, depth + 3)]
    uris += [str(secret), str(shared / "top.stl"), "file://" + str(secret)]
    uris += ["file://" + quote(str(secret)), "file://../private/secret.stl"]
    uris += ["file://" + str(shared / "robot" / ".." / "private" / "secret.stl")]
    uris += ["package://robot/../private/secret.stl", "package://robot/%2e%2e/private/secret.stl"]
    uris += ["package://private/secret.stl", "package:///private/secret.stl"]
    uris += [f"package://{shared.name}/private/secret.stl", f"package://{shared.name}/top.stl"]
    uris += ["package://../private/secret.stl", "package://./private/secret.stl"]
    uris += ["package://robot/../../" + str(secret).lstrip("/")]
    return uris


def _family(shared: Path) -> list[tuple[str, Path]]:
    """(label, URDF path) for every escape: the URIs above, and symbolic links inside
    the robot folder that point out (to a file, to a folder)."""
    robot = shared / "robot"
    cases = [(uri, _urdf(robot, uri, f"u{k}.urdf")) for k, uri in enumerate(_escape_uris(shared))]
    (robot / "link.stl").symlink_to(shared / "private" / "secret.stl")
    (robot / "linked").symlink_to(shared / "private", target_is_directory=True)
    (robot / "up").symlink_to("..", target_is_directory=True)
    for uri in ("link.stl", "linked/secret.stl", "up/top.stl", "up/private/secret.stl"):
        cases.append((f"symlink {uri}", _urdf(robot, uri, f"s{len(cases)}.urdf")))
    return cases


def _refused_by_every_reader(path: Path, out: Path, capsys) -> None:
    with pytest.raises(RobotwrightError):
        urdf_to_hrdf(path)
    with pytest.raises(RobotwrightError):
        load_model(path)  # render's and view's loader
    capsys.readouterr()
    assert main(["convert", str(path), "-o", str(out)]) == 2
    err = capsys.readouterr().err
    assert err.startswith("error:") and "Traceback" not in err
    assert not out.exists()


def test_mesh_escapes_are_refused_by_every_reader(shared: Path, capsys) -> None:
    cases = _family(shared)
    assert len(cases) >= 30
    for k, (label, path) in enumerate(cases):
        try:
            _refused_by_every_reader(path, shared / f"out{k}.xml", capsys)
        except BaseException as exc:
            raise AssertionError(f"escape not refused: {label!r}") from exc


def test_roundtrip_refuses_escapes(shared: Path, capsys) -> None:
    """roundtrip: the API reports the refusal as input_error, the command exits 2 with
    no table (a sample of the family: each is a full parse)."""
    cases = _family(shared)
    for label, path in cases[:: max(1, len(cases) // 10)]:
        report = roundtrip(path, configs=2)
        assert report.input_error is not None, label
        capsys.readouterr()
        assert main(["roundtrip", str(path), "--configs", "2"]) == 2, label
        captured = capsys.readouterr()
        assert captured.err.startswith("error:") and not captured.out, label


def test_own_mesh_still_converts(shared: Path, tmp_path: Path) -> None:
    """The control: the same file naming its own mesh is read."""
    path = _urdf(shared / "robot", "part.stl")
    assert len(urdf_to_hrdf(path).meshes) == 1
    assert load_model(path).model.nmesh == 1
    assert main(["convert", str(path), "-o", str(tmp_path / "ok.xml")]) == 0


def test_loose_file_in_shared_folder_cannot_reach_subfolders_above(tmp_path: Path) -> None:
    """A URDF saved directly in a download folder: its root is that folder, never the
    folder's parent (the home folder)."""
    _stl(tmp_path / "work" / "private.stl")
    downloads = tmp_path / "Downloads"
    for uri in ("../work/private.stl", f"package://{tmp_path.name}/work/private.stl"):
        with pytest.raises(RobotwrightError):
            urdf_to_hrdf(_urdf(downloads, uri))


@pytest.mark.parametrize("layout", ["package.xml relative", "package.xml package://"])
def test_ros_package_layouts_convert(tmp_path: Path, layout: str) -> None:
    """``my_robot_description/urdf/robot.urdf`` + ``meshes/``: with a ``package.xml`` the
    package folder is the root."""
    pkg = tmp_path / "my_robot_description"
    _stl(pkg / "meshes" / "part.stl")
    (pkg / "package.xml").write_text("<package><name>my_robot_description</name></package>")
    uri = (
        "../meshes/part.stl"
        if layout.endswith("relative")
        else "package://my_robot_description/meshes/part.stl"
    )
    path = _urdf(pkg / "urdf", uri)
    assert len(urdf_to_hrdf(path).meshes) == 1


@pytest.mark.parametrize("name", ["my_robot_description", "home", "Downloads", "tmp"])
def test_name_urdf_layout_without_package_xml_reaches_nothing_above(
    tmp_path: Path, name: str, capsys
) -> None:
    """``NAME/urdf/robot.urdf`` naming ``package://NAME/...`` without a ``package.xml``:
    the folder above ``urdf/`` is not the robot's (``~/urdf/robot.urdf`` in a home
    folder called NAME would reach every file of it); it is read only when the user
    names it with ``--package NAME=DIR``."""
    pkg = tmp_path / name
    _stl(pkg / "meshes" / "part.stl")
    _stl(pkg / ".ssh" / "id_ed25519.stl")
    for uri in (f"package://{name}/meshes/part.stl", f"package://{name}/.ssh/id_ed25519.stl"):
        path = _urdf(pkg / "urdf", uri)
        with pytest.raises(RobotwrightError, match=f"package '{name}' not found"):
            urdf_to_hrdf(path)
        out = tmp_path / "out.xml"
        assert main(["convert", str(path), "-o", str(out)]) == 2
        assert "--package" in capsys.readouterr().err
        assert not out.exists()
    assert main(["convert", str(path), "-o", str(out), "--package", f"{name}={pkg}"]) == 0


def test_name_urdf_layout_of_an_installed_package_resolves(tmp_path: Path) -> None:
    """The same layout where pip installed it (``site-packages/NAME/urdf/``): the user
    installed the package, so its folder is the package's."""
    jvrc = pytest.importorskip("jvrc_description", reason="jvrc-description not installed")
    urdf = Path(jvrc.__file__).parent / "urdf" / "jvrc1.urdf"
    assert len(urdf_to_hrdf(urdf).meshes) > 0


def test_urdf_folder_without_package_xml_keeps_relative_paths_inside(tmp_path: Path) -> None:
    """Without a ``package.xml`` the root is the URDF's own folder: ``../meshes`` needs
    ``--asset-root`` (the user names the folder)."""
    pkg = tmp_path / "robot"
    _stl(pkg / "meshes" / "part.stl")
    path = _urdf(pkg / "urdf", "../meshes/part.stl")
    with pytest.raises(RobotwrightError, match="outside the robot folder"):
        urdf_to_hrdf(path)
    out = tmp_path / "out.xml"
    assert main(["convert", str(path), "-o", str(out)]) == 2
    assert main(["convert", str(path), "-o", str(out), "--asset-root", str(pkg)]) == 0


def test_sibling_package_only_when_named(shared: Path, capsys) -> None:
    path = _urdf(shared / "robot", "package://private/secret.stl")
    out = shared / "out.xml"
    assert main(["convert", str(path), "-o", str(out)]) == 2
    assert "--package private=DIR" in capsys.readouterr().err
    assert not out.exists()
    named = ["--package", f"private={shared / 'private'}"]
    assert main(["convert", str(path), "-o", str(out), *named]) == 0
    assert out.is_file()
    assert len(urdf_to_hrdf(path, package_map={"private": shared / "private"}).meshes) == 1
    # A named package still keeps its paths inside it.
    up = _urdf(shared / "robot", "package://private/../top.stl", "up.urdf")
    assert main(["convert", str(up), "-o", str(shared / "up.xml"), *named]) == 2


def test_ros_package_path_names_packages(shared: Path, monkeypatch) -> None:
    """Environment variables set by the user are the user's choice."""
    path = _urdf(shared / "robot", "package://private/secret.stl")
    with pytest.raises(RobotwrightError):
        urdf_to_hrdf(path)
    monkeypatch.setenv("ROS_PACKAGE_PATH", str(shared / "private"))
    assert len(urdf_to_hrdf(path).meshes) == 1


@pytest.mark.parametrize(
    "value",
    ["private", "=/tmp", "private=", "../x=/tmp", "a/b=/tmp", ".hidden=/tmp", "-x=/tmp", "=", ""],
)
def test_malformed_package_option_is_refused(shared: Path, value: str, capsys) -> None:
    path = _urdf(shared / "robot", "part.stl")
    with pytest.raises(SystemExit) as exc:
        main(["convert", str(path), "-o", str(shared / "o.xml"), "--package", value])
    assert exc.value.code == 2
    assert "--package" in capsys.readouterr().err


def test_package_option_folder_must_exist(shared: Path, capsys) -> None:
    path = _urdf(shared / "robot", "part.stl")
    missing = shared / "nope"
    assert main(["convert", str(path), "-o", str(shared / "o.xml"), "--package", f"p={missing}"])
    assert "is not a folder" in capsys.readouterr().err


# --------------------------------------------------------------------------------- xacro

pytest.importorskip("xacro")


def _xacro_bodies(shared: Path) -> list[tuple[str, str]]:
    """(before the link, the link's name): each would name the only link after a secret
    (a valid robot) if the file it reads were allowed."""
    creds = shared / "private" / "creds.yaml"
    inc = shared / "private" / "inc.xacro"
    yaml_names = [
        "$(find private)/creds.yaml",
        "../private/creds.yaml",
        str(creds),
        f"file://{creds}",
        "$(find robot)/../private/creds.yaml",
        f"$(find {shared.name})/private/creds.yaml",
        "link/creds.yaml",
        "./link/../link/creds.yaml",
    ]
    cases = [("", f"${{xacro.load_yaml('{y}')['token']}}") for y in yaml_names]
    for include in (
        "$(find private)/inc.xacro",
        "../private/inc.xacro",
        str(inc),
        "link/inc.xacro",
    ):
        cases.append((f'<xacro:include filename="{include}"/>', "${stolen}"))
    cases += [("", "$(find private)"), ("", f"$(find {shared.name})")]
    return cases


def test_xacro_reads_nothing_outside_its_root(shared: Path, capsys) -> None:
    """``$(find)`` of a sibling or parent, ``load_yaml`` / ``include`` of a parent file,
    an absolute path or a symbolic link out: refused, and the secret is in no output."""
    robot = shared / "robot"
    (robot / "link").symlink_to(shared / "private", target_is_directory=True)
    for k, (pre, name) in enumerate(_xacro_bodies(shared)):
        body = pre + name
        path = robot / f"x{k}.urdf.xacro"
        path.write_text(XACRO.format(pre=pre, name=name))
        out = shared / f"x{k}.xml"
        with pytest.raises(RobotwrightError):
            urdf_to_hrdf(path)
        capsys.readouterr()
        assert main(["convert", str(path), "-o", str(out)]) == 2, body
        err = capsys.readouterr().err
        assert err.startswith("error:") and "s3cr3t" not in err, body
        assert "root link" not in err, body  # refused for the path, not the tree
        assert not out.exists(), body


def test_xacro_find_of_a_named_package(shared: Path) -> None:
    """The control: the user names the package, ``$(find)`` and ``load_yaml`` read it."""
    path = shared / "robot" / "ok.urdf.xacro"
    name = "${xacro.load_yaml('$(find private)/creds.yaml')['user']}"
    path.write_text(XACRO.format(pre="", name=name))
    out = shared / "ok.xml"
    named = ["--package", f"private={shared / 'private'}"]
    assert main(["convert", str(path), "-o", str(out), *named]) == 0
    assert 'name="alice"' in out.read_text()


def test_loose_xacro_in_shared_folder(tmp_path: Path) -> None:
    """A xacro saved directly in a download folder cannot ``$(find)`` the folder above."""
    (tmp_path / "cfg.yaml").write_text("token: s3cr3t\n")
    downloads = tmp_path / "Downloads"
    downloads.mkdir()
    path = downloads / "r.urdf.xacro"
    name = f"${{xacro.load_yaml('$(find {tmp_path.name})/cfg.yaml')['token']}}"
    path.write_text(XACRO.format(pre="", name=name))
    with pytest.raises(RobotwrightError, match="not found"):
        urdf_to_hrdf(path)


def test_fifo_mesh_in_urdf_is_refused(shared: Path) -> None:
    path = _urdf(shared / "robot", "pipe.stl")
    os.mkfifo(shared / "robot" / "pipe.stl")
    with pytest.raises(RobotwrightError, match="not a regular file"):
        urdf_to_hrdf(path)


def test_roundtrip_reference_api_keeps_the_rule(shared: Path) -> None:
    """The round trip's reference (MuJoCo's import of the source) is also a reader: an
    outside mesh is refused, not handed to MuJoCo as written."""
    from robotwright.errors import UnsafePathError
    from robotwright.parsers.reference import urdf_for_mujoco
    from robotwright.proof.roundtrip.run import reference_view

    path = _urdf(shared / "robot", "../private/secret.stl")
    with pytest.raises(UnsafePathError):
        urdf_for_mujoco(path)
    with pytest.raises(UnsafePathError):
        reference_view(path, reference="mujoco")
    own = _urdf(shared / "robot", "part.stl", "own.urdf")
    assert str(shared / "robot" / "part.stl") in urdf_for_mujoco(own)


MJCF = """<mujoco><asset><mesh name="m" file="{file}"/></asset>
<worldbody><body name="b"><geom type="mesh" mesh="m"/></body></worldbody></mujoco>"""


@pytest.mark.parametrize("kind", ["fifo", "device"])
def test_mjcf_readers_refuse_fifo_and_device_files(shared: Path, kind: str) -> None:
    """The MJCF gate (the parser, render/view's loader) refuses a mesh that is not a
    regular file before MuJoCo opens it. Run in a subprocess: the timeout only guards
    against a regression that blocks."""
    import subprocess
    import sys

    folder = shared / "robot"
    if kind == "fifo":
        os.mkfifo(folder / "pipe.stl")
        file, trust = "pipe.stl", []
    else:
        file, trust = "/dev/zero", ["--asset-root", "/dev"]
    scene = folder / "scene.xml"
    scene.write_text(MJCF.format(file=file))
    out = shared / "out.urdf"
    run = [sys.executable, "-m", "robotwright", "convert", str(scene), "-o", str(out), *trust]
    done = subprocess.run(run, capture_output=True, text=True, timeout=300)
    assert done.returncode == 2, done.stderr
    assert "expected a regular file" in done.stderr and not out.exists()
    code = (
        "import sys\nfrom robotwright.render import load_model\n"
        "from robotwright import trusted_asset_roots\n"
        "from robotwright.errors import RobotwrightError\n"
        f"try:\n    with trusted_asset_roots({trust[1:]!r}):\n"
        f"        load_model({str(scene)!r})\n"
        "except RobotwrightError as exc:\n    print(exc); sys.exit(2)\n"
    )
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300)
    assert done.returncode == 2, done.stderr
    assert "expected a regular file" in done.stdout


def test_given_packages_reach_the_render_view_loader(shared: Path) -> None:
    """``--package`` on render/view is a ``given_packages`` block around the loader."""
    from robotwright.parsers.packages import given_packages

    path = _urdf(shared / "robot", "package://private/secret.stl")
    with pytest.raises(RobotwrightError, match="package 'private' not found"):
        load_model(path)
    with given_packages({"private": shared / "private"}):
        assert load_model(path).model.nmesh == 1
    with pytest.raises(RobotwrightError):  # the block is closed
        load_model(path)


@pytest.mark.parametrize("levels", [1, 2, 4])
def test_planted_package_xml_in_a_shared_folder_widens_nothing(
    tmp_path: Path, monkeypatch, levels: int
) -> None:
    # A package.xml someone planted in a shared folder (here the temporary folder) or
    # more levels up than ROS keeps robot files must not make that folder the root.
    shared = tmp_path / "shared"
    robot_dir = shared.joinpath(*[f"d{i}" for i in range(levels)])
    robot_dir.mkdir(parents=True)
    (shared / "package.xml").write_text("<package><name>planted</name></package>")
    monkeypatch.setattr(tempfile, "tempdir", str(shared))
    urdf = robot_dir / "robot.urdf"
    urdf.write_text("<robot name='r'><link name='a'/></robot>")
    assert robot_root(urdf) == robot_dir.resolve()


def test_package_xml_found_within_ros_depth(tmp_path: Path) -> None:
    pkg = tmp_path / "my_robot_description"
    urdf_dir = pkg / "robots" / "my_robot" / "urdf"
    urdf_dir.mkdir(parents=True)
    (pkg / "package.xml").write_text("<package><name>my_robot_description</name></package>")
    deep = urdf_dir / "a" / "b" / "c" / "d"
    deep.mkdir(parents=True)
    (urdf_dir / "r.urdf").write_text("<robot name='r'/>")
    (deep / "r.urdf").write_text("<robot name='r'/>")
    assert robot_root(urdf_dir / "r.urdf") == pkg.resolve()
    # Seven levels below the package.xml: further than ROS keeps robot files.
    assert robot_root(deep / "r.urdf") == deep.resolve()
