"""The browser page: a viser server drawing a :class:`~robotwright.scene.load.ViewScene`.

Scene layout (viser node names): ``/bodies/b<id>`` is a frame per MuJoCo body placed at
its world pose; each geom is a mesh under its body (``/bodies/b<id>/g<id>``) at its
pose in the body frame, and each site a frame (``/bodies/b<id>/s<id>``). Meshes are
sent once, when a geom group is first shown; moving a joint slider runs
``mujoco.mj_kinematics`` and sends only the body poses that changed. A scan is one
point cloud (``/scan/points``) in the world frame, coloured by class, with a legend.
"""

from __future__ import annotations

import collections
import contextlib
import html
import io
import math
import numbers
import threading
from collections.abc import Iterator
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import mujoco
import numpy as np

from robotwright.scene.geometry import (
    DEFAULT_GEOM_GROUPS,
    GeomShape,
    body_poses,
    geom_shapes,
    site_frames,
)
from robotwright.scene.load import ViewError, ViewScene
from robotwright.sensors.plot import CLASS_COLORS
from robotwright.view._serve import gated_viser
from robotwright.view.gate import Gate, bind_listener, check_value, is_loopback, parse_origin
from robotwright.view.simulate import Contacts, Simulation, contacts, ctrl_problem, ctrl_range

if TYPE_CHECKING:
    import viser

__all__ = ["CLASS_COLORS", "Viewer", "ViewerConfig", "class_color"]

#: Slider range of a joint without limits: a full turn for a hinge [rad], +-1 m for a
#: slide. Only the slider's range; the model is not changed.
UNLIMITED_HINGE = (-np.pi, np.pi)
UNLIMITED_SLIDE = (-1.0, 1.0)
#: Joint types that get a slider (one coordinate each).
_SLIDER_JOINTS = (int(mujoco.mjtJoint.mjJNT_HINGE), int(mujoco.mjtJoint.mjJNT_SLIDE))


def class_color(class_id: int) -> tuple[int, int, int]:
    """RGB (0-255) of a semantic class id (the palette repeats after 9 classes)."""
    h = CLASS_COLORS[class_id % len(CLASS_COLORS)].lstrip("#")
    return (int(h[0:2], 16), int(h[2:4], 16), int(h[4:6], 16))


@dataclass(frozen=True)
class ViewerConfig:
    """How the page starts.

    Attributes:
        host: address the server listens on; ``127.0.0.1`` (default) serves this
            machine only, ``0.0.0.0`` every network interface (anyone who can reach
            the machine sees the model: :attr:`Viewer.exposure` says so).
        port: TCP port, that one only (an error when it is taken); None (default):
            8080, or the next free one up to 8179 (the handle's ``url`` says which);
            0 picks any free port.
        allowed_origins: web origins (``http://robot-pc.lan:8080``) other than the
            page's own whose pages may connect, for deliberate remote use; their host
            names are also accepted in the ``Host`` header.
        geom_groups: MuJoCo geom groups shown first (MuJoCo's viewer shows 0, 1, 2).
        body_frames: show the body frames (axes) first.
        site_frames: show the site frames first.
        point_size: size of a scan point [m].
        grid: draw a ground grid at z = 0 when the model has no plane.
        plain: light with the default lights only, no environment map and no shadows:
            much faster where the browser draws without a GPU (software WebGL).
        verbose: let viser print its own banner and connection messages.
        simulate: start the simulation playing (the page's *Simulation* folder has
            play/pause, step and reset either way).
        contacts: draw contact points and forces while simulating.
    """

    host: str = "127.0.0.1"
    port: int | None = None
    allowed_origins: tuple[str, ...] = ()
    geom_groups: tuple[int, ...] = DEFAULT_GEOM_GROUPS
    body_frames: bool = False
    site_frames: bool = False
    point_size: float = 0.03
    grid: bool = True
    plain: bool = False
    verbose: bool = False
    simulate: bool = False
    contacts: bool = True

    def __post_init__(self) -> None:
        port_ok = isinstance(self.port, int) and not isinstance(self.port, bool)
        if self.port is not None and not (port_ok and 0 <= self.port <= 65535):
            raise ViewError(f"port: expected an integer in 0..65535, got {self.port!r}")
        for origin in self.allowed_origins:
            if not isinstance(origin, str) or parse_origin(origin) is None:
                raise ViewError(
                    f"allowed origin {origin!r}: expected scheme://host[:port] "
                    "(http or https, no path)"
                )
        if not self.host or not isinstance(self.host, str):
            raise ViewError(f"host: expected an address, got {self.host!r}")
        bad = [g for g in self.geom_groups if not (isinstance(g, int) and 0 <= g < 6)]
        if bad:
            raise ViewError(f"geom_groups: expected MuJoCo groups 0..5, got {bad}")
        if not (np.isfinite(self.point_size) and self.point_size > 0):
            raise ViewError(f"point_size: expected a positive size [m], got {self.point_size}")


