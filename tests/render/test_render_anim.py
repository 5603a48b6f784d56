"""``render --groups/--hide-groups``, the default output name, and GIF/MP4 animations
(read back with Pillow and imageio)."""

from __future__ import annotations

import sys
from pathlib import Path

import mujoco
import numpy as np
import pytest
from PIL import Image

from robotwright.cli import main
from robotwright.cli.render import default_output
from robotwright.render import RenderError, RenderOptions, render_animation, render_model
from robotwright.render.anim import simulate_states, sweep_states
from robotwright.render.core import _scene

#: A floor, a robot arm (group 0) and its collision box (group 3), a falling box.
XML = """<mujoco><compiler angle="radian"/><option timestep="0.004"/><worldbody>
  <light pos="0 0 3" dir="0 0 -1"/>
  <geom type="plane" size="2 2 0.1" rgba="0.8 0.8 0.8 1"/>
  <body name="arm" pos="0 0 0.4"><joint name="hinge" axis="0 1 0" range="-1 0.5"/>
    <geom type="capsule" fromto="0 0 0 0.4 0 0" size="0.04" rgba="0.2 0.4 0.9 1"/>
    <geom type="box" pos="0.2 0 0" size="0.25 0.08 0.08" group="3" rgba="0.9 0.2 0.2 1"/>
  </body>
  <body name="box" pos="-0.3 0 0.5"><freejoint name="box"/><geom type="box" size="0.05 0.05 0.05"/></body>
</worldbody></mujoco>"""

SMALL = {"width": 64, "height": 48, "backend": "software", "supersample": 1}


@pytest.fixture
def model_file(tmp_path: Path) -> Path:
    path = tmp_path / "two_things.xml"
    path.write_text(XML)
    return path


def _drawn_geoms(model: mujoco.MjModel, groups: tuple[int, ...]) -> set[int]:
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    scene = _scene(model, data, mujoco.MjvCamera(), groups)
    return {
        int(scene.geoms[i].objid)
        for i in range(scene.ngeom)
        if int(scene.geoms[i].objtype) == int(mujoco.mjtObj.mjOBJ_GEOM)
    }


@pytest.mark.parametrize("groups", [(0, 1, 2), (3,), (0, 3), (), (0, 1, 2, 3, 4, 5)])
def test_groups_draw_exactly_the_geoms_of_those_groups(groups: tuple[int, ...]) -> None:
    model = mujoco.MjModel.from_xml_string(XML)
    expected = {g for g in range(model.ngeom) if int(model.geom_group[g]) in groups}
    assert _drawn_geoms(model, groups) == expected


def test_hiding_the_collision_group_changes_the_picture_only_where_it_is() -> None:
    model = mujoco.MjModel.from_xml_string(XML)
    with_collision = render_model(model, None, RenderOptions(**SMALL, geom_groups=(0, 3)))
    visual = render_model(model, None, RenderOptions(**SMALL, geom_groups=(0,)))
    camera = "150,-25,2.5"  # one camera for both: framing follows what is drawn
    a = render_model(model, None, RenderOptions(**SMALL, camera=camera, geom_groups=(0, 3)))
    b = render_model(model, None, RenderOptions(**SMALL, camera=camera, geom_groups=(0,)))
    c = render_model(model, None, RenderOptions(**SMALL, camera=camera, geom_groups=(0, 4)))
    assert not np.array_equal(a.image, b.image)  # the red collision box is drawn in a only
    np.testing.assert_array_equal(b.image, c.image)  # group 4 is empty: nothing changes
    assert with_collision.image.shape == visual.image.shape == (48, 64, 3)


@pytest.mark.parametrize("bad", [(6,), (-1,), (True,), [0, 1], ("0",)])
def test_groups_option_is_checked(bad: object) -> None:
    with pytest.raises(RenderError, match="geom_groups"):
        RenderOptions(geom_groups=bad)  # type: ignore[arg-type]


@pytest.mark.parametrize(
    ("source", "name"),
    [
        ("arm6", "arm6.png"),
        ("robots/go1.urdf", "go1.png"),
        ("x/pr2.urdf.xacro", "pr2.png"),
        ("scene/semantic_scene.xml", "semantic_scene.png"),
        ("out/limb/", "limb.png"),
        ("example-robot-data:talos", "example-robot-data_talos.png"),
        ("../..", "picture.png"),
        (".hidden.xml", "hidden.png"),
    ],
)
def test_default_output_name(source: str, name: str) -> None:
    assert default_output(source, ".png") == Path(name)


def test_cli_default_output_respects_the_overwrite_rule(
    model_file: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys
) -> None:
    monkeypatch.chdir(tmp_path)
    args = ["render", str(model_file), "--size", "64x48", "--backend", "software"]
    assert main(args) == 0
    written = tmp_path / "two_things.png"
    assert Image.open(written).size == (64, 48)
    assert "wrote two_things.png" in capsys.readouterr().out
    before = written.read_bytes()
    assert main(args) == 2
    assert "give --overwrite" in capsys.readouterr().err
    assert written.read_bytes() == before
    assert main([*args, "--hide-groups", "3", "--overwrite"]) == 0


