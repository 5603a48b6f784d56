"""robotwright.render: the pictures show the model (software and OpenGL renderers)."""

from __future__ import annotations

import warnings

import matplotlib.image as mpimg
import mujoco
import numpy as np
import pytest

from robotwright.errors import ConversionWarning
from robotwright.render import (
    CameraError,
    RenderError,
    RenderOptions,
    SourceError,
    load_model,
    render_model,
)
from robotwright.render.gl import GLUnavailable, render_gl

SMALL = {"width": 160, "height": 120}

RED_BOX = """
<mujoco>
  <worldbody>
    <light pos="0 0 3" dir="0 0 -1"/>
    <geom name="floor" type="plane" size="2 2 0.1" rgba="0.5 0.5 0.5 1"/>
    <body name="red" pos="0 0 0.3">
      <geom name="red_box" type="box" size="0.2 0.2 0.2" rgba="0.9 0.1 0.1 1"/>
    </body>
  </worldbody>
</mujoco>
"""


def _robot() -> mujoco.MjModel:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ConversionWarning)
        return load_model("mini_humanoid").model


def _robot_alone(model: mujoco.MjModel) -> mujoco.MjModel:
    """The robot without its floor (the world body's geoms made invisible): what is not
    background in its picture is the robot. (Planes never move the framing.)"""
    alone = model.__copy__()
    alone.geom_rgba[alone.geom_bodyid == 0, 3] = 0.0
    return alone


def _not_background(picture) -> np.ndarray:
    """Pixels where a surface was drawn (finite depth)."""
    return np.isfinite(picture.depth)


def _gl_works() -> bool:
    model = mujoco.MjModel.from_xml_string(RED_BOX)
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    scene = mujoco.MjvScene(model, 100)
    mujoco.mjv_updateScene(
        model, data, mujoco.MjvOption(), None, mujoco.MjvCamera(), mujoco.mjtCatBit.mjCAT_ALL, scene
    )
    try:
        render_gl(model, scene, 32, 32)
    except GLUnavailable:
        return False
    return True


@pytest.mark.parametrize("backend", ["software", "gl"])
def test_robot_is_drawn_where_it_stands(backend: str) -> None:
    if backend == "gl" and not _gl_works():
        pytest.skip("no OpenGL platform (EGL/OSMesa) starts on this machine")
    model = _robot()
    opts = RenderOptions(backend=backend, **SMALL)
    picture = render_model(_robot_alone(model), None, opts)
    assert picture.backend.startswith(backend)
    diff = _not_background(picture)
    # The robot covers a good part of the picture, framed in its middle.
    assert 0.05 < diff.mean() < 0.6
    cols = np.nonzero(diff.any(axis=0))[0]
    rows = np.nonzero(diff.any(axis=1))[0]
    assert cols.min() > 0.15 * SMALL["width"] and cols.max() < 0.85 * SMALL["width"]
    assert rows.max() - rows.min() > 0.6 * SMALL["height"]  # a standing humanoid: tall


def test_two_camera_views_differ() -> None:
    model = _robot()
    front = render_model(model, None, RenderOptions(camera="front", backend="software", **SMALL))
    left = render_model(model, None, RenderOptions(camera="left", backend="software", **SMALL))
    top = render_model(model, None, RenderOptions(camera="top", backend="software", **SMALL))
    for a, b in ((front, left), (front, top), (left, top)):
        changed = np.abs(a.image.astype(int) - b.image.astype(int)).max(axis=2) > 30
        assert changed.mean() > 0.05


