"""The page's server side without a browser: meshes sent once per geom, sliders moving
the bodies exactly as MuJoCo's forward kinematics does, frames and geom groups toggled,
the scan's points coloured by class."""

from __future__ import annotations

from pathlib import Path

import mujoco
import numpy as np
import pytest

from robotwright.sensors.plot import CLASS_COLORS
from robotwright.view import Viewer, ViewerConfig, ViewError, load_source, show
from robotwright.view.drawing import class_color

pytestmark = pytest.mark.filterwarnings("ignore::robotwright.errors.ConversionWarning")


@pytest.fixture
def humanoid() -> Viewer:
    viewer = show("mini_humanoid", port=0)
    yield viewer
    viewer.stop()


def test_url_and_meshes_sent_once(humanoid: Viewer) -> None:
    assert humanoid.url.startswith("http://127.0.0.1:")
    assert int(humanoid.url.rsplit(":", 1)[1]) == humanoid.server.get_port() > 0
    model = humanoid.model
    visible = int(np.isin(model.geom_group, (0, 1, 2)).sum())
    assert humanoid.geom_count == visible
    nodes = dict(humanoid._geom_nodes)
    humanoid.show_groups(set())
    assert all(not n.visible for n in nodes.values())
    humanoid.show_groups({0, 1, 2})
    # shown again: the same nodes, no new mesh sent
    assert humanoid._geom_nodes == nodes and all(n.visible for n in nodes.values())


def test_sliders_move_bodies_by_forward_kinematics(humanoid: Viewer) -> None:
    model = humanoid.model
    rng = np.random.default_rng(7)
    names = humanoid.joint_names()
    assert len(names) == 20  # every hinge; the floating base has none
    for name in names:
        j = model.joint(name).id
        lo, hi = model.jnt_range[j]
        humanoid.set_joint(name, rng.uniform(lo, hi))
    reference = mujoco.MjData(model)
    reference.qpos[:] = humanoid.data.qpos
    mujoco.mj_kinematics(model, reference)
    base = mujoco.MjData(model)
    mujoco.mj_kinematics(model, base)  # at qpos0
    for b, node in enumerate(humanoid._body_nodes):
        np.testing.assert_allclose(node.position, reference.xpos[b], atol=1e-6)
        np.testing.assert_allclose(node.wxyz, reference.xquat[b], atol=1e-6)
    assert np.abs(reference.xpos - base.xpos).max() > 0.05  # the limbs did move
    humanoid.set_qpos(model.qpos0)
    np.testing.assert_allclose(
        np.array([n.position for n in humanoid._body_nodes]), base.xpos, atol=1e-6
    )
    with pytest.raises(ViewError, match="joint 'nope': no slider"):
        humanoid.set_joint("nope", 0.0)


def test_slider_ranges_are_the_model_limits(humanoid: Viewer) -> None:
    for j, slider in humanoid._sliders.items():
        assert humanoid.model.jnt_limited[j]
        np.testing.assert_allclose((slider.min, slider.max), humanoid.model.jnt_range[j])


def test_frames_toggle(tmp_path: Path) -> None:
    with show("arm6", port=0, body_frames=True) as viewer:
        assert all(n.show_axes for n in viewer._body_nodes[1:])
        assert not any(n.show_axes for n in viewer._site_nodes)
        assert len(viewer._site_nodes) == viewer.model.nsite > 0


def test_config_is_validated() -> None:
    for bad in ({"port": -1}, {"geom_groups": (6,)}, {"point_size": 0.0}, {"host": ""}):
        with pytest.raises(ViewError):
            ViewerConfig(**bad)


def _rgb(hex_color: str) -> tuple[int, int, int]:
    h = hex_color.lstrip("#")
    return (int(h[0:2], 16), int(h[2:4], 16), int(h[4:6], 16))


def test_scan_points_coloured_by_class(tmp_path: Path) -> None:
    from robotwright.sensors import scan_to_files
    from robotwright.sensors.plot import class_color as picture_color

    # the same colours as the scan pictures
    assert all(class_color(i) == _rgb(picture_color(i)) for i in range(len(CLASS_COLORS)))
    xml = tmp_path / "room.xml"
    xml.write_text(
        '<mujoco><worldbody><geom name="floor" type="plane" size="3 3 0.1"/>'
        '<body name="sofa" pos="1 0 0.3"><geom type="box" size="0.3 0.3 0.3"/></body>'
        '<body name="s" pos="0 0 0.5"><site name="lidar"/></body></worldbody></mujoco>',
        encoding="utf-8",
    )
    model = mujoco.MjModel.from_xml_path(str(xml))
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    scan_to_files(model, data, "lidar", "vlp16", tmp_path / "scan.npz", exclude_robot=False)
    scene = load_source(tmp_path / "scan.npz", scene=xml)
    with Viewer(scene, ViewerConfig(port=0)) as viewer:
        node = viewer._scan_node
        expected = np.array([class_color(int(c)) for c in scene.scan.labels], np.uint8)
        np.testing.assert_array_equal(node.colors, expected)
        assert len(node.points) == len(scene.scan.points)
        legend = viewer._legend_html()
        for name, count in scene.scan.class_counts().items():
            assert f"{name} ({count} points)" in legend
        assert scene.scan.class_counts()["valuable"] > 0


