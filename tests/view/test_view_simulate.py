"""The viewer's simulate mode: stepping is MuJoCo's ``mj_step``, an actuator slider's
message drives ``ctrl`` as physics says, contacts are ``mj_contactForce`` in the world
frame, the thread plays and stops, the camera is fitted to the robots of a scene.

Nothing asserts a time: a played simulation is waited for by polling its clock (with a
generous deadline that only stops a hung test).
"""

from __future__ import annotations

import socket
import time
from collections.abc import Iterator

import msgspec
import mujoco
import numpy as np
import pytest
import viser
from websockets.sync.client import ClientConnection, connect

from robotwright.view import Viewer, ViewError, show
from robotwright.view.drawing import robot_bodies
from robotwright.view.simulate import contacts

DEADLINE = 60.0
PROTOCOL = f"viser-v{viser.__version__}"

XML = """<mujoco><compiler angle="radian"/><option timestep="0.005"/><worldbody>
  <geom name="floor" type="plane" size="2 2 0.1"/>
  <body name="box" pos="0 0 0.3"><freejoint/><geom type="box" size="0.1 0.1 0.1" mass="1"/></body>
  <body name="arm" pos="0.5 0 0.5"><joint name="hinge" axis="0 1 0" range="-1 1"/>
    <geom type="capsule" fromto="0 0 0 0.3 0 0" size="0.03"/></body>
</worldbody>
<actuator><motor name="m" joint="hinge" ctrlrange="-2 2"/>
  <motor name="free_motor" joint="hinge" ctrllimited="false"/></actuator></mujoco>"""


def _model() -> mujoco.MjModel:
    return mujoco.MjModel.from_xml_string(XML)


def _rollout(model: mujoco.MjModel, steps: int, ctrl: np.ndarray) -> mujoco.MjData:
    data = mujoco.MjData(model)
    data.ctrl[:] = ctrl
    for _ in range(steps):
        mujoco.mj_step(model, data)
    return data


@pytest.fixture
def viewer() -> Iterator[Viewer]:
    with show(_model(), port=0) as v:
        yield v


def test_step_advances_time_as_mj_step(viewer: Viewer) -> None:
    assert viewer.sim_time == 0.0 and not viewer.simulation.playing
    viewer.step(37)
    direct = _rollout(viewer.model, 37, np.zeros(viewer.model.nu))
    assert viewer.sim_time == direct.time
    np.testing.assert_array_equal(viewer.data.qpos, direct.qpos)
    # the page shows the stepped poses
    b = viewer.model.body("box").id
    np.testing.assert_array_equal(viewer._body_nodes[b].position, viewer.data.xpos[b])


def _ws(port: int) -> ClientConnection:
    return connect(
        f"ws://localhost:{port}",
        sock=socket.create_connection(("127.0.0.1", port), timeout=DEADLINE),
        origin=f"http://localhost:{port}",  # type: ignore[arg-type]
        subprotocols=[PROTOCOL],  # type: ignore[list-item]
        open_timeout=DEADLINE,
        max_size=None,
        max_queue=None,
    )


CAMERA = {
    "type": "ViewerCameraMessage",
    **{"wxyz": [1.0, 0.0, 0.0, 0.0], "position": [0.0, 0.0, 1.0], "fov": 1.0},
    **{"near": 0.01, "far": 100.0, "image_height": 480, "image_width": 640},
    **{"look_at": [0.0, 0.0, 0.0], "up_direction": [0.0, 0.0, 1.0]},
}


def _until(condition: object) -> bool:
    end = time.monotonic() + DEADLINE
    while time.monotonic() < end:
        if condition():  # type: ignore[operator]
            return True
        time.sleep(0.01)
    return False


def _update(uuid: object, value: object) -> bytes:
    return msgspec.msgpack.encode(
        {"type": "GuiUpdateMessage", "uuid": uuid, "updates": {"value": value}}
    )


def test_actuator_slider_message_drives_ctrl_as_physics_says(viewer: Viewer) -> None:
    port = viewer.server.get_port()
    with _ws(port) as ws:
        ws.send(msgspec.msgpack.encode(CAMERA))
        assert _until(lambda: len(viewer.server.get_clients()) == 1)
        uuid = viewer._ctrl_sliders[0]._impl.uuid
        ws.send(_update(uuid, 1.5))
        assert _until(lambda: viewer.data.ctrl[0] == 1.5)
    viewer.step(120)
    direct = _rollout(viewer.model, 120, np.array([1.5, 0.0]))
    np.testing.assert_array_equal(viewer.data.qpos, direct.qpos)
    hinge = viewer.model.jnt_qposadr[viewer.model.joint("hinge").id]
    assert viewer.data.qpos[hinge] != _rollout(viewer.model, 120, np.zeros(2)).qpos[hinge]


