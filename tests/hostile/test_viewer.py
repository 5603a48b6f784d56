"""Hostile input to the viewer's server: requests from other sites (DNS rebinding Host
headers, websocket handshakes from foreign origins), bad control messages from a page,
bad joint values from Python, and hosts the server cannot listen on.

The server runs in the test (port 0). Nothing waits a fixed time: an HTTP answer is
read to the end, a refused page message is waited for through the viewer's refusal
count, and an accepted one by polling the joint it moves (with a generous deadline that
only stops a hung test).
"""

from __future__ import annotations

import os
import random
import signal
import socket
import string
import subprocess
import sys
import time
from collections.abc import Iterator

import msgspec
import mujoco
import numpy as np
import pytest
import viser
import websockets.exceptions
import zstandard
from websockets.sync.client import ClientConnection, connect

from robotwright.view import Viewer, ViewError, show
from robotwright.view.gate import MAX_DEPTH, MAX_FRAME_BYTES, bind_listener

DEADLINE = 60.0  # seconds; only ends a hung test, never asserted
PROTOCOL = f"viser-v{viser.__version__}"

MODEL_XML = """
<mujoco><compiler angle="radian"/><worldbody>
  <body name="upper"><joint name="shoulder" range="-1 1.5"/>
    <geom type="capsule" fromto="0 0 0 0 0 -0.5" size="0.05"/>
    <body name="slider_body" pos="0 0 -0.5"><joint name="reach" type="slide" range="0 0.2"/>
      <geom type="box" size="0.05 0.05 0.05"/>
      <body name="spin" pos="0 0 -0.2"><joint name="free_spin" limited="false"/>
        <geom type="sphere" size="0.04"/></body></body></body>
</worldbody>
<keyframe><key name="bad" qpos="0 0.1 0"/></keyframe>
</mujoco>
"""


def _model() -> mujoco.MjModel:
    return mujoco.MjModel.from_xml_string(MODEL_XML)


@pytest.fixture(scope="module")
def viewer() -> Iterator[Viewer]:
    with show(_model(), port=0) as v:
        yield v


# -- raw HTTP -----------------------------------------------------------------------------
def _http(port: int, head: bytes) -> tuple[int, bytes]:
    """Send a request head to the server; (status code, whole answer)."""
    with socket.create_connection(("127.0.0.1", port), timeout=DEADLINE) as sock:
        sock.sendall(head)
        data = b""
        while chunk := sock.recv(65536):
            data += chunk
    status = data.split(b"\r\n", 1)[0].split(b" ")
    return int(status[1]), data


def _get(port: int, host_lines: list[str], extra: str = "") -> tuple[int, bytes]:
    hosts = "".join(f"Host: {h}\r\n" for h in host_lines)
    return _http(port, f"GET / HTTP/1.1\r\n{hosts}{extra}Connection: close\r\n\r\n".encode())


