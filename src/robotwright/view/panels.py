"""The page's panels: geom groups, the scan and its legend, the camera framing, joint
sliders, keyframes and the summary (a part of :class:`~robotwright.view.server.Viewer`)."""

from __future__ import annotations

import html
import math
import numbers
from typing import TYPE_CHECKING, Any

import mujoco
import numpy as np

from robotwright.scene.geometry import (
    DEFAULT_GEOM_GROUPS,
)
from robotwright.scene.load import ViewError
from robotwright.sensors.plot import CLASS_COLORS
from robotwright.view.drawing import (
    _SLIDER_JOINTS,
    UNLIMITED_HINGE,
    UNLIMITED_SLIDE,
    _md,
    class_color,
    geom_box,
    robot_bodies,
)
from robotwright.view.gate import check_value

if TYPE_CHECKING:
    pass


class PagePanels:
    """Building the page's panels; a base of :class:`~robotwright.view.server.Viewer`, whose
    ``__init__`` sets the attributes used here."""

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
