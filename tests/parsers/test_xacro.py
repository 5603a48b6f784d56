"""xacro sources (``.xacro`` / ``.urdf.xacro``) through ``urdf_to_hrdf``, ``convert``,
``roundtrip`` and the CLI, on the xacro files of the robosuite corpus and on small
files written here; the hostile-input rules (no reads outside the allowed folders, no
environment, no XML entities)."""

from __future__ import annotations

import builtins
import math
import sysconfig
import textwrap
import xml.etree.ElementTree as ET
from pathlib import Path

import mujoco
import numpy as np
import pytest

from robotwright.cli import main
from robotwright.errors import ConversionError
from robotwright.parsers import urdf_to_hrdf
from robotwright.proof.roundtrip.run import our_mjcf_model, roundtrip

pytest.importorskip("xacro", reason="the xacro extra (pip install 'robotwright[xacro]') is absent")

PANDA = (
    Path(__file__).resolve().parents[2]
    / ".testdata/robosuite/robosuite/models/assets/bullet_data/panda_description/urdf"
)


def _same(a: mujoco.MjModel, b: mujoco.MjModel, configs: int = 20) -> None:
    """Equal compiled models: masses, inertias, joints, and FK at random configurations."""
    assert (a.nbody, a.njnt, a.nq, a.ngeom) == (b.nbody, b.njnt, b.nq, b.ngeom)
    assert [a.body(i).name for i in range(a.nbody)] == [b.body(i).name for i in range(b.nbody)]
    np.testing.assert_allclose(a.body_mass, b.body_mass, rtol=1e-12)
    np.testing.assert_allclose(a.body_inertia, b.body_inertia, rtol=1e-9, atol=1e-15)
    np.testing.assert_array_equal(a.jnt_type, b.jnt_type)
    np.testing.assert_allclose(a.jnt_range, b.jnt_range)
    np.testing.assert_allclose(a.jnt_axis, b.jnt_axis)
    np.testing.assert_allclose(a.actuator_gear, b.actuator_gear)
    np.testing.assert_allclose(a.actuator_ctrlrange, b.actuator_ctrlrange)
    rng = np.random.default_rng(7)
    da, db = mujoco.MjData(a), mujoco.MjData(b)
    for _ in range(configs):
        q = a.qpos0 + rng.uniform(-1.0, 1.0, a.nq)
        da.qpos[:] = q
        db.qpos[:] = q
        mujoco.mj_kinematics(a, da)
        mujoco.mj_kinematics(b, db)
        np.testing.assert_allclose(da.xpos, db.xpos, atol=1e-12)
        np.testing.assert_allclose(da.xquat, db.xquat, atol=1e-12)


def _panda(name: str) -> Path:
    path = PANDA / name
    if not path.is_file():
        pytest.skip(
            f"robosuite test data not fetched (run python tools/fetch_test_data.py): {path}"
        )
    return path


# ---------------------------------------------------------------- real xacro files
@pytest.mark.realdata
def test_robosuite_hand_xacro_equals_its_shipped_urdf(tmp_path: Path) -> None:
    xacro_robot = urdf_to_hrdf(_panda("hand.urdf.xacro"), work_dir=tmp_path / "x")
    urdf_robot = urdf_to_hrdf(_panda("hand.urdf"), work_dir=tmp_path / "u")
    _same(our_mjcf_model(xacro_robot), our_mjcf_model(urdf_robot))


@pytest.mark.realdata
def test_robosuite_arm_xacro_equals_its_shipped_urdf_but_link8(tmp_path: Path) -> None:
    # The shipped panda_arm.urdf has a panda_link8 that panda_arm.xacro comments out; with
    # that link (and its joint) removed, the two robots are the same.
    import xml.etree.ElementTree as ET

    root = ET.parse(_panda("panda_arm.urdf")).getroot()
    for elem in list(root):
        child = elem.find("child")
        if elem.get("name") == "panda_link8" or (
            child is not None and child.get("link") == "panda_link8"
        ):
            root.remove(elem)
    edited = tmp_path / "panda_arm.urdf"
    edited.write_text(ET.tostring(root, encoding="unicode"))
    urdf_robot = urdf_to_hrdf(edited, package_map={"panda_description": PANDA.parent})
    xacro_robot = urdf_to_hrdf(_panda("panda_arm.urdf.xacro"))
    _same(our_mjcf_model(xacro_robot), our_mjcf_model(urdf_robot))