def _refused_hosts(port: int) -> list[list[str]]:
    other = port + 1 if port < 65535 else port - 1
    fixed = [
        ["evil.com"],
        [f"evil.com:{port}"],
        [f"EVIL.COM:{port}"],
        [f"localhost.evil.com:{port}"],
        [f"LOCALHOST.EVIL.COM:{port}"],
        [f"127.0.0.1.nip.io:{port}"],
        [f"localtest.me:{port}"],
        [f"x.localhost:{port}"],
        [f"localhost.:{port}"],
        [f"localhost:{other}"],
        [f"127.0.0.1:{other}"],
        [f"[::1]:{other}"],
        ["localhost"],
        ["127.0.0.1"],
        ["[::1]"],
        [f"::1:{port}"],
        [f"[::2]:{port}"],
        [f"[::ffff:127.0.0.1]:{port}"],
        [f"[0:0:0:0:0:0:0:1]:{port}"],
        [f"127.1:{port}"],
        [f"2130706433:{port}"],
        [f"0x7f000001:{port}"],
        [f"0.0.0.0:{port}"],
        [f"localhost:{port}@evil.com"],
        [f"evil.com#@localhost:{port}"],
        [f"localhost:{port}:80"],
        [f"localhost :{port}"],
        [f"localhost:{port}/x"],
        [f"localhost:+{port}"],
        [f"localhost:0{port}"],  # a leading zero: another parser may read it otherwise
        [f"127.0.0.1:00{port}"],
        [f"localhost:{port}99999"],
        ["localhost:"],
        [""],
        [],  # no Host header
        [f"localhost:{port}", f"localhost:{port}"],  # two
        [f"localhost:{port}", f"evil.com:{port}"],
        [f"evil.com:{port}", f"localhost:{port}"],
    ]
    rng = random.Random(19)
    tlds = ["com", "net", "io", "test", "lan", "local"]
    for _ in range(30):
        label = "".join(rng.choices(string.ascii_letters + string.digits, k=rng.randint(1, 20)))
        name = f"{label}.{rng.choice(tlds)}"
        if rng.random() < 0.5:
            name = f"{name}:{port}"
        fixed.append([name])
    return fixed


def test_http_requests_for_other_hosts_are_refused(viewer: Viewer) -> None:
    """DNS rebinding: a page whose name now points at 127.0.0.1 sends its own name as
    Host; every Host that is not this server (name and port) gets 403 and no page."""
    port = viewer.server.get_port()
    cases = _refused_hosts(port)
    before = viewer.refused_count
    for hosts in cases:
        status, answer = _get(port, hosts)
        assert status in (400, 403), (hosts, status)
        assert b"<html" not in answer.lower() and b"<script" not in answer.lower(), hosts
    # each reached the gate (none was answered by viser before it)
    assert viewer.refused_count - before >= len(cases) - 1


@pytest.mark.parametrize(
    "host",
    [
        "localhost:{port}",
        "127.0.0.1:{port}",
        "[::1]:{port}",
        "LOCALHOST:{port}",
        "LocalHost:{port}",
    ],
)
def test_http_requests_for_this_server_are_answered(viewer: Viewer, host: str) -> None:
    status, answer = _get(viewer.server.get_port(), [host.format(port=viewer.server.get_port())])
    assert status == 200 and b"<html" in answer.lower()


# -- websocket handshakes -----------------------------------------------------------------
def _ws(port: int, origin: str | None, host: str) -> ClientConnection:
    """A websocket handshake to the server with ``Host: host`` (the URI's authority;
    the socket goes to 127.0.0.1 whatever the name)."""
    return connect(
        f"ws://{host}",
        sock=socket.create_connection(("127.0.0.1", port), timeout=DEADLINE),
        origin=origin,  # type: ignore[arg-type]
        subprotocols=[PROTOCOL],  # type: ignore[list-item]
        open_timeout=DEADLINE,
        max_size=None,
        max_queue=None,
    )


def _refused_origins(port: int) -> list[str | None]:
    other = port + 1 if port < 65535 else port - 1
    fixed: list[str | None] = [
        None,
        "null",
        "",
        "http://evil.com",
        f"http://evil.com:{port}",
        f"http://localhost.evil.com:{port}",
        f"http://127.0.0.1.nip.io:{port}",
        f"http://localhost:{other}",
        f"http://127.0.0.1:{other}",
        f"https://localhost:{port}",
        f"https://127.0.0.1:{port}",
        "http://localhost",
        f"ws://localhost:{port}",
        f"file://localhost:{port}",
        "file://",
        "chrome-extension://abcdefghijklmnop",
        f"http://localhost:{port}/page",
        f"http://localhost:{port}?x",
        f"http://user@localhost:{port}",
        f"http://[::2]:{port}",
        f"http://[::ffff:127.0.0.1]:{port}",
        f"http://localhost.:{port}",
        f"http://0.0.0.0:{port}",
        "*",
    ]
    rng = random.Random(5)
    for _ in range(20):
        label = "".join(rng.choices(string.ascii_lowercase + string.digits, k=rng.randint(1, 15)))
        scheme = rng.choice(["http", "https"])
        fixed.append(f"{scheme}://{label}.example:{rng.choice([port, 80, 443, other])}")
    return fixed


