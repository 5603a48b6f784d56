"""Hostile input to the viewer's simulate controls: control messages a page might send
to the actuator sliders, the play/step/reset buttons, the follow menu and the contacts
checkbox, a joint slider moved while the physics runs (disabled), and bad values given
to ``set_ctrl``/``step`` from Python. Each is refused with ``ctrl``/``qpos`` unchanged.

Nothing waits a fixed time: a refused message is waited for through the viewer's
refusal count (a generous deadline only stops a hung test).
"""

from __future__ import annotations

import random
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

DEADLINE = 60.0
PROTOCOL = f"viser-v{viser.__version__}"

XML = """<mujoco><compiler angle="radian"/><worldbody>
  <geom type="plane" size="1 1 0.1"/>
  <body name="arm" pos="0 0 0.5"><joint name="hinge" axis="0 1 0" range="-1 1"/>
    <geom type="capsule" fromto="0 0 0 0.3 0 0" size="0.03"/></body>
</worldbody>
<actuator><motor name="m" joint="hinge" ctrlrange="-2 2"/>
  <position name="servo" joint="hinge" kp="5" ctrlrange="-0.5 0.5"/>
  <motor name="unlimited" joint="hinge" ctrllimited="false"/></actuator></mujoco>"""

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


@pytest.fixture
def page() -> Iterator[tuple[Viewer, ClientConnection]]:
    with show(mujoco.MjModel.from_xml_string(XML), port=0) as v:
        port = v.server.get_port()
        with connect(
            f"ws://localhost:{port}",
            sock=socket.create_connection(("127.0.0.1", port), timeout=DEADLINE),
            origin=f"http://localhost:{port}",  # type: ignore[arg-type]
            subprotocols=[PROTOCOL],  # type: ignore[list-item]
            open_timeout=DEADLINE,
            max_size=None,
            max_queue=None,
        ) as ws:
            ws.send(msgspec.msgpack.encode(CAMERA))
            assert _until(lambda: len(v.server.get_clients()) == 1)
            yield v, ws


def _update(uuid: object, updates: object) -> bytes:
    return msgspec.msgpack.encode({"type": "GuiUpdateMessage", "uuid": uuid, "updates": updates})


def _bad_values(lo: float, hi: float, seed: int) -> list[object]:
    values: list[object] = [
        float("nan"),
        float("inf"),
        float("-inf"),
        hi + 1e-9,
        lo - 1e-9,
        hi + 1.0,
        1e308,
        -1e308,
        "1.0",
        None,
        True,
        False,
        [0.1],
        {"v": 0.1},
        b"\x01",
        2**64 - 1,
    ]
    rng = random.Random(seed)
    values += [rng.uniform(hi + 1e-6, 1e9) for _ in range(10)]
    values += [rng.uniform(-1e9, lo - 1e-6) for _ in range(10)]
    return values


def _send_refused(viewer: Viewer, ws: ClientConnection, frame: bytes, what: str) -> None:
    before = viewer.refused_count
    ctrl, qpos = viewer.data.ctrl.copy(), viewer.data.qpos.copy()
    ws.send(frame)
    assert viewer.wait_for_refusals(before + 1, DEADLINE), what
    np.testing.assert_array_equal(viewer.data.ctrl, ctrl, err_msg=what)
    np.testing.assert_array_equal(viewer.data.qpos, qpos, err_msg=what)


@pytest.mark.parametrize(("actuator", "seed"), [("m", 1), ("servo", 2), ("unlimited", 3)])
def test_bad_actuator_slider_messages_are_refused(
    page: tuple[Viewer, ClientConnection], actuator: str, seed: int
) -> None:
    viewer, ws = page
    i = viewer.model.actuator(actuator).id
    slider = viewer._ctrl_sliders[i]
    values = _bad_values(float(slider.min), float(slider.max), seed)
    for value in values:
        _send_refused(viewer, ws, _update(slider._impl.uuid, {"value": value}), repr(value))
    for updates in ({"min": -100.0}, {"value": 0.1, "max": 100.0}, {}, [0.1]):
        _send_refused(viewer, ws, _update(slider._impl.uuid, updates), repr(updates))
    assert any(f"actuator '{actuator}'" in r for r in viewer.refused)
    assert slider.value == 0.0
    # the same page still sets the control with a good value
    ws.send(_update(slider._impl.uuid, {"value": float(slider.max) / 2}))
    assert _until(lambda: viewer.data.ctrl[i] == float(slider.max) / 2)


