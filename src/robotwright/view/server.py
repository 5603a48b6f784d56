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
import io
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
from robotwright.view._serve import gated_viser
from robotwright.view.gate import Gate, bind_listener, is_loopback, parse_origin
from robotwright.view.messages import PageMessages
from robotwright.view.panels import PagePanels
from robotwright.view.sim_panel import SimulationPanel
from robotwright.view.simulate import Simulation

if TYPE_CHECKING:
    import viser


__all__ = ["Viewer", "ViewerConfig"]


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


class Viewer(PagePanels, SimulationPanel, PageMessages):
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


def _quiet_stdout() -> contextlib.AbstractContextManager[object]:
    return contextlib.redirect_stdout(io.StringIO())