def test_websocket_from_other_origins_is_refused(viewer: Viewer) -> None:
    """A browser lets any page open a websocket to 127.0.0.1 and sends that page's
    origin: only the viewer's own page (http, this host name, this port) connects."""
    port = viewer.server.get_port()
    clients = len(viewer.server.get_clients())
    for origin in _refused_origins(port):
        with pytest.raises(websockets.exceptions.InvalidStatus) as caught:
            _ws(port, origin, host=f"localhost:{port}").close()
        response = caught.value.response
        assert response.status_code == 403 and b"Origin" in response.body, origin
    assert len(viewer.server.get_clients()) == clients


def test_websocket_with_two_origins_or_a_foreign_host_is_refused(viewer: Viewer) -> None:
    port = viewer.server.get_port()
    key = "dGhlIHNhbXBsZSBub25jZQ=="
    upgrade = (
        "Upgrade: websocket\r\nConnection: Upgrade\r\nSec-WebSocket-Version: 13\r\n"
        f"Sec-WebSocket-Key: {key}\r\nSec-WebSocket-Protocol: {PROTOCOL}\r\n"
    )
    own = f"http://localhost:{port}"
    for host, origins in [
        (f"localhost:{port}", [own, own]),
        (f"localhost:{port}", [own, "http://evil.com"]),
        (f"evil.com:{port}", [own]),  # rebinding with a forged-looking origin
        (f"evil.com:{port}", [f"http://evil.com:{port}"]),
    ]:
        lines = "".join(f"Origin: {o}\r\n" for o in origins)
        head = f"GET / HTTP/1.1\r\nHost: {host}\r\n{upgrade}{lines}\r\n".encode()
        status, _ = _http(port, head)
        assert status == 403, (host, origins)


@pytest.mark.parametrize("name", ["localhost", "127.0.0.1", "[::1]", "LOCALHOST"])
def test_websocket_from_the_viewers_own_page_connects(viewer: Viewer, name: str) -> None:
    port = viewer.server.get_port()
    with _ws(port, f"http://{name}:{port}", host=f"{name.lower()}:{port}") as ws:
        assert ws.subprotocol == PROTOCOL


def test_allow_origin_lets_that_page_connect() -> None:
    with show(_model(), port=0, allowed_origins=("http://robot-pc.lan:8080",)) as v:
        port = v.server.get_port()
        with _ws(port, "http://robot-pc.lan:8080", host="robot-pc.lan:8080") as ws:
            assert ws.subprotocol == PROTOCOL
        assert _get(port, ["robot-pc.lan:8080"])[0] == 200
        for origin in ("http://robot-pc.lan:8081", "https://robot-pc.lan:8080", "http://evil.com"):
            with pytest.raises(websockets.exceptions.InvalidStatus) as caught:
                _ws(port, origin, host=f"localhost:{port}").close()
            assert caught.value.response.status_code == 403
        assert _get(port, [f"evil.com:{port}"])[0] == 403


@pytest.mark.parametrize(
    "origin",
    ["null", "*", "http://x.lan/path", "ftp://x.lan", "http://u@x.lan", "x.lan:80", "http://"],
)
def test_allow_origin_values_are_checked(origin: str) -> None:
    with pytest.raises(ViewError, match="allowed origin"):
        show(_model(), port=0, allowed_origins=(origin,))
    result = _cli("view", "arm6", "--port", "0", "--allow-origin", origin)
    assert result.returncode == 2 and "--allow-origin" in result.stderr


# -- messages from a page -----------------------------------------------------------------
def _update(uuid: object, updates: object) -> bytes:
    return msgspec.msgpack.encode({"type": "GuiUpdateMessage", "uuid": uuid, "updates": updates})