@pytest.mark.realdata
def test_robosuite_xacro_roundtrip_passes() -> None:
    report = roundtrip(_panda("panda_arm.urdf.xacro"), configs=20)
    assert report.error in (None, ""), report.error
    assert report.ok, report.table()
    assert report.source.endswith("panda_arm.urdf.xacro")


@pytest.mark.realdata
def test_robosuite_broken_xacro_is_named() -> None:
    # panda_arm.xacro comments out panda_link8, to which its hand is connected: a fault of
    # the source, named with the joint and the link.
    with pytest.raises(ConversionError, match=r"panda_hand_joint.*'panda_link8' is not defined"):
        urdf_to_hrdf(_panda("panda_arm_hand.urdf.xacro"))


# ---------------------------------------------------------------- written here
ARM_MACRO = """<?xml version="1.0"?>
<robot xmlns:xacro="http://www.ros.org/wiki/xacro">
  <xacro:macro name="segment" params="name parent length mass">
    <link name="${name}">
      <inertial><origin xyz="0 0 ${length/2}"/><mass value="${mass}"/>
        <inertia ixx="${mass*length*length/12}" iyy="${mass*length*length/12}" izz="0.001"
                 ixy="0" ixz="0" iyz="0"/></inertial>
      <collision><origin xyz="0 0 ${length/2}"/>
        <geometry><box size="0.05 0.05 ${length}"/></geometry></collision>
      <visual><geometry><mesh filename="$(find arm_description)/meshes/seg.stl"/></geometry></visual>
    </link>
    <joint name="${name}_joint" type="revolute"><parent link="${parent}"/><child link="${name}"/>
      <origin xyz="0 0 0.1"/><axis xyz="0 1 0"/>
      <limit lower="${-pi/2}" upper="${pi/2}" effort="10" velocity="2"/></joint>
  </xacro:macro>
</robot>
"""

ARM = """<?xml version="1.0"?>
<robot name="arm" xmlns:xacro="http://www.ros.org/wiki/xacro">
  <xacro:arg name="length" default="0.3"/>
  <xacro:property name="length" value="$(arg length)"/>
  <xacro:include filename="$(find arm_description)/urdf/segment.xacro"/>
  <link name="base"><inertial><mass value="2"/>
    <inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <xacro:segment name="upper" parent="base" length="${length}" mass="1.5"/>
  <xacro:segment name="lower" parent="upper" length="${length*0.8}" mass="$(optenv ARM_MASS 0.5)"/>
</robot>
"""


def _expected_urdf(length: float) -> str:
    def seg(name: str, parent: str, ln: float, mass: float) -> str:
        i = mass * ln * ln / 12
        return f"""
  <link name="{name}"><inertial><origin xyz="0 0 {ln / 2!r}"/><mass value="{mass!r}"/>
    <inertia ixx="{i!r}" iyy="{i!r}" izz="0.001" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><origin xyz="0 0 {ln / 2!r}"/><geometry><box size="0.05 0.05 {ln!r}"/></geometry>
    </collision>
    <visual><geometry><mesh filename="package://arm_description/meshes/seg.stl"/></geometry></visual>
  </link>
  <joint name="{name}_joint" type="revolute"><parent link="{parent}"/><child link="{name}"/>
    <origin xyz="0 0 0.1"/><axis xyz="0 1 0"/>
    <limit lower="{-np.pi / 2!r}" upper="{np.pi / 2!r}" effort="10" velocity="2"/></joint>"""

    return (
        '<robot name="arm"><link name="base"><inertial><mass value="2"/>'
        '<inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial></link>'
        + seg("upper", "base", length, 1.5)
        + seg("lower", "upper", length * 0.8, 0.5)
        + "</robot>"
    )


