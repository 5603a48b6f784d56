"""A name read from a file never becomes a path (issue 38, item 1).

Every writer that makes a file or folder name from a robot's, a model's or a design's
name goes through :func:`robotwright._names.file_stem`. These tests walk the writers
with hostile names -- ``../`` traversal, an absolute path, a backslash, a NUL, a 10 kB
name, ``.`` and the empty name -- and check that every file written lies inside the
output folder, that a file planted where the traversal points is untouched, and that
the command line ends with exit 0 or one ``error:`` line (exit 2), never a traceback.
"""

from __future__ import annotations

import dataclasses
from pathlib import Path

import pytest

from robotwright._names import MAX_STEM_CHARS, file_stem
from robotwright.cli import main
from robotwright.hrdf.model import HRDF

#: (label, name). The traversal climbs far enough to reach the filesystem's root from
#: any temporary folder, then names the test's own victim (see ``_hostile``).
HOSTILE = [
    ("traversal", "../../../../../../../../../../{victim}"),
    ("absolute", "{victim}"),
    ("backslash", "..\\..\\{victim}"),
    ("nul", "robot\x00../../x"),
    ("long", "r" * 10_000),
    ("dot", "."),
    ("dotdot", ".."),
    ("empty", ""),
    ("newline", "a\nb/../c"),
]


def _hostile(template: str, victim: Path) -> str:
    return template.format(victim=str(victim).lstrip("/"))


def _files_under(folder: Path) -> set[Path]:
    return {p for p in folder.rglob("*") if p.is_file()}


@pytest.mark.parametrize(
    "name",
    ["../../etc/passwd", "/abs/x", "a\\b", "x\x00y", "r" * 10_000, ".", "..", "", ". .", "a/./b"],
)
def test_file_stem_is_one_harmless_name(name: str) -> None:
    stem = file_stem(name, "robot")
    assert stem and len(stem) <= MAX_STEM_CHARS
    assert "/" not in stem and "\\" not in stem and "\x00" not in stem and ".." not in stem
    assert not stem.startswith(".") and stem not in (".", "..")
    assert all(c.isascii() and (c.isalnum() or c in "_.-") for c in stem)


def test_file_stem_keeps_an_ordinary_name() -> None:
    assert file_stem("unitree_go2-v1.2", "robot") == "unitree_go2-v1.2"
    assert file_stem("", "robot") == "robot" and file_stem(None, "srl") == "srl"


@pytest.fixture
def arm6() -> HRDF:
    return HRDF.from_robot_name("arm6")


@pytest.mark.parametrize(("label", "template"), HOSTILE, ids=[h[0] for h in HOSTILE])
def test_export_robot_writes_only_inside_its_folder(tmp_path, arm6, label, template) -> None:
    from robotwright.tasks import export_robot

    victim = tmp_path / "home" / "victim"
    victim.parent.mkdir()
    out = tmp_path / "out"
    hostile = dataclasses.replace(arm6, name=_hostile(template, victim))
    written = export_robot(hostile, out)
    for path in written.values():
        assert path.parent == out and path.is_file()
    files = _files_under(tmp_path)
    assert files and all(p.is_relative_to(out) for p in files), sorted(files)
    assert not victim.with_suffix(".xml").exists() and not victim.with_suffix(".urdf").exists()


@pytest.mark.parametrize(("label", "template"), HOSTILE, ids=[h[0] for h in HOSTILE])
def test_usd_staging_mjcf_stays_in_its_temporary(tmp_path, arm6, label, template) -> None:
    """The MJCF the USD export converts is written inside its own temporary folder,
    named from the robot only through file_stem (mujoco-usd-converter is not needed)."""
    from robotwright.generators.usd import _robot_mjcf

    victim = tmp_path / "home" / "victim"
    victim.parent.mkdir()
    work = tmp_path / "work"
    path, _ = _robot_mjcf(dataclasses.replace(arm6, name=_hostile(template, victim)), work)
    assert path.parent == work / "mjcf" and path.is_file()
    assert all(p.is_relative_to(work) for p in _files_under(tmp_path))