def _nested(depth: int) -> object:
    value: object = 0.1
    for _ in range(depth):
        value = [value]
    return value


def _bad_messages(uuid: str, lo: float, hi: float) -> list[tuple[str, bytes | str]]:
    """(what, frame) pairs a page might send that must not move the joint."""
    values: list[object] = [
        float("nan"),
        float("inf"),
        float("-inf"),
        hi + 1e-3,
        lo - 1e-3,
        hi + 1.0,
        1e308,
        -1e308,
        "0.1",
        None,
        True,
        False,
        [0.1],
        {"v": 0.1},
        b"\x00",
        2**64 - 1,
        _nested(MAX_DEPTH + 2),
    ]
    rng = random.Random(11)
    values += [rng.choice([1, -1]) * rng.uniform(hi + 1e-6, 1e6) for _ in range(10)]
    values += [lo - rng.uniform(1e-6, 1e6) for _ in range(10)]
    frames: list[tuple[str, bytes | str]] = [
        (f"value {v!r:.40}", _update(uuid, {"value": v})) for v in values
    ]
    frames += [
        ("min moved", _update(uuid, {"min": -100.0})),
        ("value and max", _update(uuid, {"value": 0.1, "max": 100.0})),
        ("update_cb", _update(uuid, {"update_cb": "x"})),
        ("no updates", _update(uuid, {})),
        ("updates a list", _update(uuid, [0.1])),
        ("unknown control", _update("00000000-0000-0000-0000-000000000000", {"value": 0.1})),
        ("uuid a number", _update(7, {"value": 0.1})),
        ("text frame", '{"type": "GuiUpdateMessage"}'),
        ("not msgpack", b"\xc1\xc1\xc1"),
        ("truncated array", b"\xdd\xff\xff\xff\xff"),
        ("not a map", msgspec.msgpack.encode([1, 2, 3])),
        ("no type", msgspec.msgpack.encode({"uuid": uuid})),
        ("unknown type", msgspec.msgpack.encode({"type": "EvilMessage", "x": 1})),
        ("type a number", msgspec.msgpack.encode({"type": 5})),
        ("fields missing", msgspec.msgpack.encode({"type": "GuiUpdateMessage"})),
        ("deep", b"\x91" * 100_000 + b"\x00"),
        ("deep map", b"\x81\xa1k" * 5000 + b"\x00"),
    ]
    frames += [(f"junk {i}", rng.randbytes(rng.randint(1, 200))) for i in range(15)]
    return frames


def _wait_until(condition: object) -> bool:
    end = time.monotonic() + DEADLINE
    while time.monotonic() < end:
        if condition():  # type: ignore[operator]
            return True
        time.sleep(0.01)
    return False


CAMERA = {
    "type": "ViewerCameraMessage",
    **{"wxyz": [1.0, 0.0, 0.0, 0.0], "position": [0.0, 0.0, 1.0], "fov": 1.0},
    **{"near": 0.01, "far": 100.0, "image_height": 480, "image_width": 640},
    **{"look_at": [0.0, 0.0, 0.0], "up_direction": [0.0, 0.0, 1.0]},
}


@pytest.fixture
def page() -> Iterator[tuple[Viewer, ClientConnection]]:
    with show(_model(), port=0) as v:
        port = v.server.get_port()
        with _ws(port, f"http://localhost:{port}", host=f"localhost:{port}") as ws:
            # A browser's first message is its camera: viser counts the page as a
            # client (and runs control callbacks for it) from then on.
            ws.send(msgspec.msgpack.encode(CAMERA))
            assert _wait_until(lambda: len(v.server.get_clients()) == 1)
            yield v, ws