@pytest.mark.realdata
def test_unitree_g1_sends_meshes_once_then_poses_only(testdata_dir: Path) -> None:
    """The G1's 35 visual meshes go to the page once; a slider then sends only the poses
    of the bodies that moved (no mesh), so the page does not freeze."""
    path = testdata_dir / "mjlab/mjlab/asset_zoo/robots/unitree_g1/xmls/g1.xml"
    if not path.is_file():
        pytest.skip(f"mjlab G1 absent: {path} (run tools/fetch_test_data.py)")
    with show(path, port=0) as viewer:
        model = viewer.model
        visual = int(np.isin(model.geom_group, (0, 1, 2)).sum())
        assert viewer.geom_count == visual == 35
        sent: list[str] = []
        ws = viewer.server._websock_server
        queue = ws.queue_message
        ws.queue_message = lambda msg: (sent.append(type(msg).__name__), queue(msg))[1]
        try:
            viewer.set_joint("left_knee_joint", 1.0)
        finally:
            ws.queue_message = queue
        assert "MeshMessage" not in sent
        assert set(sent) <= {"SetPositionMessage", "SetOrientationMessage", "GuiUpdateMessage"}
        below_knee = [b for b in range(model.nbody) if _is_below(model, b, "left_knee_link")]
        # the knee link turns about its origin, the ankle links also move: one orientation
        # each, positions only where they changed
        assert sent.count("SetOrientationMessage") == len(below_knee) == 3
        assert sent.count("SetPositionMessage") == 2
        assert viewer.geom_count == visual


def _is_below(model: mujoco.MjModel, body: int, name: str) -> bool:
    top = model.body(name).id
    while body > 0:
        if body == top:
            return True
        body = model.body_parentid[body]
    return False


def test_collision_only_robot_is_still_shown(tmp_path: Path) -> None:
    """A robot whose geoms are all in collision group 3 (as a URDF with collision
    elements only may be read): the page shows that group rather than an empty floor,
    and says so; groups asked for explicitly are kept."""
    xml = tmp_path / "robot.xml"
    xml.write_text(
        '<mujoco><worldbody><geom name="floor" type="plane" size="1 1 0.1"/>'
        '<body name="link" pos="0 0 0.5"><joint name="j"/>'
        '<geom type="capsule" size="0.05 0.2" group="3"/>'
        '<geom type="box" size="0.1 0.1 0.1" pos="0 0 0.3" group="3"/></body>'
        "</worldbody></mujoco>",
        encoding="utf-8",
    )
    with show(xml, port=0) as viewer:
        assert set(viewer._geom_nodes) == {0, 1, 2}
        assert any("showing groups [3]" in n for n in viewer.notes)
    with show(xml, port=0, geom_groups=(0,)) as viewer:
        assert set(viewer._geom_nodes) == {0} and not viewer.notes


def test_keyframe_menu_and_reset(tmp_path: Path) -> None:
    model = mujoco.MjModel.from_xml_string(
        '<mujoco><worldbody><body name="b"><joint name="j" axis="0 1 0"/>'
        '<geom type="capsule" fromto="0 0 0 0 0 -1" size="0.05"/>'
        '<body name="tip" pos="0 0 -1"/></body></worldbody>'
        '<keyframe><key name="up" qpos="0.7"/><key qpos="-0.3"/></keyframe></mujoco>'
    )
    tip = model.body("tip").id
    with show(model, port=0) as viewer:
        assert viewer._sliders[0].value == pytest.approx(0.7)  # keyframe 0 first
        viewer._keyframe_menu.value = "1: key 1"  # as a person picks it
        assert viewer.data.qpos[0] == pytest.approx(-0.3)
        assert viewer._sliders[0].value == pytest.approx(-0.3)
        np.testing.assert_allclose(
            viewer._body_nodes[tip].position, [np.sin(-0.3) * -1, 0, -np.cos(-0.3)], atol=1e-9
        )
        viewer._sliders[0].value = 0.2  # a slider drag
        assert viewer.data.qpos[0] == pytest.approx(0.2)
        np.testing.assert_allclose(
            viewer._body_nodes[tip].position, [-np.sin(0.2), 0, -np.cos(0.2)], atol=1e-9
        )