@pytest.mark.parametrize(
    ("extra", "message"),
    [
        (["--groups", "7"], "expected comma-separated geom groups 0..5"),
        (["--groups", "0,x"], "expected comma-separated geom groups"),
        # argparse words the exclusion; what matters is exit 2 naming the option.
        (["--groups", "1", "--hide-groups", "3"], "--hide-groups"),
        (["--sweep", "nan"], "expected seconds in (0, 60]"),
        (["--simulate", "0"], "expected seconds in (0, 60]"),
        (["--simulate", "61"], "expected seconds in (0, 60]"),
        (["--sweep", "1", "--fps", "inf"], "expected frames per second"),
        (["--sweep", "--simulate", "1"], "--simulate"),
        (["--sweep", "-o", "x.png"], "x.png: expected a .gif or .mp4 output file"),
        (["-o", "x.gif"], "x.gif: an animation needs --sweep or --simulate"),
        (["--simulate", "60", "--fps", "60"], "3600 frames; at most 1000"),
    ],
)
def test_cli_animation_options_are_checked(
    model_file: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys, extra, message
) -> None:
    monkeypatch.chdir(tmp_path)
    before = sorted(tmp_path.iterdir())
    try:
        code = main(["render", str(model_file), "--size", "64x48", *extra])
    except SystemExit as exc:
        code = exc.code
    assert code == 2
    err = capsys.readouterr().err
    # The error line (argparse prints its usage before it) names the problem.
    assert message in err.splitlines()[-1] and "Traceback" not in err
    assert sorted(tmp_path.iterdir()) == before


def test_sweep_states_reach_the_limits_and_return(model_file: Path) -> None:
    model = mujoco.MjModel.from_xml_path(str(model_file))
    states = sweep_states(model, model.qpos0, 40)
    hinge = states[:, model.jnt_qposadr[model.joint("hinge").id]]
    assert hinge[0] == 0.0 and hinge.max() == pytest.approx(0.5) and hinge.min() == -1.0
    free = model.jnt_qposadr[model.joint("box").id]
    # the free joint keeps its pose
    np.testing.assert_array_equal(
        states[:, free : free + 7], np.tile(model.qpos0[free : free + 7], (40, 1))
    )


def test_gif_of_a_simulation_has_one_frame_per_step_of_the_clock(
    model_file: Path, tmp_path: Path
) -> None:
    out = tmp_path / "fall.gif"
    opts = RenderOptions(**SMALL)
    animation = render_animation(model_file, out, opts, simulate=0.3, fps=20)
    assert animation.frames.shape == (6, 48, 64, 3)
    # the states are MuJoCo's own rollout at the frame times
    model = mujoco.MjModel.from_xml_path(str(model_file))
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    states, times = simulate_states(model, data, 6, 20)
    np.testing.assert_allclose(times, animation.times)
    box = model.jnt_qposadr[model.joint("box").id]
    assert states[-1, box + 2] < states[0, box + 2]  # the box falls
    with Image.open(out) as gif:
        assert gif.size == (64, 48)
        durations = []
        for k in range(gif.n_frames):
            gif.seek(k)
            durations.append(gif.info["duration"])
        # Pillow stores identical consecutive frames once, for their summed time.
        assert gif.n_frames <= 6 and sum(durations) == 6 * 50
        assert gif.n_frames >= 3  # the box moves: the frames differ


def test_sweep_gif_from_the_command_line(
    model_file: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys
) -> None:
    monkeypatch.chdir(tmp_path)
    args = ["render", str(model_file), "--sweep", "1", "--fps", "5", "--size", "64x48"]
    assert main([*args, "--backend", "software"]) == 0
    said = capsys.readouterr().out
    assert "wrote two_things.gif (5 frames of a sweep, 64x48, 5 frames/s" in said
    import imageio.v3 as iio

    frames = iio.imread(tmp_path / "two_things.gif", index=None)
    assert frames.shape[1:3] == (48, 64) and 2 <= frames.shape[0] <= 5


def test_mp4_frames_read_back(model_file: Path, tmp_path: Path) -> None:
    pytest.importorskip("imageio_ffmpeg")
    import imageio.v2 as iio2

    out = tmp_path / "fall.mp4"
    render_animation(model_file, out, RenderOptions(**SMALL), simulate=0.25, fps=20)
    reader = iio2.get_reader(out, format="FFMPEG")
    try:
        count, first = reader.count_frames(), reader.get_data(0)
    finally:
        reader.close()
    assert count == 5 and first.shape == (48, 64, 3)


def test_missing_imageio_is_one_clear_error_and_nothing_is_drawn(
    model_file: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys
) -> None:
    monkeypatch.setitem(sys.modules, "imageio", None)
    monkeypatch.setitem(sys.modules, "imageio.v3", None)
    monkeypatch.chdir(tmp_path)
    assert main(["render", str(model_file), "--sweep", "--size", "64x48"]) == 2
    err = capsys.readouterr().err
    assert "robotwright[video]" in err and err.count("error:") == 1
    assert not (tmp_path / "two_things.gif").exists()


def test_mp4_without_imageio_ffmpeg_names_it(
    model_file: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setitem(sys.modules, "imageio_ffmpeg", None)
    with pytest.raises(RenderError, match="imageio-ffmpeg"):
        render_animation(model_file, tmp_path / "x.mp4", RenderOptions(**SMALL), sweep=1.0)
    assert not (tmp_path / "x.mp4").exists()


def test_odd_mp4_size_is_refused(model_file: Path, tmp_path: Path) -> None:
    pytest.importorskip("imageio_ffmpeg")
    opts = RenderOptions(width=65, height=48, backend="software", supersample=1)
    with pytest.raises(RenderError, match="even width and height"):
        render_animation(model_file, tmp_path / "x.mp4", opts, sweep=0.2, fps=10)
    assert not (tmp_path / "x.mp4").exists()