def test_bad_slider_messages_are_refused_and_the_joint_stays(
    page: tuple[Viewer, ClientConnection],
) -> None:
    viewer, ws = page
    j = viewer.model.joint("shoulder").id
    slider = viewer._sliders[j]
    uuid = slider._impl.uuid
    lo, hi = (float(x) for x in viewer.model.jnt_range[j])
    qpos = viewer.data.qpos.copy()
    frames = _bad_messages(uuid, lo, hi)
    for what, frame in frames:
        before = viewer.refused_count
        ws.send(frame)
        assert viewer.wait_for_refusals(before + 1, DEADLINE), what
        np.testing.assert_array_equal(viewer.data.qpos, qpos, err_msg=what)
        assert slider.value == qpos[viewer.model.jnt_qposadr[j]], what
    assert any("joint 'shoulder'" in r and "finite" in r for r in viewer.refused)
    # the same connection still moves the joint with a good value
    count = viewer.refused_count
    ws.send(_update(uuid, {"value": 0.5}))
    assert _wait_until(lambda: viewer.data.qpos[viewer.model.jnt_qposadr[j]] == 0.5)
    assert viewer.refused_count == count


def test_refusal_is_told_to_the_page(page: tuple[Viewer, ClientConnection]) -> None:
    viewer, ws = page
    uuid = viewer._sliders[viewer.model.joint("reach").id]._impl.uuid
    ws.send(_update(uuid, {"value": float("nan")}))
    end = time.monotonic() + DEADLINE
    bodies: list[str] = []
    while time.monotonic() < end and not any("reach" in b for b in bodies):
        frame = ws.recv(timeout=DEADLINE)
        assert isinstance(frame, bytes)
        size, compressed = (int.from_bytes(frame[i : i + 8], "little") for i in (0, 8))
        inner = zstandard.ZstdDecompressor().decompress(
            frame[16 : 16 + compressed], max_output_size=size
        )
        for message in msgspec.msgpack.decode(inner)["messages"]:
            if message.get("type") == "NotificationShowMessage":
                bodies.append(str(message.get("props", message)))
    assert any("reach" in b and "finite" in b for b in bodies)


def test_oversized_frame_closes_the_connection_and_changes_nothing(
    page: tuple[Viewer, ClientConnection],
) -> None:
    viewer, ws = page
    uuid = viewer._sliders[viewer.model.joint("shoulder").id]._impl.uuid
    qpos = viewer.data.qpos.copy()
    pad = "x" * (MAX_FRAME_BYTES + 10)
    ws.send(_update(uuid, {"value": 0.5, "pad": pad}))
    with pytest.raises(websockets.exceptions.ConnectionClosed) as caught:
        while True:
            ws.recv(timeout=DEADLINE)
    assert caught.value.rcvd is not None and caught.value.rcvd.code == 1009
    np.testing.assert_array_equal(viewer.data.qpos, qpos)
    port = viewer.server.get_port()
    with _ws(port, f"http://localhost:{port}", host=f"localhost:{port}") as again:
        assert again.subprotocol == PROTOCOL  # the server still serves


def test_checkbox_and_menu_updates_are_checked(page: tuple[Viewer, ClientConnection]) -> None:
    viewer, ws = page
    menu = viewer._keyframe_menu
    boxes = list(viewer._group_boxes.values())
    for frame in [
        _update(menu._impl.uuid, {"value": "9: not a key"}),
        _update(menu._impl.uuid, {"value": 0}),
        _update(boxes[0]._impl.uuid, {"value": 1}),
        _update(boxes[0]._impl.uuid, {"value": "yes"}),
    ]:
        before = viewer.refused_count
        ws.send(frame)
        assert viewer.wait_for_refusals(before + 1, DEADLINE)
    assert menu.value == "0: bad" and boxes[0].value is True