class Viewer:
    """A running page for one scene; returned by :func:`robotwright.view.show`.

    Attributes:
        scene: what is shown.
        server: the ``viser.ViserServer`` (add your own scene nodes or controls to it).
        data: the ``mujoco.MjData`` whose ``qpos`` the sliders set.
        exposure: a warning when the server listens on an address other machines
            reach (not loopback), else None.
        refused: the last 100 requests and page messages refused (one line each);
            ``refused_count`` counts all of them.
    """

    def __init__(self, scene: ViewScene, config: ViewerConfig | None = None) -> None:
        import viser

        self.scene = scene
        self.config = config or ViewerConfig()
        self.model = scene.model
        self.data = mujoco.MjData(self.model)
        self.skipped: list[str] = []
        self.notes: list[str] = []
        self._lock = threading.Lock()
        self._shapes: dict[int, list[GeomShape]] = {}
        for shape in geom_shapes(self.model, skipped=self.skipped):
            self._shapes.setdefault(shape.group, []).append(shape)
        self._geom_nodes: dict[int, Any] = {}
        self._shown_groups: set[int] = set()
        self._sliders: dict[int, Any] = {}
        self._group_boxes: dict[int, Any] = {}
        self._quiet = False  # set while the code itself moves sliders
        self.refused: collections.deque[str] = collections.deque(maxlen=100)
        self.refused_count = 0
        self._refusals = threading.Condition()
        self._slider_joint: dict[str, int] = {}  # slider uuid -> joint id
        self._slider_actuator: dict[str, int] = {}  # slider uuid -> actuator id
        self._ctrl_sliders: dict[int, Any] = {}
        self.simulation = Simulation(self.model, self.data, self._lock)
        self._follow: int | None = None  # body the cameras follow
        self._follow_at: np.ndarray | None = None
        self._fit_radius = 1.0
        self._contact_nodes: list[Any] = []
        listener = bind_listener(self.config.host, self.config.port)
        address, port = listener.getsockname()[:2]
        self.exposure = (
            None
            if is_loopback(address)
            else f"listening on {self.config.host} (port {port}): anyone who can reach this "
            "machine on that port can see the model and move its joints"
        )
        gate = Gate(
            self.config.host,
            port,
            tuple(o for o in map(parse_origin, self.config.allowed_origins) if o is not None),
            refused=self._note_refusal,
        )
        # viser prints a banner on start; the caller prints the URL instead.
        quiet = contextlib.nullcontext() if self.config.verbose else _quiet_stdout()
        try:
            with (
                quiet,
                gated_viser(listener, gate, self._check_message, self._refuse_message) as gated,
            ):
                self.server: viser.ViserServer = viser.ViserServer(
                    host=self.config.host,
                    port=port,
                    label=f"robotwright: {scene.title}",
                    verbose=self.config.verbose,
                )
        except BaseException:
            listener.close()
            raise
        if not gated():
            self.stop()
            listener.close()
            raise ViewError(
                f"viser {viser.__version__} opens its server in a way robotwright cannot "
                "guard (Host and Origin checks); use the viser version robotwright requires"
            )
        try:
            self._build()
        except BaseException:
            self.server.stop()
            raise

    # -- public -------------------------------------------------------------------------
    @property
    def url(self) -> str:
        """The page's address (``localhost`` when serving every interface)."""
        host = self.server.get_host()
        if host in ("0.0.0.0", "::", ""):
            host = "localhost"
        elif ":" in host:
            host = f"[{host}]"
        return f"http://{host}:{self.server.get_port()}"

    @property
    def geom_count(self) -> int:
        """Geoms drawn so far (meshes sent to the page)."""
        return len(self._geom_nodes)

    def joint_names(self) -> list[str]:
        """Names of the joints that have a slider (hinge and slide joints)."""
        return [self._joint_label(j) for j in self._sliders]

    def set_joint(self, name: str, value: float) -> None:
        """Move joint ``name`` to ``value`` (rad for a hinge, m for a slide), as its
        slider does.

        Raises:
            ViewError (a ``ValueError``): no slider has that name, or ``value`` is not a
                finite number inside the joint's range (a joint without limits takes
                any finite value; its slider shows the nearest end of its range).
        """
        jid = mujoco.mj_name2id(self.model, mujoco.mjtObj.mjOBJ_JOINT, name)
        if jid < 0 or jid not in self._sliders:
            raise ViewError(f"joint '{name}': no slider for it; sliders: {self.joint_names()}")
        problem = self._joint_value_problem(jid, value)
        if problem:
            raise ViewError(f"joint '{name}': {problem}")
        self._set_qpos_value(jid, float(value))
        slider = self._sliders[jid]
        with self._sliders_quiet():
            slider.value = float(np.clip(float(value), slider.min, slider.max))

    def set_qpos(self, qpos: np.ndarray) -> None:
        """Show the configuration ``qpos`` (``model.nq`` finite values)."""
        qpos = np.asarray(qpos, dtype=np.float64).reshape(-1)
        if qpos.shape != (self.model.nq,):
            raise ViewError(f"qpos: expected {self.model.nq} values, got {qpos.shape[0]}")
        bad = np.flatnonzero(~np.isfinite(qpos))
        if bad.size:
            raise ViewError(f"qpos[{bad[0]}]: expected a finite number, got {qpos[bad[0]]}")
        with self._lock:
            self.data.qpos[:] = qpos
        with self._sliders_quiet():
            for jid, slider in self._sliders.items():
                slider.value = float(qpos[self.model.jnt_qposadr[jid]])
        self._update_poses()

    def show_groups(self, groups: set[int] | tuple[int, ...]) -> None:
        """Show the geoms of exactly these MuJoCo groups (meshes sent on first show)."""
        wanted = set(groups)
        for group in sorted(set(self._shapes) | self._shown_groups):
            on = group in wanted
            if on and group not in self._shown_groups:
                self._add_group(group)
            for shape in self._shapes.get(group, []):
                node = self._geom_nodes.get(shape.geom_id)
                if node is not None:
                    node.visible = on
        self._shown_groups |= wanted & set(self._shapes)
        self._visible_groups = wanted
        for group, box in self._group_boxes.items():
            if box.value != (group in wanted):
                box.value = group in wanted

    def stop(self) -> None:
        """Stop the simulation thread and the server (the page stops updating)."""
        self.simulation.stop()
        with contextlib.nullcontext() if self.config.verbose else _quiet_stdout():
            self.server.stop()

    # -- simulation ---------------------------------------------------------------------
    @property
    def sim_time(self) -> float:
        """Simulated time [s] since the start or the last reset."""
        return float(self.data.time)

    def play(self) -> None:
        """Run the simulation in real time (as the page's *Play*)."""
        self._set_playing(True)

    def pause(self) -> None:
        """Stop stepping; the state stays (as the page's *Pause*)."""
        self._set_playing(False)

    def step(self, n: int = 1) -> None:
        """Pause, advance ``n`` timesteps (``mj_step``) and draw the state."""
        self.pause()
        self.simulation.step(n)
        self._draw_state()

    def reset(self) -> None:
        """Pause and return to the first state: time 0, the first pose (keyframe 0 or
        ``qpos0``), zero velocities, the keyframe's controls (else zero)."""
        self.pause()
        with self._lock:
            mujoco.mj_resetData(self.model, self.data)
            self.data.qpos[:] = self.scene.initial_qpos()
            if self.model.nkey:
                self.data.ctrl[:] = self.model.key_ctrl[0]
        with self._sliders_quiet():
            for i, slider in self._ctrl_sliders.items():
                slider.value = float(np.clip(self.data.ctrl[i], slider.min, slider.max))
        self._draw_state()

    def set_ctrl(self, name: str | int, value: float) -> None:
        """Set the control of actuator ``name`` (or its index; its slider's value),
        checked.

        Raises:
            ViewError (a ``ValueError``): no actuator of that name, or ``value`` not a
                finite number inside its ``ctrlrange`` (a control the model does not
                limit takes any finite number).
        """
        if isinstance(name, (int, np.integer)) and not isinstance(name, bool):
            i = int(name)
        elif isinstance(name, str):
            i = mujoco.mj_name2id(self.model, mujoco.mjtObj.mjOBJ_ACTUATOR, name)
        else:
            i = -1
        if i < 0 or i not in self._ctrl_sliders:
            names = [self._actuator_label(a) for a in self._ctrl_sliders]
            raise ViewError(f"actuator '{name}': no such actuator; actuators: {names}")
        problem = ctrl_problem(self.model, i, value)
        if problem:
            raise ViewError(f"actuator '{name}': {problem}")
        self.simulation.set_ctrl(i, float(value))
        slider = self._ctrl_sliders[i]
        with self._sliders_quiet():
            slider.value = float(np.clip(float(value), slider.min, slider.max))

    def contacts(self) -> Contacts:
        """The active contacts and their forces in the world frame (see
        :func:`robotwright.view.simulate.contacts`)."""
        with self._lock:
            return contacts(self.model, self.data)

    def follow(self, body: str | None) -> None:
        """Make the page's cameras follow ``body`` (None: stop following)."""
        if body is None:
            self._follow, self._follow_at = None, None
            return
        b = mujoco.mj_name2id(self.model, mujoco.mjtObj.mjOBJ_BODY, body)
        if b <= 0:
            raise ViewError(f"body '{body}': no such body to follow")
        with self._lock:
            self._follow_at = self.data.xpos[b].copy()
        self._follow = b

    def __enter__(self) -> Viewer:
        return self

    def __exit__(self, *exc: object) -> None:
        self.stop()

    # -- building the page ----------------------------------------------------------------
    def _build(self) -> None:
        server, model = self.server, self.model
        if self.config.plain:
            server.scene.configure_environment_map(hdri=None)
            server.scene.configure_default_lights(True, cast_shadow=False)
            # Without the environment map nothing lights a face turned away from the
            # default lights (walls came out black): a sky/ground light and an ambient
            # term give every face some of its colour, shaded by its direction.
            server.scene.add_light_hemisphere(
                "/lights/sky",
                sky_color=(255, 255, 255),
                ground_color=(150, 140, 130),
                intensity=1.2,
            )
            server.scene.add_light_ambient("/lights/ambient", intensity=0.5)
        self.data.qpos[:] = self.scene.initial_qpos()
        xpos, xquat = body_poses(model, self.data)
        extent = max(float(model.stat.extent), 0.1)
        axes = 0.08 * extent if model.nbody > 1 else 0.2
        self._body_nodes = [
            server.scene.add_frame(
                f"/bodies/b{b}",
                show_axes=self.config.body_frames and b > 0,
                axes_length=axes,
                axes_radius=axes * 0.04,
                wxyz=xquat[b],
                position=xpos[b],
            )
            for b in range(model.nbody)
        ]
        self._site_nodes = [
            server.scene.add_frame(
                f"/bodies/b{s.body_id}/s{s.site_id}",
                show_axes=self.config.site_frames,
                axes_length=axes * 0.6,
                axes_radius=axes * 0.025,
                wxyz=s.quat,
                position=s.pos,
            )
            for s in site_frames(model)
        ]
        self._visible_groups: set[int] = set()
        self.show_groups(self._first_groups())
        has_plane = bool(np.any(model.geom_type == int(mujoco.mjtGeom.mjGEOM_PLANE)))
        if self.config.grid and not has_plane:
            server.scene.add_grid("/grid", width=4 * extent, height=4 * extent, cell_size=0.1)
        if self.scene.scan is not None:
            self._add_scan()
        self._frame_camera()
        self._add_controls()
        self._sent = body_poses(model, self.data)
        if self.model.nkey:
            self.data.ctrl[:] = self.model.key_ctrl[0]
        self._add_simulation()
        self.simulation.start(self._draw_state)
        if self.config.simulate:
            self.play()

    def _first_groups(self) -> set[int]:
        """The configured groups; when they are MuJoCo's default and hold no geom of the
        robot (a URDF with collision elements only, read into group 3), every group
        holding one, so that the robot is not missing from the page."""
        groups = set(self.config.geom_groups)
        robot = {s.group for shapes in self._shapes.values() for s in shapes if s.body_id > 0}
        if self.config.geom_groups == DEFAULT_GEOM_GROUPS and robot and not robot & groups:
            self.notes.append(
                f"the robot has no geom in groups {sorted(groups)}: showing groups "
                f"{sorted(robot)} (its collision geoms) instead"
            )
            groups |= robot
        return groups

    def _add_group(self, group: int) -> None:
        with self.server.atomic():
            for s in self._shapes.get(group, []):
                rgb = tuple(int(round(255 * c)) for c in s.rgba[:3])
                self._geom_nodes[s.geom_id] = self.server.scene.add_mesh_simple(
                    f"/bodies/b{s.body_id}/g{s.geom_id}",
                    vertices=s.vertices,
                    faces=s.faces,
                    color=rgb,
                    opacity=float(s.rgba[3]) if s.rgba[3] < 1.0 else None,
                    side="double" if len(s.faces) <= 2 else "front",
                    wxyz=s.quat,
                    position=s.pos,
                )

    def _add_scan(self) -> None:
        scan = self.scene.scan
        assert scan is not None
        palette = np.array([class_color(i) for i in range(len(scan.class_names))], np.uint8)
        colors = palette[scan.labels] if len(scan.labels) else np.zeros((0, 3), np.uint8)
        self._scan_node = self.server.scene.add_point_cloud(
            "/scan/points",
            points=scan.points.astype(np.float32),
            colors=colors,
            point_size=self.config.point_size,
            point_shape="circle",
            precision="float32",  # float16 would round points 5 m away to 4 mm
        )
        if np.isfinite(scan.sensor_pos).all():
            self.server.scene.add_frame(
                "/scan/sensor",
                axes_length=0.2,
                axes_radius=0.008,
                wxyz=scan.sensor_quat,
                position=scan.sensor_pos,
            )

    def _frame_camera(self) -> None:
        """Look from the front-left (+x, -y, above) at what matters, far enough to see
        all of it: the robots (see :func:`robot_bodies`; in a composed scene the robots,
        not the room), else every geom not on the world body, else every geom but
        planes; for a scan the bulk of its points (2nd to 98th percentile, so a few far
        hits do not shrink the room)."""
        model, data = self.model, self.data
        scan = self.scene.scan
        if scan is not None and len(scan.points):
            lo, hi = np.percentile(scan.points, [2, 98], axis=0)
        else:
            mujoco.mj_kinematics(model, data)
            shown = np.isin(model.geom_group, list(self._visible_groups))
            not_plane = model.geom_type != int(mujoco.mjtGeom.mjGEOM_PLANE)
            robots = np.isin(model.geom_bodyid, robot_bodies(model))
            lo = hi = None
            for pick in (robots & shown, (model.geom_bodyid > 0) & shown, not_plane):
                if pick.any():
                    lo, hi = geom_box(model, data, np.flatnonzero(pick))
                    break
            if lo is None or hi is None:  # nothing but planes: MuJoCo's own statistic
                centre = np.asarray(model.stat.center, dtype=np.float64)
                half = np.full(3, max(float(model.stat.extent), 0.2) / 2)
                lo, hi = centre - half, centre + half
        centre = 0.5 * (lo + hi)
        radius = max(0.5 * float(np.linalg.norm(hi - lo)), 0.1)
        self._fit_radius = radius
        direction = np.array([1.0, -1.0, 0.6])
        direction /= np.linalg.norm(direction)
        # The sphere around the box fills most of the (vertical) field of view.
        distance = 1.3 * radius / np.tan(0.5 * self.server.initial_camera.fov)
        self.server.initial_camera.look_at = tuple(centre)
        self.server.initial_camera.position = tuple(centre + distance * direction)

    def _add_controls(self) -> None:
        gui, model = self.server.gui, self.model
        gui.configure_theme(show_share_button=False, dark_mode=False)
        gui.add_markdown(self._summary_markdown())
        with gui.add_folder("Show"):
            bodies = gui.add_checkbox("Body frames", initial_value=self.config.body_frames)
            sites = gui.add_checkbox("Site frames", initial_value=self.config.site_frames)
            sites.disabled = not self._site_nodes
            bodies.disabled = model.nbody <= 1

            @bodies.on_update
            def _(_: Any) -> None:
                for b, node in enumerate(self._body_nodes):
                    node.show_axes = bodies.value and b > 0

            @sites.on_update
            def _(_: Any) -> None:
                for node in self._site_nodes:
                    node.show_axes = sites.value

            for group in sorted(self._shapes):
                box = gui.add_checkbox(
                    f"Geom group {group} ({len(self._shapes[group])})",
                    initial_value=group in self._visible_groups,
                )

                def toggle(_: Any, group: int = group, box: Any = box) -> None:
                    groups = set(self._visible_groups)
                    if box.value == (group in groups):
                        return  # set by show_groups itself
                    (groups.add if box.value else groups.discard)(group)
                    self.show_groups(groups)

                box.on_update(toggle)
                self._group_boxes[group] = box
        if self.scene.scan is not None:
            with gui.add_folder("Scan"):
                gui.add_html(self._legend_html())
                points = gui.add_checkbox("Points", initial_value=True)

                @points.on_update
                def _(_: Any) -> None:
                    self._scan_node.visible = points.value

        joints = [j for j in range(model.njnt) if int(model.jnt_type[j]) in _SLIDER_JOINTS]
        if joints:
            with gui.add_folder("Joints"):
                reset = gui.add_button("Reset pose")
                for j in joints:
                    self._sliders[j] = self._add_slider(j)

                @reset.on_click
                def _(_: Any) -> None:
                    self._show_pose(self.scene.initial_qpos(), "the first pose")

                if model.nkey:
                    self._add_keyframes()

    def _add_keyframes(self) -> None:
        """A menu of the model's keyframes (``<key>``): picking one shows its ``qpos``."""
        model = self.model
        names = [
            mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_KEY, k) or f"key {k}"
            for k in range(model.nkey)
        ]
        labels = [f"{k}: {n}" for k, n in enumerate(names)]
        menu = self.server.gui.add_dropdown("Keyframe", labels, initial_value=labels[0])
        self._keyframe_menu = menu

        @menu.on_update
        def _(_: Any) -> None:
            self._show_pose(model.key_qpos[labels.index(menu.value)], f"keyframe {menu.value}")

    def _show_pose(self, qpos: np.ndarray, what: str) -> None:
        """``set_qpos`` for a control: a pose it cannot show (a model's keyframe may hold
        NaN) is noted instead of raising in viser's callback thread."""
        try:
            self.set_qpos(qpos)
        except ViewError as exc:
            self._note_refusal(f"{what}: {exc}")

    def _joint_label(self, j: int) -> str:
        return mujoco.mj_id2name(self.model, mujoco.mjtObj.mjOBJ_JOINT, j) or f"joint {j}"

    def _add_slider(self, j: int) -> Any:
        model = self.model
        hinge = int(model.jnt_type[j]) == int(mujoco.mjtJoint.mjJNT_HINGE)
        if model.jnt_limited[j]:
            lo, hi = (float(x) for x in model.jnt_range[j])
        else:
            lo, hi = UNLIMITED_HINGE if hinge else UNLIMITED_SLIDE
        value = float(np.clip(self.data.qpos[model.jnt_qposadr[j]], lo, hi))
        slider = self.server.gui.add_slider(
            self._joint_label(j),
            min=lo,
            max=hi,
            step=max((hi - lo) / 500.0, 1e-6),
            initial_value=value,
            hint=f"{'hinge [rad]' if hinge else 'slide [m]'}"
            + ("" if model.jnt_limited[j] else ", no limits in the model"),
        )

        @slider.on_update
        def _(_: Any) -> None:
            if self._quiet:
                return
            # The page's messages were checked on arrival; this also covers a value
            # set on the handle from Python.
            problem = check_value(0.0, slider.value, slider.min, slider.max)
            if problem:
                self._note_refusal(f"joint '{self._joint_label(j)}': {problem}")
                return
            self._set_qpos_value(j, float(slider.value))

        self._slider_joint[slider._impl.uuid] = j
        return slider

    def _joint_value_problem(self, j: int, value: object) -> str | None:
        """Why ``value`` cannot be joint ``j``'s position, or None."""
        model = self.model
        unit = "rad" if int(model.jnt_type[j]) == int(mujoco.mjtJoint.mjJNT_HINGE) else "m"
        if isinstance(value, (bool, np.bool_)) or not isinstance(value, numbers.Real):
            return f"expected a number [{unit}], got {type(value).__name__}"
        if not math.isfinite(float(value)):
            return f"expected a finite number [{unit}], got {value}"
        if model.jnt_limited[j]:
            lo, hi = (float(x) for x in model.jnt_range[j])
            if not lo <= float(value) <= hi:
                return f"{float(value):g} {unit} is outside the joint's range [{lo:g}, {hi:g}]"
        return None

    # -- the simulation's controls ---------------------------------------------------------
    def _actuator_label(self, i: int) -> str:
        name = mujoco.mj_id2name(self.model, mujoco.mjtObj.mjOBJ_ACTUATOR, i)
        if name:
            return name
        model = self.model
        target = ""
        if int(model.actuator_trntype[i]) == int(mujoco.mjtTrn.mjTRN_JOINT):
            target = self._joint_label(int(model.actuator_trnid[i, 0]))
        return f"actuator {i}" + (f" ({target})" if target else "")

    def _add_simulation(self) -> None:
        """The *Simulation* folder: play/pause, step, reset, the time and real-time
        factor, contacts, camera follow and one slider per actuator (its ``ctrl``)."""
        gui, model = self.server.gui, self.model
        with gui.add_folder("Simulation"):
            self._play_button = gui.add_button("Play", hint="run MuJoCo in real time")
            step = gui.add_button("Step", hint=f"one timestep ({model.opt.timestep:g} s)")
            reset = gui.add_button("Reset", hint="time 0, the first pose, its controls")
            self._clock = gui.add_markdown(self._clock_text())
            shown = gui.add_checkbox("Contacts", initial_value=self.config.contacts)
            self._contacts_box = shown
            bodies = [
                mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_BODY, b) or ""
                for b in range(1, model.nbody)
            ]
            options = ["(none)", *dict.fromkeys(n for n in bodies if n)]
            follow = gui.add_dropdown("Follow", options, initial_value="(none)")
            self._follow_menu = follow

            @self._play_button.on_click
            def _(_: Any) -> None:
                self._set_playing(not self.simulation.playing)

            @step.on_click
            def _(_: Any) -> None:
                self.step(1)

            @reset.on_click
            def _(_: Any) -> None:
                self.reset()

            @shown.on_update
            def _(_: Any) -> None:
                self._draw_contacts()

            @follow.on_update
            def _(_: Any) -> None:
                self.follow(None if follow.value == "(none)" else follow.value)

            if model.nu:
                with gui.add_folder("Actuators"):
                    for i in range(model.nu):
                        self._ctrl_sliders[i] = self._add_ctrl_slider(i)

    def _add_ctrl_slider(self, i: int) -> Any:
        lo, hi, limited = ctrl_range(self.model, i)
        slider = self.server.gui.add_slider(
            self._actuator_label(i),
            min=lo,
            max=hi,
            step=max((hi - lo) / 500.0, 1e-6),
            initial_value=float(np.clip(self.data.ctrl[i], lo, hi)),
            hint="ctrl" + ("" if limited else ", no ctrlrange in the model"),
        )

        @slider.on_update
        def _(_: Any) -> None:
            if self._quiet:
                return
            problem = check_value(0.0, slider.value, slider.min, slider.max)
            if problem is None:
                problem = ctrl_problem(self.model, i, slider.value)
            if problem:
                self._note_refusal(f"actuator '{self._actuator_label(i)}': {problem}")
                return
            self.simulation.set_ctrl(i, float(slider.value))

        self._slider_actuator[slider._impl.uuid] = i
        return slider

    def _set_playing(self, on: bool) -> None:
        if on:
            self.simulation.play()
        else:
            self.simulation.pause()
        self._play_button.label = "Pause" if on else "Play"
        # Joint sliders set positions; while the physics runs they would fight it.
        for slider in self._sliders.values():
            slider.disabled = on
        if not on:
            with self._sliders_quiet():
                for j, slider in self._sliders.items():
                    value = float(self.data.qpos[self.model.jnt_qposadr[j]])
                    slider.value = float(np.clip(value, slider.min, slider.max))

    def _clock_text(self) -> str:
        rtf = self.simulation.real_time_factor
        shown = f"{rtf:.2f}" if rtf is not None and self.simulation.playing else "-"
        text = f"t = {self.data.time:.3f} s, real-time factor {shown}"
        if self.simulation.unstable:
            text += f"  \n{_md(self.simulation.unstable)}"
        return text

    def _draw_state(self) -> None:
        """Send the current state: body poses, contacts, the clock."""
        if self.simulation.unstable and self._play_button.label != "Play":
            self._set_playing(False)
            self._note_refusal(self.simulation.unstable)
        self._update_poses()
        self._draw_contacts()
        self._clock.content = self._clock_text()

    def _draw_contacts(self) -> None:
        """Contact points (red dots) and forces (arrows from the point along the force
        on geom2; the robots' weight is drawn half as long as the robots are wide)."""
        for node in self._contact_nodes:
            node.remove()
        self._contact_nodes = []
        if not self._contacts_box.value:
            return
        found = self.contacts()
        if not len(found.pos):
            return
        size = 0.015 * self._fit_radius
        self._contact_nodes.append(
            self.server.scene.add_point_cloud(
                "/contacts/points",
                points=found.pos.astype(np.float32),
                colors=(230, 40, 40),
                point_size=size * 2,
                point_shape="circle",
                precision="float32",
            )
        )
        ends = found.pos + found.force * self._force_scale()
        long = np.linalg.norm(ends - found.pos, axis=1) > 1e-6
        if long.any():
            self._contact_nodes.append(
                self.server.scene.add_arrows(
                    "/contacts/forces",
                    points=np.stack([found.pos[long], ends[long]], axis=1).astype(np.float32),
                    colors=(230, 120, 20),
                    shaft_radius=0.3 * size,
                    head_radius=0.8 * size,
                    head_length=2.0 * size,
                )
            )

    def _force_scale(self) -> float:
        """Metres of arrow per newton: the weight of the robots (or of the model) is
        drawn as long as the radius of what the camera was fitted to."""
        model = self.model
        roots = robot_bodies(model, roots_only=True)
        mass = float(model.body_subtreemass[roots].sum()) if len(roots) else 0.0
        if mass <= 0:
            mass = float(model.body_subtreemass[0])
        weight = mass * float(np.linalg.norm(model.opt.gravity))
        return self._fit_radius / weight if weight > 0 else self._fit_radius / 10.0

    # -- messages from the page ----------------------------------------------------------
    def _check_message(self, message: Any) -> str | None:
        """Why a message from the page is refused, or None: a control update must set
        the value of one of this page's controls to a value of its kind (a slider's: a
        finite number inside its range; a menu's: one of its entries)."""
        if type(message).__name__ != "GuiUpdateMessage":
            return None
        handles = self.server.gui._gui_input_handle_from_uuid
        handle = handles.get(message.uuid) if isinstance(message.uuid, str) else None
        if handle is None:
            return "update of a control this page does not have"
        updates = message.updates
        if not isinstance(updates, dict) or set(updates) != {"value"}:
            return "a control update may set its value only"
        value = updates["value"]
        j = self._slider_joint.get(message.uuid)
        a = self._slider_actuator.get(message.uuid)
        if j is not None:
            label = f"joint '{self._joint_label(j)}'"
        elif a is not None:
            label = f"actuator '{self._actuator_label(a)}'"
        else:
            label = f"control {handle.label!r}"
        if getattr(handle, "disabled", False):
            return f"{label}: the control is disabled (joint sliders are while simulating)"
        problem = check_value(
            handle.value, value, getattr(handle, "min", None), getattr(handle, "max", None)
        )
        options = getattr(handle, "options", None)
        if problem is None and options is not None and value not in options:
            problem = f"{value!r} is not one of the menu's entries"
        return f"{label}: {problem}" if problem else None

    def _refuse_message(self, connection: Any, reason: str) -> None:
        """Record a refused page message and tell that page why."""
        self._note_refusal(f"message from the page: {reason}")
        ws = self.server._websock_server
        ids = [c for c, conn in list(ws._live_connections.items()) if conn is connection]
        client = self.server.get_clients().get(ids[0]) if ids else None
        if client is not None:
            client.add_notification("Refused", reason, color="red", auto_close_seconds=10.0)

    def _note_refusal(self, reason: str) -> None:
        with self._refusals:
            self.refused.append(reason)
            self.refused_count += 1
            self._refusals.notify_all()

    def wait_for_refusals(self, count: int, timeout: float) -> bool:
        """Wait until ``refused_count`` reaches ``count`` (at most ``timeout`` s); True
        when it did. The page's messages are checked on the server's own thread."""
        with self._refusals:
            return self._refusals.wait_for(lambda: self.refused_count >= count, timeout)

    @contextlib.contextmanager
    def _sliders_quiet(self) -> Iterator[None]:
        """Move sliders without their callbacks (viser runs them on every assignment):
        the caller updates the poses once."""
        self._quiet = True
        try:
            yield
        finally:
            self._quiet = False

    def _set_qpos_value(self, j: int, value: float) -> None:
        with self._lock:
            self.data.qpos[self.model.jnt_qposadr[j]] = value
        self._update_poses()

    def _update_poses(self) -> None:
        """Forward kinematics, then send the pose of every body that moved since the
        poses were last sent."""
        with self._lock:
            xpos, xquat = body_poses(self.model, self.data)
        old = self._sent
        moved = np.flatnonzero(
            (np.abs(xpos - old[0]).max(axis=1) > 0) | (np.abs(xquat - old[1]).max(axis=1) > 0)
        )
        with self.server.atomic():
            for b in moved:
                node = self._body_nodes[b]
                node.position = xpos[b]
                node.wxyz = xquat[b]
        self._sent = (xpos, xquat)
        if self._follow is not None and self._follow_at is not None:
            target = xpos[self._follow]
            shift = target - self._follow_at
            self._follow_at = target.copy()
            if np.abs(shift).max() > 0:
                for client in self.server.get_clients().values():
                    cam = client.camera
                    look_at = np.asarray(cam.look_at) + shift
                    with client.atomic():
                        # viser moves the look-at point with the position (same view
                        # direction); set it too where a version does not
                        cam.position = np.asarray(cam.position) + shift
                        if not np.allclose(cam.look_at, look_at):
                            cam.look_at = look_at

    def _summary_markdown(self) -> str:
        m = self.model
        lines = [
            f"**{_md(self.scene.title)}** ({self.scene.kind})",
            f"{m.nbody - 1} bodies, {m.njnt} joints, {m.nu} actuators, {m.ngeom} geoms, "
            f"{m.nsite} sites",
        ]
        drawn = sum(len(shapes) for shapes in self._shapes.values())
        if drawn < m.ngeom:
            lines.append(f"not drawn: {m.ngeom - drawn} geom(s)")
        return "  \n".join(lines)

    def _legend_html(self) -> str:
        scan = self.scene.scan
        assert scan is not None
        rows = [
            f'<div><span style="display:inline-block;width:0.9em;height:0.9em;'
            f'background:{CLASS_COLORS[i % len(CLASS_COLORS)]};margin-right:0.4em"></span>'
            f"{i}: {html.escape(name)} ({count} points)</div>"
            for i, (name, count) in enumerate(scan.class_counts().items())
        ]
        head = f"<div><b>{len(scan.points)} hits of {scan.num_rays} rays</b></div>"
        return f'<div style="font-size:0.85em">{head}{"".join(rows)}</div>'