@pytest.mark.parametrize("backend", ["software", "gl"])
def test_red_geom_comes_out_reddish(backend: str) -> None:
    if backend == "gl" and not _gl_works():
        pytest.skip("no OpenGL platform (EGL/OSMesa) starts on this machine")
    model = mujoco.MjModel.from_xml_string(RED_BOX)
    picture = render_model(model, None, RenderOptions(backend=backend, **SMALL))
    img = picture.image.astype(int)
    h, w = img.shape[:2]
    centre = img[h // 3 : 2 * h // 3, w // 3 : 2 * w // 3].reshape(-1, 3)
    r, g, b = centre.mean(axis=0)
    assert r > 1.8 * g and r > 1.8 * b and r > 80
    # And nowhere else is red: the floor and the sky are not.
    red = (img[..., 0] > 1.8 * img[..., 1]) & (img[..., 0] > 1.8 * img[..., 2])
    assert 0.05 < red.mean() < 0.7


def test_software_and_gl_agree_on_the_silhouette() -> None:
    if not _gl_works():
        pytest.skip("no OpenGL platform (EGL/OSMesa) starts on this machine")
    model = _robot()
    masks = []
    for backend in ("software", "gl"):
        opts = RenderOptions(backend=backend, **SMALL)
        masks.append(_not_background(render_model(_robot_alone(model), None, opts)))
    iou = (masks[0] & masks[1]).sum() / (masks[0] | masks[1]).sum()
    assert iou > 0.8


def test_points_behind_a_wall_are_hidden() -> None:
    model = mujoco.MjModel.from_xml_string(
        """<mujoco><worldbody>
        <geom name="wall" type="box" size="0.05 1 1" rgba="0.8 0.8 0.8 1"/>
        <geom name="marker" type="sphere" pos="-2 0 0" size="0.01" rgba="0 0 0 1"/>
        <geom name="marker2" type="sphere" pos="2 0 0" size="0.01" rgba="0 0 0 1"/>
        </worldbody></mujoco>"""
    )
    # Camera on +x looking at -x: the point at x = +0.5 is in front of the wall, the
    # one at x = -0.5 behind it (same place in the picture).
    opts = RenderOptions(camera="front", backend="software", **SMALL)
    front = render_model(
        model, None, opts, points=np.array([[0.5, 0, 0]]), point_colors=np.array([[0, 0, 1.0]])
    )
    behind = render_model(
        model, None, opts, points=np.array([[-0.5, 0, 0]]), point_colors=np.array([[0, 0, 1.0]])
    )
    bare = render_model(model, None, opts)
    blue = lambda p: ((p.image[..., 2].astype(int) - p.image[..., 0]) > 100).sum()  # noqa: E731
    assert blue(front) > 0
    assert blue(behind) == 0
    assert blue(bare) == 0


def test_model_camera_by_name_and_unknown_camera() -> None:
    model = mujoco.MjModel.from_xml_string(
        RED_BOX.replace(
            "<worldbody>", '<worldbody><camera name="above" pos="0 0 4" xyaxes="1 0 0 0 1 0"/>'
        )
    )
    above = render_model(model, None, RenderOptions(camera="above", backend="software", **SMALL))
    img = above.image.astype(int)
    # Straight from above: the box fills the centre, red.
    c = img[50:70, 70:90].reshape(-1, 3).mean(axis=0)
    assert c[0] > 1.8 * c[1]
    with pytest.raises(CameraError, match="'nope': not a camera of the model .*above"):
        render_model(model, None, RenderOptions(camera="nope", **SMALL))


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"width": 8}, "picture width 8: expected an integer in 16..4096"),
        ({"height": 100000}, "picture height 100000"),
        ({"backend": "vulkan"}, "backend 'vulkan'"),
        ({"camera": "10,-100"}, "elevation -100.0 deg outside"),
        ({"camera": "10,x"}, "expected AZIMUTH,ELEVATION"),
        ({"camera": "10,-10,-3"}, "distance -3.0 m"),
        ({"supersample": 9}, "supersample 9"),
    ],
)
def test_bad_options_are_named(kwargs: dict, message: str) -> None:
    with pytest.raises((RenderError, CameraError), match=message.replace("(", r"\(")):
        RenderOptions(**kwargs)


def test_bad_points_are_named() -> None:
    model = mujoco.MjModel.from_xml_string(RED_BOX)
    with pytest.raises(RenderError, match=r"points: expected shape \(N, 3\)"):
        render_model(model, None, RenderOptions(**SMALL), points=np.zeros((4, 2)))
    with pytest.raises(RenderError, match="point_colors: expected RGB values in"):
        render_model(
            model,
            None,
            RenderOptions(**SMALL),
            points=np.zeros((1, 3)),
            point_colors=np.full((1, 3), 2.0),
        )


def test_gl_backend_refused_cleanly_when_disabled(monkeypatch) -> None:
    monkeypatch.setenv("MUJOCO_GL", "disable")
    model = mujoco.MjModel.from_xml_string(RED_BOX)
    with pytest.raises(RenderError, match="no OpenGL platform could draw"):
        render_model(model, None, RenderOptions(backend="gl", **SMALL))
    picture = render_model(model, None, RenderOptions(backend="auto", **SMALL))
    assert picture.backend == "software"
    assert any("OpenGL unavailable" in n for n in picture.notes)


def test_sources(tmp_path) -> None:
    xml = tmp_path / "box.xml"
    xml.write_text(RED_BOX, encoding="utf-8")
    assert load_model(xml).kind == "mjcf"
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ConversionWarning)
        assert load_model("arm6").model.nu == 6
    bad = tmp_path / "robot.stl"
    bad.write_bytes(b"solid x")
    with pytest.raises(SourceError, match="cannot show a '.stl' file"):
        load_model(bad)
    with pytest.raises(SourceError, match="missing.xml: no such file"):
        load_model(tmp_path / "missing.xml")
    broken = tmp_path / "broken.xml"
    broken.write_text("<mujoco><worldbody><geom type='box'/></worldbody>", encoding="utf-8")
    with pytest.raises(SourceError, match="broken.xml"):
        load_model(broken)
    urdf_root = tmp_path / "robot.xml"
    urdf_root.write_text('<robot name="r"><link name="a"/></robot>', encoding="utf-8")
    with pytest.raises(SourceError, match=r"root element <robot>: expected <mujoco>"):
        load_model(urdf_root)


