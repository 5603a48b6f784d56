"""The page as a person sees it: headless Chromium loads the viewer, and the robot is
drawn where it stands (pixels differ from the empty scene inside the robot's projected
outline, and nowhere else in the 3D view).

Chromium is Debian's ``chromium`` (installed by ``tools/fetch_test_data.py`` where it
can be); without it the test skips with the reason. The page is drawn with software
WebGL (SwiftShader) and the viewer's ``plain`` lighting, which software WebGL draws in
seconds.
"""

from __future__ import annotations

import mujoco
import numpy as np
import pytest

from robotwright.scene.geometry import geom_shapes
from robotwright.view import ViewerConfig, load_source
from robotwright.view.server import Viewer

from .browser import Browser, find_chromium

WIDTH, HEIGHT = 960, 640
#: Parts of the window that are not the 3D view: viser's control panel (right), its
#: notice about software WebGL (top left) and the orientation gizmo (bottom left) [px].
MASKED = ((620, 0, WIDTH, HEIGHT), (0, 0, 330, 170), (0, HEIGHT - 90, 90, HEIGHT))

pytestmark = pytest.mark.filterwarnings("ignore::robotwright.errors.ConversionWarning")


@pytest.fixture(scope="module")
def chromium() -> str:
    path = find_chromium()
    if path is None:
        pytest.skip(
            "no Chromium: install Debian's 'chromium' package (apt-get install chromium; "
            ".ci/run does for CI) or set $CHROMIUM to a Chromium executable"
        )
    return path


def _project(viewer: Viewer, points: np.ndarray) -> np.ndarray:
    """Pixel coordinates of world points [m] through the page's initial camera (three.js
    perspective camera: vertical field of view, +z up)."""
    cam = viewer.server.initial_camera
    eye, target = np.asarray(cam.position), np.asarray(cam.look_at)
    forward = (target - eye) / np.linalg.norm(target - eye)
    right = np.cross(forward, [0.0, 0.0, 1.0])
    right /= np.linalg.norm(right)
    up = np.cross(right, forward)
    d = points - eye
    depth = d @ forward
    f = 1.0 / np.tan(cam.fov / 2.0)
    ndc_x = (d @ right) * f / (depth * WIDTH / HEIGHT)
    ndc_y = (d @ up) * f / depth
    return np.stack([(ndc_x + 1) / 2 * WIDTH, (1 - ndc_y) / 2 * HEIGHT], axis=1)


def _robot_outline(viewer: Viewer) -> tuple[int, int, int, int]:
    """Pixel box around every vertex of the robot's drawn geoms at the shown pose."""
    model, data = viewer.model, viewer.data
    mujoco.mj_kinematics(model, data)
    points = []
    for s in geom_shapes(model):
        if s.group in viewer.config.geom_groups and s.body_id > 0:  # not the floor
            mat = data.geom_xmat[s.geom_id].reshape(3, 3)
            points.append(s.vertices @ mat.T + data.geom_xpos[s.geom_id])
    px = _project(viewer, np.concatenate(points))
    lo, hi = np.floor(px.min(axis=0)).astype(int), np.ceil(px.max(axis=0)).astype(int)
    return int(lo[0]), int(lo[1]), int(hi[0]), int(hi[1])


def _view_mask() -> np.ndarray:
    mask = np.ones((HEIGHT, WIDTH), bool)
    for x0, y0, x1, y1 in MASKED:
        mask[y0:y1, x0:x1] = False
    return mask