# -- the Python API -----------------------------------------------------------------------
@pytest.mark.parametrize(
    ("joint", "value", "match"),
    [
        ("shoulder", float("nan"), "joint 'shoulder': expected a finite number"),
        ("shoulder", float("inf"), "finite"),
        ("shoulder", -float("inf"), "finite"),
        ("shoulder", 1.5 + 1e-9, r"outside the joint's range \[-1, 1.5\]"),
        ("shoulder", -1.01, r"outside the joint's range \[-1, 1.5\]"),
        ("shoulder", 1e300, "outside"),
        ("reach", 0.21, r"0.21 m is outside the joint's range \[0, 0.2\]"),
        ("reach", -0.0001, "outside"),
        ("reach", "0.1", "expected a number"),
        ("reach", None, "expected a number"),
        ("reach", True, "expected a number"),
        ("reach", [0.1], "expected a number"),
        ("reach", complex(0.1, 0), "expected a number"),
        ("free_spin", float("nan"), "joint 'free_spin': expected a finite number"),
        ("nope", 0.0, "joint 'nope': no slider"),
        ("", 0.0, "no slider"),
    ],
)
def test_set_joint_refuses_bad_values(
    viewer: Viewer, joint: str, value: object, match: str
) -> None:
    qpos = viewer.data.qpos.copy()
    with pytest.raises(ValueError, match=match):
        viewer.set_joint(joint, value)  # type: ignore[arg-type]
    np.testing.assert_array_equal(viewer.data.qpos, qpos)


def test_set_joint_takes_values_in_range(viewer: Viewer) -> None:
    viewer.set_joint("shoulder", 1.5)
    viewer.set_joint("reach", np.float32(0.0))
    viewer.set_joint("free_spin", 4.0)  # no limits: any finite angle
    adr = viewer.model.jnt_qposadr
    assert viewer.data.qpos[adr[viewer.model.joint("shoulder").id]] == 1.5
    assert viewer.data.qpos[adr[viewer.model.joint("free_spin").id]] == 4.0
    with pytest.raises(ViewError, match=r"qpos\[1\]: expected a finite number"):
        viewer.set_qpos(np.array([0.0, np.nan, 0.0]))


# -- listening ----------------------------------------------------------------------------
def _cli(*args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, "-m", "robotwright", *args],
        capture_output=True,
        text=True,
        timeout=300,  # a hang fails the test instead of blocking the run
        env={**os.environ, "PYTHONWARNINGS": "ignore"},
    )


def _one_error_line(stderr: str) -> str:
    errors = [line for line in stderr.splitlines() if line.startswith("error:")]
    assert len(errors) == 1 and "Traceback" not in stderr, stderr
    return errors[0]


def test_port_in_use_is_an_error() -> None:
    with socket.socket() as taken:
        taken.bind(("127.0.0.1", 0))
        taken.listen()
        port = taken.getsockname()[1]
        result = _cli("view", "arm6", "--port", str(port))
        assert result.returncode == 2
        assert f"127.0.0.1:{port}" in _one_error_line(result.stderr)
        assert "in use" in result.stderr
        assert result.stdout == ""  # no URL printed: nothing serves
        with pytest.raises(ViewError, match="in use"):
            show(_model(), port=port)


@pytest.mark.parametrize(
    ("host", "match"),
    [
        ("192.0.2.1", "not one of this machine's"),  # TEST-NET-1, never local
        ("198.51.100.7", "not one of this machine's"),
        ("no-such-host.invalid", "cannot resolve"),
        ("300.1.1.1", "cannot resolve"),
        ("bad host name", "cannot resolve"),
    ],
)
def test_host_that_cannot_be_bound_is_an_error(host: str, match: str) -> None:
    result = _cli("view", "arm6", "--host", host, "--port", "0")
    assert result.returncode == 2
    assert match in _one_error_line(result.stderr)
    with pytest.raises(ViewError, match=match):
        show(_model(), host=host, port=0)


def test_default_port_moves_on_when_taken(monkeypatch: pytest.MonkeyPatch) -> None:
    import robotwright.view.gate as gate

    with socket.socket() as taken:
        taken.bind(("127.0.0.1", 0))
        taken.listen()
        port = taken.getsockname()[1]
        monkeypatch.setattr(gate, "DEFAULT_PORT", port)
        with bind_listener("127.0.0.1", None) as sock:
            assert port < sock.getsockname()[1] < port + gate.PORT_TRIES