def test_mesh_geoms_are_drawn() -> None:
    # An inline mesh (a pyramid): the software renderer takes its triangles from the
    # compiled model.
    model = mujoco.MjModel.from_xml_string(
        """<mujoco><asset>
        <mesh name="pyramid" vertex="-.3 -.3 0  .3 -.3 0  .3 .3 0  -.3 .3 0  0 0 .5"/>
        </asset><worldbody>
        <geom type="mesh" mesh="pyramid" rgba="0.1 0.8 0.1 1"/>
        </worldbody></mujoco>"""
    )
    picture = render_model(model, None, RenderOptions(backend="software", **SMALL))
    img = picture.image.astype(int)
    green = (img[..., 1] > 1.8 * img[..., 0]) & (img[..., 1] > 1.8 * img[..., 2])
    assert 0.05 < green.mean() < 0.8
    # Lit faces differ in shade: the pyramid's sides are not one flat colour.
    assert len(np.unique(img[green][:, 1] // 8)) >= 2


@pytest.mark.realdata
def test_unitree_g1_meshes_are_drawn(testdata_dir) -> None:
    xml = testdata_dir / "mjlab/mjlab/asset_zoo/robots/unitree_g1/xmls/g1.xml"
    if not xml.is_file():
        pytest.skip(f"mjlab's G1 is absent: {xml}")
    loaded = load_model(xml)
    picture = render_model(
        loaded.model, loaded.initial_data(), RenderOptions(backend="software", **SMALL)
    )
    drawn = np.isfinite(picture.depth)
    assert 0.05 < drawn.mean() < 0.7  # no floor in this file: what is drawn is the robot
    rows = np.nonzero(drawn.any(axis=1))[0]
    assert rows.max() - rows.min() > 0.6 * SMALL["height"]


def test_scan_source_draws_its_points_in_its_scene(tmp_path) -> None:
    from robotwright.render import render
    from robotwright.sensors.scan import save_npz

    scene = tmp_path / "scene.xml"
    scene.write_text(RED_BOX, encoding="utf-8")
    xs, ys = np.meshgrid(np.linspace(-1.5, 1.5, 40), np.linspace(-1.5, 1.5, 40))
    points = np.stack([xs.ravel(), ys.ravel(), np.full(xs.size, 0.001)], axis=1)
    npz = save_npz(
        tmp_path / "scan.npz",
        points=points,
        labels=np.ones(len(points), dtype=np.int64),
        class_names=np.array(["unknown", "terrain"]),
    )
    opts = RenderOptions(backend="software", camera="top", **SMALL)
    with_points = render(npz, tmp_path / "scan.png", opts, scene=scene)
    without = render(scene, None, opts)
    changed = np.abs(with_points.image.astype(int) - without.image.astype(int)).max(axis=2) > 30
    assert 0.05 < changed.mean() < 0.9
    # The box hides the floor points under it: its centre is unchanged.
    h, w = changed.shape
    assert not changed[h // 2 - 3 : h // 2 + 3, w // 2 - 3 : w // 2 + 3].any()
    assert mpimg.imread(tmp_path / "scan.png").shape[:2] == (SMALL["height"], SMALL["width"])
    with pytest.raises(SourceError, match="applies to a scan"):
        render("arm6", None, opts, scene=scene)


def test_transparent_geom_is_blended_over_what_is_behind() -> None:
    def picture(alpha: float) -> np.ndarray:
        model = mujoco.MjModel.from_xml_string(
            f"""<mujoco><worldbody><light pos="0 0 3" dir="0 0 -1"/>
            <geom type="box" size="0.3 0.3 0.3" rgba="0.9 0.1 0.1 1"/>
            <geom type="box" pos="0.6 0 0" size="0.02 0.6 0.6" rgba="0.1 0.1 0.9 {alpha}"/>
            </worldbody></mujoco>"""
        )
        opts = RenderOptions(camera="front", backend="software", **SMALL)
        return render_model(model, None, opts).image.astype(int)

    h, w = SMALL["height"], SMALL["width"]
    centre = (slice(h // 2 - 3, h // 2 + 3), slice(w // 2 - 3, w // 2 + 3))
    solid, glass = picture(1.0)[centre].mean((0, 1)), picture(0.4)[centre].mean((0, 1))
    assert solid[2] > 2 * solid[0]  # an opaque blue pane hides the red box
    assert glass[0] > 1.5 * solid[0] and glass[2] > 30  # through glass: red and blue