def _changed(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    return np.abs(a.astype(int) - b.astype(int)).sum(axis=-1) > 40


def test_robot_is_drawn_where_it_stands(chromium: str) -> None:
    scene = load_source("mini_humanoid")
    with (
        Viewer(scene, ViewerConfig(port=0, plain=True)) as viewer,
        Browser(chromium, WIDTH, HEIGHT) as browser,
    ):
        x0, y0, x1, y1 = _robot_outline(viewer)
        assert 0 <= x0 < x1 <= MASKED[0][0] and 0 <= y0 < y1 <= HEIGHT, "robot outside the view"
        inside = np.zeros((HEIGHT, WIDTH), bool)
        inside[y0:y1, x0:x1] = True
        browser.goto(viewer.url)
        # Software WebGL takes seconds for the first frame: wait for something drawn
        # in the robot's box, then for the page to settle.
        full = browser.steady_screenshot(
            until=lambda s: (s[inside] < 200).any(axis=-1).mean() > 0.1
        )
        robot = [node for g, node in viewer._geom_nodes.items() if viewer.model.geom_bodyid[g]]
        for node in robot:  # hide the robot, keep the floor: the empty scene, same camera
            node.visible = False
        empty = browser.steady_screenshot(until=lambda s: _changed(s, full)[inside].any())
        for node in robot:
            node.visible = True
        again = browser.steady_screenshot(until=lambda s: _changed(s, empty)[inside].any())
        # the page's own requests and messages all pass the server's Host/Origin and
        # message checks
        assert not viewer.refused, list(viewer.refused)
    changed = _changed(full, empty)
    view = _view_mask()
    grown = np.zeros_like(inside)  # a few pixels of anti-aliasing around the outline
    grown[max(y0 - 4, 0) : y1 + 4, max(x0 - 4, 0) : x1 + 4] = True
    # The robot covers a good part of its box, nothing changed outside it, and showing
    # it again draws it the same (the meshes were kept, only made visible).
    assert changed[inside & view].mean() > 0.2
    assert changed[view & ~grown].sum() == 0
    assert _changed(again, full)[view].mean() < 0.002


def test_scan_points_are_drawn_in_their_class_colours(chromium: str, tmp_path) -> None:
    """A scan shown alone: its points appear inside their projected outline, in the
    colours of their classes (terrain brown, valuable blue)."""
    from robotwright.sensors import scan_to_files
    from robotwright.view.drawing import class_color

    room = tmp_path / "room.xml"
    room.write_text(
        '<mujoco><worldbody><geom name="floor" type="plane" size="3 3 0.1"/>'
        '<body name="sofa" pos="1.5 0 0.4"><geom type="box" size="0.4 0.8 0.4"/></body>'
        '<body name="s" pos="0 0 0.6"><site name="lidar"/></body></worldbody></mujoco>',
        encoding="utf-8",
    )
    model = mujoco.MjModel.from_xml_path(str(room))
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    npz = tmp_path / "scan.npz"
    scan_to_files(model, data, "lidar", "vlp16", npz, max_distance=4.0, exclude_robot=False)
    scene = load_source(npz)
    with (
        Viewer(scene, ViewerConfig(port=0, plain=True, point_size=0.06)) as viewer,
        Browser(chromium, WIDTH, HEIGHT) as browser,
    ):
        px = _project(viewer, scene.scan.points)
        x0, y0 = np.floor(px.min(axis=0)).astype(int)
        x1, y1 = np.ceil(px.max(axis=0)).astype(int)
        inside = np.zeros((HEIGHT, WIDTH), bool)
        inside[max(y0, 0) : y1, max(x0, 0) : x1] = True
        inside &= _view_mask()
        browser.goto(viewer.url)
        full = browser.steady_screenshot(
            until=lambda s: (s[inside] < 200).any(axis=-1).mean() > 0.02
        )
        viewer._scan_node.visible = False
        empty = browser.steady_screenshot(until=lambda s: _changed(s, full)[inside].any())
    changed = _changed(full, empty) & _view_mask()
    grown = np.zeros_like(inside)
    grown[max(y0 - 8, 0) : y1 + 8, max(x0 - 8, 0) : x1 + 8] = True
    assert changed.sum() > 500 and changed[~grown].sum() == 0
    drawn = full[changed].astype(int)
    for name in ("terrain", "valuable"):
        colour = np.array(class_color(scene.scan.class_names.index(name)))
        near = np.abs(drawn - colour).sum(axis=1) < 90  # shading varies the tone a little
        assert near.sum() > 50, f"no {name} points drawn in {tuple(colour)}"