def test_simulation_controls_refuse_values_of_another_kind(
    page: tuple[Viewer, ClientConnection],
) -> None:
    viewer, ws = page
    menu, box = viewer._follow_menu, viewer._contacts_box
    frames = [
        (menu, "arm/../world"),
        (menu, "no such body"),
        (menu, 1),
        (menu, None),
        (box, 1),
        (box, "true"),
        (box, None),
        (viewer._play_button, "yes"),
        (viewer._play_button, 1.0),
        (viewer._play_button, None),
    ]
    rng = random.Random(9)
    frames += [(menu, "".join(rng.choices("abcxyz/_. ", k=rng.randint(1, 30)))) for _ in range(10)]
    for handle, value in frames:
        _send_refused(viewer, ws, _update(handle._impl.uuid, {"value": value}), repr(value))
    assert menu.value == "(none)" and box.value is True and not viewer.simulation.playing
    assert viewer._follow is None


def test_joint_slider_is_refused_while_the_physics_runs(
    page: tuple[Viewer, ClientConnection],
) -> None:
    viewer, ws = page
    j = viewer.model.joint("hinge").id
    uuid = viewer._sliders[j]._impl.uuid
    viewer.play()
    try:
        before = viewer.refused_count
        ws.send(_update(uuid, {"value": 0.5}))
        assert viewer.wait_for_refusals(before + 1, DEADLINE)
        assert "disabled" in viewer.refused[-1]
    finally:
        viewer.pause()
    ws.send(_update(uuid, {"value": 0.5}))  # paused: the slider sets the pose again
    assert _until(lambda: viewer.data.qpos[viewer.model.jnt_qposadr[j]] == 0.5)


@pytest.mark.parametrize(
    ("actuator", "value", "match"),
    [
        ("m", float("nan"), "actuator 'm': expected a finite number"),
        ("m", float("inf"), "finite"),
        ("m", 2.0 + 1e-9, r"outside the actuator's ctrlrange \[-2, 2\]"),
        ("m", -1e300, "outside"),
        ("servo", 0.6, r"ctrlrange \[-0.5, 0.5\]"),
        ("servo", "0.1", "expected a number"),
        ("servo", None, "expected a number"),
        ("servo", True, "expected a number"),
        ("servo", [0.1], "expected a number"),
        ("unlimited", float("-inf"), "finite"),
        ("nope", 0.0, "actuator 'nope': no such actuator"),
        (7, 0.0, "no such actuator"),
        (-1, 0.0, "no such actuator"),
        (None, 0.0, "no such actuator"),
        (True, 0.0, "no such actuator"),
    ],
)
def test_set_ctrl_refuses_bad_values(actuator: object, value: object, match: str) -> None:
    with show(mujoco.MjModel.from_xml_string(XML), port=0) as v:
        with pytest.raises(ViewError, match=match):
            v.set_ctrl(actuator, value)  # type: ignore[arg-type]
        np.testing.assert_array_equal(v.data.ctrl, 0.0)
        v.set_ctrl("unlimited", 1e6)  # no ctrlrange: any finite value
        v.set_ctrl(1, np.float32(0.5))
        assert v.data.ctrl.tolist() == [0.0, 0.5, 1e6]


@pytest.mark.parametrize("n", [-1, 1.5, "3", None, True])
def test_step_refuses_bad_counts(n: object) -> None:
    with show(mujoco.MjModel.from_xml_string(XML), port=0) as v:
        with pytest.raises(ValueError, match="steps"):
            v.step(n)  # type: ignore[arg-type]
        assert v.sim_time == 0.0


def test_an_unstable_model_pauses_with_a_note() -> None:
    xml = XML.replace('kp="5"', 'kp="1e12"').replace(
        "<worldbody>", '<option timestep="0.1"/><worldbody>'
    )
    with show(mujoco.MjModel.from_xml_string(xml), port=0) as v:
        v.set_ctrl("servo", 0.5)
        v.step(200)
        assert v.simulation.unstable is not None and "unstable" in v.simulation.unstable
        assert np.isfinite(v.data.qpos).all()
