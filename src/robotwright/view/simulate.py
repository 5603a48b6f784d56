"""The viewer's simulate mode: MuJoCo stepping in a thread, paced to the wall clock.

:class:`Simulation` owns the stepping of one ``MjData`` (shared with the page, guarded
by the viewer's lock): :meth:`Simulation.step` advances it by whole timesteps,
:meth:`Simulation.set_ctrl` sets an actuator's control after checking it, and
:func:`contacts` reads the active contacts with their forces (``mj_contactForce``) in
the world frame. :meth:`Simulation.start` runs the stepping loop in a daemon thread:
while playing, it steps until the simulated time has caught up with the wall-clock time
since play was pressed, at most :data:`MAX_LAG` seconds of physics per frame (a model
slower than real time then runs slower: the real-time factor shown says so), and calls
``on_frame`` about :data:`FRAME_RATE` times a second.
"""

from __future__ import annotations

import collections
import math
import numbers
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass

import mujoco
import numpy as np

__all__ = ["FRAME_RATE", "Contacts", "Simulation", "contacts", "ctrl_range"]

#: Page updates per second while playing.
FRAME_RATE = 30.0
#: Most simulated time [s] stepped between two page updates: behind by more, the
#: simulation runs slower than real time instead of trying to catch up.
MAX_LAG = 0.1
#: Slider range of an actuator without ``ctrlrange`` (its control is not limited).
UNLIMITED_CTRL = (-1.0, 1.0)


@dataclass(frozen=True)
class Contacts:
    """The active contacts of a state.

    Attributes:
        pos: ``(N, 3)`` contact points in the world frame [m].
        force: ``(N, 3)`` contact force [N] in the world frame: the force geom1 exerts
            on geom2 (the contact normal points from geom1 to geom2).
        geom1, geom2: ``(N,)`` geom ids of each pair.
    """

    pos: np.ndarray
    force: np.ndarray
    geom1: np.ndarray
    geom2: np.ndarray


def contacts(model: mujoco.MjModel, data: mujoco.MjData) -> Contacts:
    """The contacts of ``data`` (after ``mj_step`` or ``mj_forward``) with their forces:
    ``mj_contactForce`` (contact frame, normal first) rotated by the contact's frame
    into the world frame."""
    n = int(data.ncon)
    pos, force = np.zeros((n, 3)), np.zeros((n, 3))
    wrench = np.zeros(6)
    for i in range(n):
        c = data.contact[i]
        mujoco.mj_contactForce(model, data, i, wrench)
        pos[i] = c.pos
        # frame: rows are the normal and two tangents, in world coordinates
        force[i] = np.asarray(c.frame).reshape(3, 3).T @ wrench[:3]
    g1 = np.array([data.contact[i].geom1 for i in range(n)], dtype=np.int64)
    g2 = np.array([data.contact[i].geom2 for i in range(n)], dtype=np.int64)
    return Contacts(pos, force, g1, g2)


def ctrl_range(model: mujoco.MjModel, i: int) -> tuple[float, float, bool]:
    """Slider range of actuator ``i``'s control and whether the model limits it: its
    ``ctrlrange`` when ``ctrllimited``, else :data:`UNLIMITED_CTRL` (slider only)."""
    if model.actuator_ctrllimited[i]:
        lo, hi = (float(x) for x in model.actuator_ctrlrange[i])
        return lo, hi, True
    return (*UNLIMITED_CTRL, False)


def ctrl_problem(model: mujoco.MjModel, i: int, value: object) -> str | None:
    """Why ``value`` cannot be actuator ``i``'s control, or None: a finite number,
    inside ``ctrlrange`` when the model limits it."""
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, numbers.Real):
        return f"expected a number, got {type(value).__name__}"
    if not math.isfinite(float(value)):
        return f"expected a finite number, got {value}"
    lo, hi, limited = ctrl_range(model, i)
    if limited and not lo <= float(value) <= hi:
        return f"{float(value):g} is outside the actuator's ctrlrange [{lo:g}, {hi:g}]"
    return None