@pytest.mark.parametrize(("label", "template"), HOSTILE, ids=[h[0] for h in HOSTILE])
def test_design_export_names_its_files_safely(tmp_path, label, template) -> None:
    from robotwright.grammar import default_grammar, demo_limb_design
    from robotwright.grammar.export import export_design

    victim = tmp_path / "home" / "victim"
    victim.parent.mkdir()
    out = tmp_path / "design"
    export_design(
        default_grammar(), demo_limb_design(0), out, name=_hostile(template, victim), picture=False
    )
    files = _files_under(tmp_path)
    assert all(p.is_relative_to(out) for p in files), sorted(files)
    assert sum(p.suffix == ".xml" for p in files) == 1


URDF = """<robot name="{name}">
  <link name="base">
    <inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>
    <visual><geometry><mesh filename="part.stl"/></geometry></visual>
  </link>
  <link name="arm">
    <inertial><mass value="0.5"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>
  </link>
  <joint name="j" type="revolute"><parent link="base"/><child link="arm"/>
    <axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
</robot>
"""


@pytest.mark.parametrize(
    ("label", "template"),
    [h for h in HOSTILE if h[0] not in ("nul", "newline")],  # XML cannot hold them
    ids=[h[0] for h in HOSTILE if h[0] not in ("nul", "newline")],
)
@pytest.mark.parametrize("suffix", [".xml", ".urdf"])
def test_cli_export_of_a_hostile_robot_name(tmp_path, capsys, label, template, suffix) -> None:
    """``export robot.urdf -o out/robot.xml`` with the name in the URDF: the file and its
    copied meshes (``meshes/<stem>/``) land inside ``out``; nothing else is written."""
    import trimesh

    src = tmp_path / "src"
    src.mkdir()
    trimesh.creation.box(extents=(0.1, 0.1, 0.1)).export(str(src / "part.stl"))
    victim = tmp_path / "home" / "victim"
    victim.parent.mkdir()
    victim.with_suffix(".xml").write_text("precious")
    name = _hostile(template, victim)
    (src / "robot.urdf").write_text(URDF.format(name=name), encoding="utf-8")
    before = _files_under(tmp_path)
    out = tmp_path / "out"
    code = main(["export", str(src / "robot.urdf"), "-o", str(out / f"robot{suffix}")])
    err = capsys.readouterr().err
    assert "Traceback" not in err
    assert code in (0, 2), err
    new = _files_under(tmp_path) - before
    assert all(p.is_relative_to(out) for p in new), sorted(new)
    assert victim.with_suffix(".xml").read_text() == "precious"
    if code == 0:
        assert (out / f"robot{suffix}").is_file()
        meshes = [p for p in new if p.suffix == ".stl"]
        assert all(p.parent.parent == out / "meshes" for p in meshes), meshes


def test_no_writer_joins_a_name_to_a_path() -> None:
    """The source never builds a file name from an HRDF's, a spec's or a robot's name
    without file_stem (a new writer that did would make this test fail)."""
    import ast

    root = Path(__import__("robotwright").__file__).parent
    found = []
    for path in root.rglob("*.py"):
        tree = ast.parse(path.read_text(encoding="utf-8"))
        for node in ast.walk(tree):
            if not isinstance(node, ast.BinOp) or not isinstance(node.op, ast.Div):
                continue
            right = node.right
            if isinstance(right, ast.JoinedStr):
                for part in right.values:
                    if isinstance(part, ast.FormattedValue):
                        value = part.value
                        text = ast.unparse(value)
                        if text.endswith((".name", ".modelname")) or text in ("name", "group"):
                            found.append(f"{path.relative_to(root)}:{node.lineno}: {text}")
    assert found == [], found