@pytest.fixture
def arm_package(tmp_path: Path) -> Path:
    """``ws/arm_description`` (a ROS package: package.xml, urdf/, meshes/)."""
    import trimesh

    pkg = tmp_path / "ws" / "arm_description"
    (pkg / "urdf").mkdir(parents=True)
    (pkg / "meshes").mkdir()
    (pkg / "package.xml").write_text("<package><name>arm_description</name></package>")
    trimesh.creation.box((0.04, 0.04, 0.2)).export(str(pkg / "meshes" / "seg.stl"))
    (pkg / "urdf" / "segment.xacro").write_text(ARM_MACRO)
    (pkg / "urdf" / "arm.urdf.xacro").write_text(ARM)
    (pkg / "urdf" / "expected_default.urdf").write_text(_expected_urdf(0.3))
    (pkg / "urdf" / "expected_long.urdf").write_text(_expected_urdf(0.5))
    return pkg


def test_xacro_equals_the_urdf_it_stands_for(arm_package: Path, monkeypatch) -> None:
    monkeypatch.delenv("ARM_MASS", raising=False)
    urdf_dir = arm_package / "urdf"
    ours = our_mjcf_model(urdf_to_hrdf(urdf_dir / "arm.urdf.xacro"))
    _same(ours, our_mjcf_model(urdf_to_hrdf(urdf_dir / "expected_default.urdf")))
    long = our_mjcf_model(urdf_to_hrdf(urdf_dir / "arm.urdf.xacro", xacro_args={"length": "0.5"}))
    _same(long, our_mjcf_model(urdf_to_hrdf(urdf_dir / "expected_long.urdf")))
    lower = long.body("lower").id
    boxes = (long.geom_bodyid == lower) & (long.geom_type == mujoco.mjtGeom.mjGEOM_BOX)
    np.testing.assert_allclose(long.geom_size[boxes][:, 2], [0.5 * 0.8 / 2])  # half-length


def test_find_uses_the_package_map(arm_package: Path, tmp_path: Path) -> None:
    # The same package in another place, named by package_map: $(find) and package://
    # both go there (the xacro file's own ancestors are not searched first).
    import shutil

    other = tmp_path / "elsewhere" / "arm_description"
    shutil.copytree(arm_package, other)
    (other / "urdf" / "segment.xacro").write_text(
        ARM_MACRO.replace('<mass value="${mass}"/>', '<mass value="9"/>')
    )
    robot = urdf_to_hrdf(
        arm_package / "urdf" / "arm.urdf.xacro",
        package_map={"arm_description": other},
        asset_roots=(other,),
    )
    model = our_mjcf_model(robot)
    assert model.body("upper").mass[0] == 9.0


def test_missing_argument_and_unknown_package_are_named(tmp_path: Path) -> None:
    robot = tmp_path / "r" / "urdf"
    robot.mkdir(parents=True)
    (robot / "a.urdf.xacro").write_text(
        '<robot name="a" xmlns:xacro="http://www.ros.org/wiki/xacro">'
        '<link name="l"><visual><geometry><box size="$(arg size) 1 1"/></geometry></visual>'
        "</link></robot>"
    )
    with pytest.raises(ConversionError, match=r"size.*--xacro-arg size:=VALUE"):
        urdf_to_hrdf(robot / "a.urdf.xacro")
    (robot / "b.xacro").write_text(
        '<robot name="b"><link name="l"><visual><geometry>'
        '<mesh filename="$(find no_such_pkg)/m.stl"/></geometry></visual></link></robot>'
    )
    with pytest.raises(ConversionError, match="package 'no_such_pkg' not found"):
        urdf_to_hrdf(robot / "b.xacro")


# ---------------------------------------------------------------- hostile input
@pytest.fixture
def robot_dir(tmp_path: Path) -> Path:
    folder = tmp_path / "robot" / "urdf"
    folder.mkdir(parents=True)
    (tmp_path / "secret.xacro").write_text(
        '<robot xmlns:xacro="http://www.ros.org/wiki/xacro"><link name="stolen"/></robot>'
    )
    (tmp_path / "secret.yaml").write_text("token: abc\n")
    return folder


def _xacro(folder: Path, body: str) -> Path:
    path = folder / "evil.urdf.xacro"
    path.write_text(
        f'<robot name="evil" xmlns:xacro="http://www.ros.org/wiki/xacro">{body}'
        '<link name="base"/></robot>'
    )
    return path


