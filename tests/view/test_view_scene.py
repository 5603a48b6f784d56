"""Every kind of source the viewer takes, loaded through the project's readers; bad
input gets a located error (exit code 2 on the command line)."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import mujoco
import numpy as np
import pytest

from robotwright.errors import RobotwrightError, UnsafePathError
from robotwright.generators import MJCFHumanoidGenerator
from robotwright.hrdf.model import HRDF
from robotwright.scene.load import ViewError, load_source

# The reference models are generated here too; what MJCF/URDF cannot hold is not the
# viewer's concern.
pytestmark = pytest.mark.filterwarnings("ignore::robotwright.errors.ConversionWarning")

ROOM = """
<mujoco>
  <worldbody>
    <geom name="floor" type="plane" size="3 3 0.1"/>
    <geom name="wall_a" type="box" size="0.05 2 1" pos="2 0 1"/>
    <body name="sofa" pos="-1 0 0.3"><geom name="sofa_seat" type="box" size="0.5 0.3 0.3"/></body>
    <body name="scanner" pos="0 0 0.8"><site name="lidar"/></body>
  </worldbody>
</mujoco>
"""


def _reference_model(name: str) -> mujoco.MjModel:
    return MJCFHumanoidGenerator.from_hrdf(HRDF.from_robot_name(name)).to_model()


def _same_model(a: mujoco.MjModel, b: mujoco.MjModel) -> None:
    assert (a.nbody, a.njnt, a.ngeom, a.nu) == (b.nbody, b.njnt, b.ngeom, b.nu)
    np.testing.assert_allclose(a.body_mass, b.body_mass)
    np.testing.assert_allclose(a.geom_rgba, b.geom_rgba)


@pytest.mark.parametrize("name", ["mini_humanoid", "arm6"])
def test_bundled_robot_by_name(name: str) -> None:
    scene = load_source(name)
    assert scene.kind == "robot" and scene.title == name
    _same_model(scene.model, _reference_model(name))


def test_hrdf_folder_and_object(tmp_path: Path) -> None:
    hrdf = HRDF.from_robot_name("arm6")
    hrdf.save(tmp_path / "arm")
    from_dir = load_source(tmp_path / "arm")
    from_obj = load_source(hrdf)
    _same_model(from_dir.model, _reference_model("arm6"))
    _same_model(from_obj.model, from_dir.model)


def test_mjcf_and_urdf_files(tmp_path: Path) -> None:
    from robotwright.tasks import export_robot

    paths = export_robot("mini_humanoid", tmp_path)
    mjcf = load_source(paths["mjcf"])
    assert mjcf.kind == "mjcf"
    # compiled by MuJoCo as written: the same model MuJoCo loads from the file
    _same_model(mjcf.model, mujoco.MjModel.from_xml_path(str(paths["mjcf"])))
    urdf = load_source(paths["urdf"])
    assert urdf.kind == "urdf"
    hinges = [
        int((m.jnt_type == int(mujoco.mjtJoint.mjJNT_HINGE)).sum())
        for m in (urdf.model, mjcf.model)
    ]
    assert hinges[0] == hinges[1] > 0
    np.testing.assert_allclose(urdf.model.body_mass.sum(), mjcf.model.body_mass.sum())


def test_design_folder(tmp_path: Path) -> None:
    from robotwright.grammar import default_grammar, demo_limb_design
    from robotwright.grammar.build import build_hrdf
    from robotwright.grammar.export import export_design

    grammar, design = default_grammar(), demo_limb_design(3)
    export_design(grammar, design, tmp_path / "limb", picture=False)
    scene = load_source(tmp_path / "limb")
    assert scene.kind == "design"
    reference = MJCFHumanoidGenerator.from_hrdf(build_hrdf(grammar, design)).to_model()
    _same_model(scene.model, reference)
    # without its MJCF the design is rebuilt from design.txt with the bundled grammar
    (tmp_path / "limb" / "srl.xml").unlink()
    _same_model(load_source(tmp_path / "limb").model, reference)


def _scan(tmp_path: Path) -> tuple[Path, Path]:
    from robotwright.sensors import scan_to_files

    scene = tmp_path / "room.xml"
    scene.write_text(ROOM, encoding="utf-8")
    model = mujoco.MjModel.from_xml_path(str(scene))
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    npz = tmp_path / "scan.npz"
    scan_to_files(model, data, "lidar", "vlp16", npz, exclude_robot=False)
    return npz, scene


def test_scan_with_its_scene(tmp_path: Path) -> None:
    npz, room = _scan(tmp_path)
    scene = load_source(npz, scene=room)
    raw = np.load(npz)
    hits = raw["hit_mask"]
    assert scene.kind == "scan" and scene.model.ngeom == 3
    assert scene.scan is not None
    np.testing.assert_array_equal(scene.scan.points, raw["points"][hits])
    np.testing.assert_array_equal(scene.scan.labels, raw["labels"][hits])
    assert scene.scan.num_rays == len(hits)
    counts = scene.scan.class_counts()
    assert counts["valuable"] > 0 and counts["terrain"] > 0  # sofa and floor/wall
    assert sum(counts.values()) == int(hits.sum())
    # points only, without the scene
    alone = load_source(npz)
    assert alone.model.nbody == 1 and len(alone.scan.points) == int(hits.sum())


def test_bad_scan_files(tmp_path: Path) -> None:
    npz, _ = _scan(tmp_path)
    raw = dict(np.load(npz))
    bad = tmp_path / "bad.npz"
    np.savez(bad, points=raw["points"])
    with pytest.raises(ViewError, match="bad.npz: scan file lacks array.*labels"):
        load_source(bad)
    raw["labels"] = raw["labels"] + 50
    np.savez(bad, **raw)
    with pytest.raises(ViewError, match="'labels': class id 5[0-9] outside"):
        load_source(bad)
    np.savez(bad, points=np.zeros(3), labels=np.zeros(3, int), class_names=np.array(["a"]))
    with pytest.raises(ViewError, match=r"'points': expected shape \(N, 3\)"):
        load_source(bad)
    np.savez(bad, points=np.zeros((1, 3)), labels=np.zeros(1, int), x=np.array([object()]))
    with pytest.raises(ViewError, match="lacks"):
        load_source(bad)
    (tmp_path / "junk.npz").write_bytes(b"not a zip")
    with pytest.raises(ViewError, match="junk.npz: not a readable .npz"):
        load_source(tmp_path / "junk.npz")


def test_bad_sources(tmp_path: Path) -> None:
    (tmp_path / "notes.txt").write_text("x", encoding="utf-8")
    with pytest.raises(ViewError, match=r"notes.txt: cannot show a '.txt' file"):
        load_source(tmp_path / "notes.txt")
    with pytest.raises(ViewError, match="missing.xml: no such file"):
        load_source(tmp_path / "missing.xml")
    with pytest.raises(RobotwrightError, match="no robot named 'no_such_robot'"):
        load_source("no_such_robot")
    with pytest.raises(ViewError, match="applies to a scan"):
        load_source("arm6", scene=tmp_path / "x.xml")
    bomb = tmp_path / "bomb.xml"
    bomb.write_text(
        '<!DOCTYPE m [<!ENTITY a "aaaa">]><mujoco><worldbody>&a;</worldbody></mujoco>',
        encoding="utf-8",
    )
    with pytest.raises(ViewError, match="bomb.xml"):
        load_source(bomb)
    (tmp_path / "model").mkdir()
    outside = tmp_path / "model" / "robot.xml"
    outside.write_text(
        '<mujoco><asset><mesh name="m" file="../secret.stl"/></asset>'
        '<worldbody><geom type="mesh" mesh="m"/></worldbody></mujoco>',
        encoding="utf-8",
    )
    with pytest.raises(UnsafePathError, match="secret.stl"):
        load_source(outside)
    broken = tmp_path / "broken.xml"
    broken.write_text("<mujoco><worldbody><geom type='box'/></worldbody></mujoco>", "utf-8")
    with pytest.raises(ViewError, match="broken.xml: MuJoCo cannot load it"):
        load_source(broken)


def test_initial_pose_is_keyframe_zero(tmp_path: Path) -> None:
    xml = tmp_path / "k.xml"
    xml.write_text(
        '<mujoco><worldbody><body><joint name="j"/><geom size="0.1"/></body></worldbody>'
        '<keyframe><key qpos="0.7"/></keyframe></mujoco>',
        encoding="utf-8",
    )
    np.testing.assert_allclose(load_source(xml).initial_qpos(), [0.7])
    np.testing.assert_allclose(load_source("arm6").initial_qpos(), load_source("arm6").model.qpos0)


def test_cli_bad_input_exit_2_without_traceback(tmp_path: Path) -> None:
    (tmp_path / "robot.txt").write_text("x", encoding="utf-8")
    for args in (
        [str(tmp_path / "robot.txt")],
        ["no_such_robot"],
        ["arm6", "--port", "70000"],
        ["arm6", "--groups", "7"],
    ):
        run = subprocess.run(
            [sys.executable, "-m", "robotwright", "view", *args],
            capture_output=True,
            text=True,
            timeout=60,
        )
        assert run.returncode == 2, (args, run.stderr)
        assert "Traceback" not in run.stderr
        assert "error" in run.stderr


#: Seconds after which a viewer test that hangs is ended. Never a measure of speed: each
#: step waits for its signal (the address line, the page, the exit), however loaded the
#: machine is; this only stops a test that would otherwise wait forever.
HANG_GUARD_S = 600


def test_cli_serves_the_page_until_ctrl_c(tmp_path: Path) -> None:
    """``robotwright view arm6 --port 0`` prints the address, serves the page there, and
    stops cleanly on Ctrl-C (SIGINT)."""
    import re
    import signal
    import urllib.request

    # stderr goes to a file: a pipe nobody reads could fill and stop the viewer.
    with (tmp_path / "stderr.txt").open("w+") as errors:
        proc = subprocess.Popen(
            [sys.executable, "-m", "robotwright", "view", "arm6", "--port", "0"],
            stdout=subprocess.PIPE,
            stderr=errors,
            text=True,
        )
        try:
            # Readiness: the address line is printed once the server listens, inside
            # the block that turns Ctrl-C into a clean stop.
            lines = []
            for line in proc.stdout:
                lines.append(line)
                if "Ctrl-C" in line:
                    break
            match = re.search(r"open (http://127\.0\.0\.1:\d+) in a browser", "".join(lines))
            assert match, lines
            assert lines[0].startswith("arm6: 7 bodies, 6 joints,")
            with urllib.request.urlopen(match.group(1), timeout=HANG_GUARD_S) as page:
                assert page.status == 200 and b"<html" in page.read().lower()
            proc.send_signal(signal.SIGINT)
            # A user pressing Ctrl-C twice: the second lands while the server stops.
            for line in proc.stdout:
                if line.startswith("stopped"):
                    proc.send_signal(signal.SIGINT)
                    break
            out, _ = proc.communicate(timeout=HANG_GUARD_S)
        finally:
            if proc.poll() is None:
                proc.kill()
                proc.wait()
        errors.seek(0)
        err = errors.read()
    assert proc.returncode == 0, err
    assert "Traceback" not in err and "interrupted" not in err


def test_composed_scene(tmp_path: Path) -> None:
    """A scene written by compose_scene (two robots, prefixed) is shown as MuJoCo
    compiles it: both robots, each at its placement."""
    from robotwright.tasks import compose_scene

    xml = compose_scene(
        {"h": "mini_humanoid", "arm": "arm6"},
        tmp_path / "scene.xml",
        placements={"h": (0.0, 0.0, 0.0), "arm": (1.5, 0.5, 0.0)},
    )
    scene = load_source(xml)
    reference = mujoco.MjModel.from_xml_path(str(xml))
    _same_model(scene.model, reference)
    names = {scene.model.body(b).name for b in range(scene.model.nbody)}
    assert any(n.startswith("h_") for n in names) and any(n.startswith("arm_") for n in names)


def test_xacro_file(tmp_path: Path) -> None:
    """A .urdf.xacro is expanded (default arguments) and read as its URDF would be."""
    pytest.importorskip("xacro", reason="the xacro extra is not installed")
    body = (
        '<link name="{n}"><inertial><mass value="{m}"/>'
        '<inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>'
        '<visual><geometry><box size="0.1 0.1 {len}"/></geometry></visual></link>'
    )
    urdf = (
        '<robot name="two">'
        + body.format(n="base", m=1.0, len=0.5)
        + body.format(n="tip", m=0.5, len=0.5)
        + '<joint name="j" type="revolute"><parent link="base"/><child link="tip"/>'
        '<origin xyz="0 0 0.5"/><axis xyz="0 1 0"/>'
        '<limit lower="-1" upper="1" effort="1" velocity="1"/></joint></robot>'
    )
    macro = (
        '<robot name="two" xmlns:xacro="http://www.ros.org/wiki/xacro">'
        '<xacro:arg name="len" default="0.5"/>'
        + body.format(n="base", m=1.0, len="$(arg len)")
        + body.format(n="tip", m=0.5, len="$(arg len)")
        + urdf[urdf.index("<joint") :]
    )
    (tmp_path / "two.urdf").write_text(urdf, encoding="utf-8")
    (tmp_path / "two.urdf.xacro").write_text(macro, encoding="utf-8")
    plain, expanded = load_source(tmp_path / "two.urdf"), load_source(tmp_path / "two.urdf.xacro")
    assert expanded.kind == "urdf"
    _same_model(expanded.model, plain.model)
    np.testing.assert_allclose(expanded.model.geom_size, plain.model.geom_size)


def test_a_robot_is_called_by_its_own_name_in_every_command(tmp_path: Path) -> None:
    """A URDF file named otherwise than its robot (example-robot-data's talos_reduced.urdf
    holds robot 'talos'): view and render call it what info calls it."""
    import subprocess
    import sys

    urdf = (
        '<robot name="walker"><link name="base"><inertial><mass value="1"/>'
        '<inertia ixx="0.1" iyy="0.1" izz="0.1" ixy="0" ixz="0" iyz="0"/></inertial>'
        '<collision><geometry><box size="0.1 0.1 0.1"/></geometry></collision></link></robot>'
    )
    (tmp_path / "walker_reduced.urdf").write_text(urdf)
    scene = load_source(str(tmp_path / "walker_reduced.urdf"))
    info = subprocess.run(
        [sys.executable, "-m", "robotwright", "info", "walker_reduced.urdf"],
        capture_output=True,
        text=True,
        cwd=tmp_path,
    )
    assert info.returncode == 0, info.stderr
    assert scene.title == "walker" and "robot walker:" in info.stdout


def test_a_scan_shown_in_another_scene_says_so(tmp_path: Path) -> None:
    npz, room = _scan(tmp_path)
    assert load_source(npz, scene=room).warnings == []
    other = tmp_path / "other.xml"
    other.write_text(ROOM.replace("</worldbody>", '<geom name="crate" size="0.2"/></worldbody>'))
    shown = load_source(npz, scene=other)
    assert len(shown.warnings) == 1
    assert "scan.npz was not taken in other.xml" in shown.warnings[0]