class Simulation:
    """Steps ``data`` of ``model``; every change is made under ``lock``.

    Attributes:
        playing: True while the thread steps with the wall clock.
        real_time_factor: simulated seconds per wall-clock second over the last second
            of playing; None before there is one.
        unstable: set (one line) when MuJoCo reset a bad acceleration; playing stops.
    """

    def __init__(self, model: mujoco.MjModel, data: mujoco.MjData, lock: threading.Lock) -> None:
        self.model, self.data, self.lock = model, data, lock
        self.playing = False
        self.real_time_factor: float | None = None
        self.unstable: str | None = None
        self._wake = threading.Condition()
        self._stopped = False
        self._thread: threading.Thread | None = None
        self._samples: collections.deque[tuple[float, float]] = collections.deque()

    # -- stepping ---------------------------------------------------------------------
    def step(self, n: int = 1) -> None:
        """Advance ``n`` timesteps (``mj_step``); stops playing if MuJoCo finds the
        state invalid (NaN or huge accelerations: it resets the state and warns)."""
        if isinstance(n, bool) or not isinstance(n, int) or n < 0:
            raise ValueError(f"steps: expected a whole number >= 0, got {n!r}")
        with self.lock:
            self._step_locked(n)

    def _step_locked(self, n: int) -> None:
        bad = mujoco.mjtWarning.mjWARN_BADQACC
        before = int(self.data.warning[bad].number)
        for _ in range(n):
            mujoco.mj_step(self.model, self.data)
            if int(self.data.warning[bad].number) > before:
                self.unstable = (
                    f"MuJoCo reset an unstable state at t = {self.data.time:.3f} s "
                    "(NaN or huge acceleration); simulation paused"
                )
                self.playing = False
                return

    def set_ctrl(self, i: int, value: float) -> None:
        """Set actuator ``i``'s control.

        Raises:
            ValueError: not a finite number inside the actuator's ``ctrlrange``.
        """
        problem = ctrl_problem(self.model, i, value)
        if problem:
            raise ValueError(problem)
        with self.lock:
            self.data.ctrl[i] = float(value)

    # -- the thread ---------------------------------------------------------------------
    def play(self) -> None:
        with self._wake:
            self.playing = True
            self.unstable = None
            self._wake.notify_all()

    def pause(self) -> None:
        with self._wake:
            self.playing = False
            self._wake.notify_all()

    def start(self, on_frame: Callable[[], None]) -> None:
        """Run the stepping loop in a daemon thread; ``on_frame`` is called after each
        batch of steps (it draws the state)."""
        self._thread = threading.Thread(
            target=self._loop, args=(on_frame,), name="robotwright-simulate", daemon=True
        )
        self._thread.start()

    def stop(self, timeout: float = 5.0) -> None:
        """End the loop and wait for the thread (at most ``timeout`` s)."""
        with self._wake:
            self._stopped = True
            self.playing = False
            self._wake.notify_all()
        if self._thread is not None and self._thread is not threading.current_thread():
            self._thread.join(timeout)

    def _loop(self, on_frame: Callable[[], None]) -> None:
        period = 1.0 / FRAME_RATE
        dt = float(self.model.opt.timestep)
        most = max(1, int(math.ceil(MAX_LAG / dt)))
        while True:
            with self._wake:
                while not self.playing and not self._stopped:
                    self._wake.wait()
                if self._stopped:
                    return
            wall0, sim0 = time.monotonic(), float(self.data.time)
            self._samples.clear()
            while self.playing and not self._stopped:
                now = time.monotonic()
                with self.lock:
                    behind = sim0 + (now - wall0) - float(self.data.time)
                    steps = min(most, int(behind / dt)) if behind > 0 else 0
                    self._step_locked(steps)
                    sim = float(self.data.time)
                if steps == most:  # cannot keep up: pace from here
                    wall0, sim0 = time.monotonic(), sim
                self._measure(now, sim)
                on_frame()
                with self._wake:
                    if self.playing and not self._stopped:
                        self._wake.wait(max(0.0, period - (time.monotonic() - now)))
            on_frame()

    def _measure(self, wall: float, sim: float) -> None:
        """Real-time factor over the last second of (wall, simulated) time samples."""
        self._samples.append((wall, sim))
        while len(self._samples) > 2 and wall - self._samples[0][0] > 1.0:
            self._samples.popleft()
        (w0, s0), (w1, s1) = self._samples[0], self._samples[-1]
        if w1 - w0 > 0.2:
            self.real_time_factor = (s1 - s0) / (w1 - w0)