@pytest.mark.parametrize(
    ("body", "match"),
    [
        ('<xacro:include filename="../../secret.xacro"/>', "outside the robot folder"),
        ('<xacro:include filename="/etc/hostname"/>', "outside the robot folder"),
        (
            '<xacro:property name="s" value="${xacro.load_yaml(\'../../secret.yaml\')}"/>'
            "<link name=\"${s['token']}\"/>",
            "outside the robot folder",
        ),
        ('<link name="$(env HOME)"/>', r"\$\(env HOME\): reading the environment is refused"),
    ],
)
def test_hostile_xacro_is_refused(robot_dir: Path, body: str, match: str) -> None:
    with pytest.raises(ConversionError, match=match):
        urdf_to_hrdf(_xacro(robot_dir, body))


MACRO_BOMB = "".join(
    f'<xacro:macro name="m{k}"><xacro:m{k - 1}/><xacro:m{k - 1}/></xacro:macro>'
    for k in range(1, 40)
)


@pytest.mark.parametrize(
    "body",
    [
        '<xacro:macro name="m0"><link name="x"/></xacro:macro>' + MACRO_BOMB + "<xacro:m39/>",
        "<link name=\"${'x' * 10**10}\"/>",
    ],
    ids=["macro-explosion", "huge-expression"],
)
def test_expansion_bombs_stop_at_the_limits(robot_dir: Path, body: str, monkeypatch) -> None:
    import robotwright.parsers.xacro.expand as X

    monkeypatch.setattr(X, "XACRO_CPU_S", 2)
    monkeypatch.setattr(X, "XACRO_MEMORY_BYTES", 1 << 30)
    monkeypatch.setattr(X, "XACRO_TIMEOUT_S", 20)
    with pytest.raises(ConversionError, match="refused"):
        urdf_to_hrdf(_xacro(robot_dir, body))


def test_entities_in_an_included_file_are_refused(robot_dir: Path) -> None:
    (robot_dir / "bomb.xacro").write_text(
        '<?xml version="1.0"?><!DOCTYPE r [<!ENTITY a "aaaaaaaaaa">'
        '<!ENTITY b "&a;&a;&a;&a;&a;&a;&a;&a;&a;&a;">]>'
        '<robot xmlns:xacro="http://www.ros.org/wiki/xacro"><link name="&b;"/></robot>'
    )
    with pytest.raises(ConversionError, match="unsafe XML refused"):
        urdf_to_hrdf(_xacro(robot_dir, '<xacro:include filename="bomb.xacro"/>'))


def test_optenv_gives_its_default_not_the_environment(robot_dir: Path, monkeypatch) -> None:
    monkeypatch.setenv("ROBOT_PREFIX", "leaked_")
    path = robot_dir / "p.urdf.xacro"
    path.write_text(
        '<robot name="p"><link name="$(optenv ROBOT_PREFIX my_)base"><inertial>'
        '<mass value="1"/><inertia ixx="1" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/>'
        "</inertial></link></robot>"
    )
    model = our_mjcf_model(urdf_to_hrdf(path))
    names = [model.body(i).name for i in range(model.nbody)]
    assert "my_base" in names and not any("leaked" in n for n in names)


# ---------------------------------------------------------------- CLI
def test_cli_convert_with_xacro_args(arm_package: Path, tmp_path: Path, capsys) -> None:
    out = tmp_path / "arm.xml"
    src = str(arm_package / "urdf" / "arm.urdf.xacro")
    assert main(["convert", src, "--xacro-arg", "length:=0.5", "-o", str(out)]) == 0
    expected = tmp_path / "expected.xml"
    assert (
        main(["convert", str(arm_package / "urdf" / "expected_long.urdf"), "-o", str(expected)])
        == 0
    )
    _same(mujoco.MjModel.from_xml_path(str(out)), mujoco.MjModel.from_xml_path(str(expected)))
    capsys.readouterr()
    with pytest.raises(SystemExit) as exc:
        main(["convert", src, "--xacro-arg", "length=0.5", "-o", str(tmp_path / "b.xml")])
    assert exc.value.code == 2
    assert "expected NAME:=VALUE" in capsys.readouterr().err
    assert not (tmp_path / "b.xml").exists()


