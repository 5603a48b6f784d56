"""The viewer's simulation: play, pause, step and reset, actuator sliders, the clock,
contact points and forces, a camera that follows a body (a part of
:class:`~robotwright.view.server.Viewer`)."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import mujoco
import numpy as np

from robotwright.scene.load import ViewError
from robotwright.view.drawing import (
    _md,
    robot_bodies,
)
from robotwright.view.gate import check_value
from robotwright.view.simulate import Contacts, contacts, ctrl_problem, ctrl_range

if TYPE_CHECKING:
    pass


class SimulationPanel:
    """The simulation's controls and drawing; a base of
    :class:`~robotwright.view.server.Viewer`, whose ``__init__`` sets the attributes used here."""

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