def test_contacts_are_mj_contact_force_in_the_world_frame(viewer: Viewer) -> None:
    viewer.set_joint("hinge", 0.0)
    viewer.step(200)  # the box has landed
    found = viewer.contacts()
    data = _rollout(viewer.model, 200, np.zeros(2))
    assert data.ncon == len(found.pos) >= 1
    for i in range(data.ncon):
        wrench = np.zeros(6)
        mujoco.mj_contactForce(viewer.model, data, i, wrench)
        frame = data.contact[i].frame.reshape(3, 3)
        np.testing.assert_allclose(found.force[i], wrench[:3] @ frame, atol=1e-12)
        np.testing.assert_array_equal(found.pos[i], data.contact[i].pos)
    # at rest the floor carries the box's weight
    box = viewer.model.body("box").id
    weight = viewer.model.body_subtreemass[box] * 9.81
    assert found.force[:, 2].sum() == pytest.approx(weight, rel=1e-3)
    # what the page draws: a point and an arrow from it along the force
    arrows = viewer._contact_nodes[1]
    scale = viewer._force_scale()
    np.testing.assert_allclose(arrows.points[:, 0], found.pos, rtol=1e-6, atol=1e-6)
    np.testing.assert_allclose(
        arrows.points[:, 1], found.pos + found.force * scale, rtol=1e-5, atol=1e-5
    )
    assert contacts(viewer.model, viewer.data).geom1.tolist() == found.geom1.tolist()


def test_play_runs_the_thread_and_pause_and_stop_end_it() -> None:
    v = show(_model(), port=0, simulate=True)
    try:
        assert v.simulation.playing
        assert _until(lambda: v.sim_time > 0.05)
        slider = v._sliders[v.model.joint("hinge").id]
        assert slider.disabled is True  # joint sliders would fight the physics
        v.pause()
        assert slider.disabled is False
        assert not v.simulation.playing
        assert v._play_button.label == "Play"
    finally:
        v.stop()
    assert v.simulation._thread is not None and not v.simulation._thread.is_alive()


def test_reset_returns_to_the_first_state(viewer: Viewer) -> None:
    viewer.set_ctrl("m", 1.0)
    viewer.step(50)
    viewer.reset()
    assert viewer.sim_time == 0.0
    np.testing.assert_array_equal(viewer.data.qpos, viewer.model.qpos0)
    np.testing.assert_array_equal(viewer.data.ctrl, 0.0)
    assert viewer._ctrl_sliders[0].value == 0.0


def test_follow_moves_the_cameras_with_the_body(viewer: Viewer) -> None:
    with _ws(viewer.server.get_port()) as ws:
        ws.send(msgspec.msgpack.encode(CAMERA))
        assert _until(lambda: len(viewer.server.get_clients()) == 1)
        client = next(iter(viewer.server.get_clients().values()))
        assert _until(lambda: np.allclose(client.camera.position, [0, 0, 1]))
        viewer.follow("box")
        start = viewer.data.xpos[viewer.model.body("box").id].copy()
        viewer.step(100)
        moved = viewer.data.xpos[viewer.model.body("box").id] - start
        np.testing.assert_allclose(client.camera.position, np.array([0, 0, 1.0]) + moved)
        np.testing.assert_allclose(client.camera.look_at, moved)
    with pytest.raises(ViewError, match="body 'nope'"):
        viewer.follow("nope")


def test_camera_is_fitted_to_the_robot_not_the_room() -> None:
    room = """<mujoco><compiler angle="radian"/><worldbody>
      <geom type="plane" size="10 10 0.1"/>
      <body name="wall" pos="9 0 1"><geom type="box" size="0.1 9 1"/></body>
      <body name="far_wall" pos="-9 0 1"><geom type="box" size="0.1 9 1"/></body>
      <body name="prop" pos="5 5 0.1"><freejoint/><geom type="box" size="0.1 0.1 0.1"/></body>
      <body name="base" pos="1 1 0.1"><geom type="box" size="0.1 0.1 0.1"/>
        <body name="link"><joint name="j" axis="0 0 1"/>
          <geom type="capsule" fromto="0 0 0.1 0 0 0.5" size="0.05"/></body></body>
    </worldbody></mujoco>"""
    model = mujoco.MjModel.from_xml_string(room)
    assert robot_bodies(model).tolist() == [model.body("base").id, model.body("link").id]
    with show(model, port=0) as v:
        look_at = np.array(v.server.initial_camera.look_at)
        distance = np.linalg.norm(np.array(v.server.initial_camera.position) - look_at)
    np.testing.assert_allclose(look_at[:2], [1.0, 1.0], atol=0.2)
    assert distance < 3.0 < float(model.stat.extent)  # the room is 18 m wide


def test_plain_lights_every_face() -> None:
    with show(_model(), port=0, plain=True) as v:
        names = set(v.server.scene._handle_from_node_name)
    assert {"/lights/sky", "/lights/ambient"} <= names