def test_cli_refuses_hostile_xacro_with_exit_2(robot_dir: Path, tmp_path: Path, capsys) -> None:
    src = _xacro(robot_dir, '<xacro:include filename="../../secret.xacro"/>')
    out = tmp_path / "o.xml"
    assert main(["convert", str(src), "-o", str(out)]) == 2
    err = capsys.readouterr().err
    assert "outside the robot folder" in err and "Traceback" not in err
    assert not out.exists()


def test_xacro_source_text_is_not_mistaken_for_urdf(tmp_path: Path) -> None:
    # A .xacro holding plain URDF (no macros) reads like the URDF itself.
    folder = tmp_path / "plain" / "urdf"
    folder.mkdir(parents=True)
    text = textwrap.dedent(
        """\
        <robot name="plain"><link name="a"><inertial><mass value="1"/>
          <inertia ixx="1" iyy="2" izz="2.5" ixy="0" ixz="0" iyz="0"/></inertial></link>
        <joint name="j" type="prismatic"><parent link="a"/><child link="b"/><axis xyz="1 0 0"/>
          <limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
        <link name="b"><inertial><mass value="0.5"/>
          <inertia ixx="1" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/></inertial></link></robot>"""
    )
    (folder / "p.xacro").write_text(text)
    (folder / "p.urdf").write_text(text)
    _same(
        our_mjcf_model(urdf_to_hrdf(folder / "p.xacro")),
        our_mjcf_model(urdf_to_hrdf(folder / "p.urdf")),
    )


# ---------------------------------------------------------------- expressions without eval
ROOT = Path(__file__).resolve().parents[2]
ERD_SHARE = Path(sysconfig.get_paths()["purelib"]) / "cmeel.prefix/share/example-robot-data"
#: xacro's own test files (tools/fetch_test_data.py), robosuite's and example-robot-data's.
CORPUS = sorted(
    p
    for folder in (ROOT / ".testdata/xacro-tests", PANDA, ERD_SHARE)
    if folder.is_dir()
    for p in folder.rglob("*.xacro")
)


class _AgainstPython:
    """Installs our evaluator, but checks each ``${...}`` value against Python's ``eval``
    (a trusted helper for trusted corpus files only), counting the expressions."""

    def __init__(self) -> None:
        self.count = 0
        self.mismatches: list[tuple[str, str, str]] = []

    def __call__(self, xacro, substitution_args):  # noqa: ANN001, ANN204 - xacro's modules
        from robotwright.parsers.xacro.expressions import installed

        hook = installed(xacro, substitution_args)
        ours = hook.safe_eval

        def both(expr: str, symbols, _locals=None):  # noqa: ANN001, ANN202
            mine = ours(expr, symbols)
            dict.update(symbols, __builtins__={})  # as xacro's own safe_eval does
            try:
                theirs = builtins.eval(compile(expr.strip(), "<expr>", "eval"), symbols)
            finally:
                dict.pop(symbols, "__builtins__", None)
            self.count += 1
            if type(mine) is not type(theirs) or str(mine) != str(theirs):
                self.mismatches.append((expr, repr(mine), repr(theirs)))
            return mine

        hook.safe_eval = both
        return hook


def _expand(path: Path, installer) -> str:  # noqa: ANN001
    import robotwright.parsers.xacro.expand as X

    saved = X.installed
    X.installed = installer
    try:
        return X._expand_here(path, xacro_args={}, package_map=None, trusted=())[0]
    except ConversionError as exc:
        return f"refused: {exc}"
    finally:
        X.installed = saved


@pytest.mark.skipif(not CORPUS, reason="no xacro corpus (run tools/fetch_test_data.py)")
def test_corpus_expands_as_with_python_eval() -> None:
    # Every corpus file expands with our evaluator exactly as with Python's eval (the
    # xacro package as shipped): same URDF (canonical XML), and every ${...} value the
    # same type and text.
    import contextlib

    checker = _AgainstPython()
    expanded = 0
    for path in CORPUS:
        shipped = _expand(path, lambda *_: contextlib.nullcontext())
        ours = _expand(path, checker)
        if shipped.startswith("refused:"):
            assert ours.startswith("refused:"), path  # fragments needing arguments
            continue
        assert not ours.startswith("refused:"), (path, ours)
        assert ET.canonicalize(ours, strip_text=True) == ET.canonicalize(shipped, strip_text=True)
        expanded += 1
    assert checker.mismatches == []
    # All of robosuite's and example-robot-data's files expand, and most of xacro's own.
    assert expanded >= len([p for p in CORPUS if "xacro-tests" not in str(p)])
    assert checker.count > 0