def test_listening_beyond_loopback_warns() -> None:
    with pytest.warns(UserWarning, match="anyone who can reach this machine"):
        v = show(_model(), host="0.0.0.0", port=0)
    with v:
        assert v.exposure is not None
    with show(_model(), port=0) as local:
        assert local.exposure is None
    proc = subprocess.Popen(
        [sys.executable, "-m", "robotwright", "view", "arm6", "--host", "0.0.0.0", "--port", "0"],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    try:
        assert proc.stdout is not None
        for line in proc.stdout:  # the URL line says the server runs
            if line.startswith("open "):
                break
        proc.send_signal(signal.SIGINT)
        _, stderr = proc.communicate(timeout=DEADLINE)
    finally:
        if proc.poll() is None:
            proc.kill()
    assert proc.returncode == 0, stderr
    assert any(
        line.startswith("warning: listening on 0.0.0.0") and "anyone" in line
        for line in stderr.splitlines()
    )


def _children() -> set[int]:
    """Process ids of this process's children (every thread's)."""
    out: set[int] = set()
    for task in os.listdir("/proc/self/task"):
        try:
            with open(f"/proc/self/task/{task}/children") as f:
                out.update(int(x) for x in f.read().split())
        except OSError:
            continue
    return out


@pytest.mark.skipif(not os.path.exists("/proc/self/task"), reason="needs Linux /proc")
@pytest.mark.parametrize(
    "message",
    [
        {"type": "ShareUrlRequest"},
        {"type": "ShareUrlDisconnect"},
        {
            "type": "FileTransferStartUpload",
            "source_component_uuid": "x",
            "transfer_uuid": "t",
            "filename": "a",
            "mime_type": "text/plain",
            "part_count": 1,
            "size_bytes": 1,
        },
        {"type": "CommandTriggerMessage", "name": "x"},
        {"type": "GuiFormSubmitMessage", "uuid": "x"},
        {"type": "NoSuchMessage"},
    ],
)
def test_messages_the_page_never_sends_are_refused(
    page: tuple[Viewer, ClientConnection], message: dict
) -> None:
    """A share-URL request made viser fork a copy that dialled its public relay; no
    message outside what the viewer's page sends reaches viser, and nothing forks."""
    viewer, ws = page
    before_children = _children()
    before = viewer.refused_count
    ws.send(msgspec.msgpack.encode(message))
    assert viewer.wait_for_refusals(before + 1, DEADLINE), message["type"]
    assert any("not a message the viewer's page sends" in r for r in viewer.refused)
    time.sleep(0.2)
    assert _children() <= before_children


def _ignore_sigint() -> None:
    signal.signal(signal.SIGINT, signal.SIG_IGN)


def _block_signals() -> None:
    signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT, signal.SIGTERM})


@pytest.mark.parametrize("inherited", [_ignore_sigint, _block_signals])
@pytest.mark.parametrize("sig", [signal.SIGINT, signal.SIGTERM])
def test_view_stops_on_signals_even_when_sigint_was_ignored(sig: signal.Signals, inherited) -> None:
    """A background job of a script starts with SIGINT ignored, and a process inherits
    its parent's blocked signals: Ctrl-C (or SIGTERM) still stops the viewer, exit 0."""
    proc = subprocess.Popen(
        [sys.executable, "-m", "robotwright", "view", "arm6", "--port", "0"],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        preexec_fn=inherited,
    )
    try:
        assert proc.stdout is not None
        for line in proc.stdout:
            if line.startswith("open "):
                break
        proc.send_signal(sig)
        _, stderr = proc.communicate(timeout=DEADLINE)
    finally:
        if proc.poll() is None:
            proc.kill()
    assert proc.returncode == 0, stderr