def robot_bodies(model: mujoco.MjModel, *, roots_only: bool = False) -> np.ndarray:
    """Ids of the bodies of the robots: the subtrees hanging from the world whose
    joints are more than one free joint (an articulated robot, fixed or floating),
    not walls and furniture (no joint) nor loose props (one free joint).
    ``roots_only``: the subtrees' root bodies only."""
    free = int(mujoco.mjtJoint.mjJNT_FREE)
    root_of = np.asarray(model.body_rootid)
    roots = []
    for r in np.flatnonzero((np.arange(model.nbody) > 0) & (root_of == np.arange(model.nbody))):
        joints = np.flatnonzero(root_of[model.jnt_bodyid] == r)
        if len(joints) > 1 or (len(joints) == 1 and int(model.jnt_type[joints[0]]) != free):
            roots.append(r)
    roots_arr = np.array(roots, dtype=np.int64)
    if roots_only:
        return roots_arr
    return np.flatnonzero(np.isin(root_of, roots_arr))


def geom_box(
    model: mujoco.MjModel, data: mujoco.MjData, geoms: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """World bounding box ``(lo, hi)`` [m] of ``geoms`` (their MuJoCo boxes ``geom_aabb``
    placed at their world poses; kinematics must be current)."""
    signs = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)], float)
    points = []
    for g in geoms:
        centre, half = model.geom_aabb[g, :3], model.geom_aabb[g, 3:]
        rot = data.geom_xmat[g].reshape(3, 3)
        points.append((centre + signs * half) @ rot.T + data.geom_xpos[g])
    every = np.concatenate(points)
    return every.min(axis=0), every.max(axis=0)


def _quiet_stdout() -> contextlib.AbstractContextManager[object]:
    return contextlib.redirect_stdout(io.StringIO())


def _md(text: str) -> str:
    """Escape Markdown's special characters in a name."""
    return "".join("\\" + c if c in "\\`*_{}[]()#+-.!|<>" else c for c in text)