PROPS = {"a": 2, "b": 0.5, "s": "Link_A", "l": [1, 2, 3], "t": (1, "x"), "d": {"k": 1, "m": [4]}}
BENIGN = (
    "1 + 2 * 3 - 4 / 8",
    "7 // 2 + 7 % 3 - -a",
    "2 ** 10 + 2 ** -1 + a ** b",
    "(1 << 4) | 3 ^ 5 & 6 >> 1",
    "~a",
    "1 < a <= 2 != 3",
    "a if b > 1 else -a",
    "not a or b and s",
    "a in l and 'x' in t and 'k' in d and 'k' not in l",
    "[1, 2.5, 'x', True, None]",
    "(1,)",
    "{'x': a, **d}",
    "[*l, *t]",
    "l[-1] + l[0:2][1] + d['m'][0]",
    "s[::-1] + s[1:3]",
    "[x * 2 for x in l if x > 1]",
    "[i * j for i in l for j in range(2)]",
    "{k: v for k, v in d.items()}",
    "python.sum(x for x in l)",
    "python.sum([x ** 2 for x in l])",
    "sin(pi / 4) + cos(0) + math.sqrt(2) + radians(90) + degrees(1)",
    "math.atan2(1, 2) + fabs(-1) + floor(2.5) + ceil(2.5) + log(e) + exp(1) + tau",
    "min(l) + max(l) + len(l) + round(2.567, 2) + int('7') + float('1.5')",
    "str(a) + str(b) + str(l) + str(True)",
    "list(t) + list(map(float, ['1', '2']))",
    "dict(a=1, b=2)",
    "sorted(l, reverse=True)",
    "sorted(['bb', 'a'], key=len)",
    "list(range(0, 10, 3))",
    "bool(0) or bool([])",
    "s.lower() + s.upper() + s.replace('_', '-') + s.strip('L')",
    "s.split('_') + 'a b  c'.split()",
    "'-'.join(['x', 'y']) + s.zfill(10) + s.center(9, '*')",
    "s.startswith('Li') and s.endswith('A') and s.find('_') == 4",
    "'%s_%d_%.3f' % (s, a, b)",
    "'%(k)s' % d",
    "d.get('z', 5) + len(d.keys()) + len(list(d.values()))",
    "l.index(2) + l.count(1) + t.count('x')",
    "python.abs(-a) + python.divmod(7, 2)[0]",
    "python.all(l) and python.any([0, a])",
    "python.zip(l, l)",
    "python.enumerate(['x'])",
    "python.reversed(l)",
    "python.ord('a')",
    "b.is_integer()",
    "2.0 * 3",
    "1e-3 + 1.5e2",
    "'caf\\u00e9' + s",
    "10 ** 100",
    "-0.0",
    "pi",
    "inf > 1e308",
    "(a, b) == (2, 0.5)",
)


@pytest.mark.parametrize("expr", BENIGN)
def test_benign_expressions_equal_pythons(expr: str) -> None:
    from robotwright.parsers.xacro.expressions import Evaluator, default_names

    ours = Evaluator(lambda name: PROPS[name], default_names()).evaluate(expr)
    # Python's eval over the same names, with xacro's symbols (the real builtins).
    env = {k: v for k, v in vars(math).items() if not k.startswith("_")}
    env.update(vars(builtins))
    env.update(PROPS, math=math, python=builtins)
    theirs = builtins.eval(expr, {**env, "__builtins__": {}})  # globals, as xacro passes
    if hasattr(theirs, "__next__"):
        theirs = list(theirs)  # ours are lists (documented); the items must be equal
    assert type(ours) is type(theirs)
    assert ours == theirs or (ours != ours and theirs != theirs)
