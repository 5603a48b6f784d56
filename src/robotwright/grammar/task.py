"""Tasks: what the physics objectives ask of a limb, read from a YAML file.

A task names the carrier and where the limb is worn, the payload test (poses sampled,
bound, share of free poses), the path to track and the collision check, so that
``grammar search --task FILE`` judges designs on the user's job rather than the
built-in one. Every field is optional; the built-in objectives are
:data:`DEFAULT_TASK`. Units: metres, kilograms, seconds; quaternions (w, x, y, z).

.. code-block:: yaml

    task: carry-and-trace              # a name (required)
    carrier:
      robot: mini_humanoid             # a bundled robot
      at: back_mount                   # its body or site carrying the limb's base
      pos: [0.0, 0.0, 0.0]             # the base's pose there [m]
      quat: [0.7071068, 0.0, -0.7071068, 0.0]
      postures:                        # optional: judge the limb in each of these
        standing: {}                   # the reference pose
        arms_raised: {left_shoulder_pitch_joint: -2.6, right_shoulder_pitch_joint: -2.6}
    payload: {samples: 32, seed: 0, limit: 100.0, min_free_share: 0.5, min_reach: 0.25}
    track:
      duration: 2.0                    # [s]
      center: [0.4, 0.0, 0.4]          # [m] in the mount frame (z out of the base)
      radius: 0.05                     # [m], the circle's
      path: [[0, 0, 0], [0, 0.1, 0], [0, 0.1, 0.1], [0, 0, 0]]  # offsets [m]
    coverage: {low: [0.2, -0.2, 0.2], high: [0.6, 0.2, 0.6], voxel: 0.05}  # [m], mount frame
    collision: {samples: 32, seed: 0}

Targets are absolute, the same for every design: ``track.center`` is fixed in the mount
frame (``display`` instead: the tool point at the design's display pose), ``radius`` is
in metres (``scale`` instead: that share of the design's reach), and ``payload.min_reach``
counts only poses that hold the tool points at least that far from the mount.
``track.path`` lists waypoints, offsets [m] in the world frame from the centre, visited
in order (each leg the same time, starting and stopping at rest); without it the
reference is the built-in circle and line.

``coverage`` is the box whose share of cells the tool must reach (``coverage``'s
objective). A task that names a carrier wears the limb for ``reach`` and ``coverage``
too: a pose that touches the carrier (in any posture) does not count towards them.

``carrier.postures`` names postures of the carrier, each the joint values (rad for a
hinge, m for a slide; joints not named stay at the reference pose) it holds while the
limb is judged. With postures, every physics objective is measured in each of them and
scored by the worst (the smallest payload, the largest tracking error or power), and the
limb must not touch the carrier in any of them: a limb that does its job in every posture.

The file is untrusted input: read within its size cap, every field checked, problems
reported together naming the file and field.
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

from robotwright._bounds import finite_number
from robotwright._names import MAX_NAME_LENGTH, name_problem, shown, shown_key
from robotwright.errors import GrammarError, Problem, RobotwrightError
from robotwright.grammar.loader import _read_yaml
from robotwright.grammar.physics import BACKWARDS, SETTING_BOUNDS, Carrier, _carrier_xml
from robotwright.hrdf.assets import bundled_robot_names

__all__ = ["DEFAULT_TASK", "Task", "load_task"]

#: Largest waypoint offset accepted [m] (a limb's reach is a metre or two).
MAX_OFFSET = 10.0
#: Most waypoints in a path.
MAX_WAYPOINTS = 1000
#: Most carrier postures in a task (each multiplies the physics objectives' cost).
MAX_POSTURES = 16
#: Largest joint value a posture may give (rad or m); a limited joint's range is
#: checked too.
MAX_POSTURE_VALUE = 100.0


@dataclass(frozen=True)
class Task:
    """What the physics objectives measure (see the module docstring)."""

    name: str = "built-in"
    carrier: Carrier = Carrier()
    payload: dict[str, float] = field(default_factory=dict)
    track: dict[str, Any] = field(default_factory=dict)
    collision: dict[str, float] = field(default_factory=dict)
    #: (name, the carrier in that posture) for each posture the limb is judged in; none:
    #: the carrier as it is.
    postures: tuple[tuple[str, Carrier], ...] = ()
    #: The task's file names a carrier: ``reach`` and ``coverage`` count only poses
    #: that do not touch it (in every posture). The built-in task measures the limb's own.
    worn: bool = False
    #: The box ``coverage`` asks the tool to reach: ``low``, ``high`` (m, mount frame),
    #: ``voxel`` (m), ``samples``, ``seed``.
    coverage: dict[str, Any] = field(default_factory=dict)

    def carriers(self) -> tuple[Carrier, ...]:
        """The carrier in each posture (the carrier alone when the task names none)."""
        return tuple(c for _, c in self.postures) or (self.carrier,)

    def objective(self, name: str) -> Any:
        """The objective ``name`` (any of ``grammar search --objective``) set for this
        task; a physics objective over several postures is scored by the worst."""
        from robotwright.grammar.objectives import OBJECTIVES, WorstPosture

        cls = OBJECTIVES[name]
        sections = {"payload": self.payload, "track": self.track, "energy": self.track}
        settings = {**sections, "coverage": self.coverage}.get(name, {})
        # The physics objectives are always worn; reach and coverage when the task file
        # names a carrier; the others never.
        if not (name in sections or self.worn and name in ("reach", "coverage")):
            return cls(**settings)
        if not self.postures:
            return cls(carrier=self.carrier, **settings)
        return WorstPosture(
            tuple(cls(carrier=c, **settings) for _, c in self.postures),
            tuple(n for n, _ in self.postures),
        )

    def constraint(self, text: str) -> Any:
        """The constraint ``text`` (as ``--constraint`` takes it) set for this task: the
        carrier collision check with the task's ``collision`` settings, the tracking
        run's (``no-contact-on-track``, ``within-ratings``, ``max-track-error=M``) with
        its ``track`` settings; each holds in every posture."""
        from robotwright.grammar.objectives import (
            TRACK_CONSTRAINTS,
            InEveryPosture,
            NoCarrierCollision,
            make_constraint,
        )

        if text == "no-carrier-collision":
            base, settings = NoCarrierCollision(), self.collision
        elif text.partition("=")[0] in TRACK_CONSTRAINTS:
            base, settings = make_constraint(text), self.track
        else:
            return make_constraint(text)
        if not self.postures:
            return replace(base, carrier=self.carrier, **settings)
        return InEveryPosture(
            tuple(replace(base, carrier=c, **settings) for _, c in self.postures),
            tuple(n for n, _ in self.postures),
        )


#: The built-in task: the bundled humanoid carries the limb on its back, 32 payload
#: poses counted at 0.25 m or more from the mount, the circle (5 cm radius, centred at
#: (0.4, 0, 0.4) m in the mount frame) and line over 2 s, 32 collision poses.
DEFAULT_TASK = Task()

#: The fields of each section; the ranges of numbers are the objectives' own
#: (:data:`~robotwright.grammar.physics.SETTING_BOUNDS`), ``path`` is the waypoints.
_SECTIONS = {
    "payload": ("samples", "seed", "limit", "min_free_share", "min_reach"),
    "track": ("duration", "center", "radius", "scale", "path"),
    "coverage": ("low", "high", "voxel", "samples", "seed"),
    "collision": ("samples", "seed"),
}
#: Largest quaternion component accepted (the quaternion is normalised).
MAX_QUAT_COMPONENT = 1e6
_CARRIER_KEYS = ("robot", "at", "pos", "quat", "postures")


def load_task(path: str | os.PathLike[str]) -> Task:
    """Read and check a task file.

    Raises:
        GrammarError: every problem, each naming the file and field.
    """
    path = Path(path)
    where = str(path)
    problems: list[Problem] = []

    def bad(field_: str, message: str) -> None:
        problems.append(Problem(where, message, column=field_))

    data = _read_yaml(path, problems)  # the grammar loader's checks and messages
    if data is None:
        raise GrammarError(problems, f"invalid task file {path}")
    for key in data:
        if key not in ("task", "carrier", *_SECTIONS):
            bad(shown_key(key), f"unknown key; expected task, carrier, {', '.join(_SECTIONS)}")
    name = data.get("task")
    if not isinstance(name, str) or not name.strip() or name_problem(name) is not None:
        bad(
            "task",
            "expected the task's name (a non-empty string, a name without control "
            f"characters, at most {MAX_NAME_LENGTH} characters)",
        )
        name = "task"
    carrier = _carrier(data.get("carrier"), bad)
    raw_carrier = data.get("carrier")
    postures = (
        _postures(raw_carrier.get("postures"), carrier, bad)
        if isinstance(raw_carrier, dict) and not problems
        else ()
    )
    sections = {key: _section(key, data.get(key), bad) for key in _SECTIONS}
    if problems:
        raise GrammarError(problems, f"invalid task file {path}")
    task = Task(
        name.strip(),
        carrier,
        sections["payload"],
        sections["track"],
        sections["collision"],
        postures,
        worn=data.get("carrier") is not None,
        coverage=sections["coverage"],
    )
    # The objectives check their settings as they are built: report as the file's.
    for what in ("payload", "track", "coverage"):
        try:
            task.objective(what)
        except ValueError as exc:
            bad(what, str(exc))
    try:
        task.constraint("no-carrier-collision")
    except ValueError as exc:
        bad("collision", str(exc))
    if problems:
        raise GrammarError(problems, f"invalid task file {path}")
    return task


def _vector(value: Any, n: int) -> tuple[float, ...] | None:
    if not isinstance(value, list) or len(value) != n:
        return None
    out = tuple(finite_number(v) for v in value)
    return None if any(v is None for v in out) else out  # type: ignore[return-value]


def _carrier(raw: Any, bad: Any) -> Carrier:
    if raw is None:
        return Carrier()
    if not isinstance(raw, dict):
        bad("carrier", "expected a mapping (robot, at, pos, quat)")
        return Carrier()
    for key in raw:
        if key not in _CARRIER_KEYS:
            bad(f"carrier.{shown_key(key)}", f"unknown key; expected {', '.join(_CARRIER_KEYS)}")
    robot, at = raw.get("robot", "mini_humanoid"), raw.get("at", "back_mount")
    for key, value in (("robot", robot), ("at", at)):
        if not isinstance(value, str) or not value:
            bad(f"carrier.{key}", "expected a name")
            return Carrier()
    # A name from an untrusted file: one of the bundled robots, never a path to follow.
    bundled = bundled_robot_names()
    if robot not in bundled:
        bad("carrier.robot", f"{shown(robot)}: expected a bundled robot, one of {bundled}")
        return Carrier()
    pos = _vector(raw.get("pos", [0.0, 0.0, 0.0]), 3)
    quat = _vector(raw.get("quat", list(BACKWARDS)), 4)
    if pos is None or any(abs(v) > MAX_OFFSET for v in pos):
        bad("carrier.pos", f"expected 3 finite numbers [m], each within +-{MAX_OFFSET:g}")
        return Carrier()
    if quat is not None and any(abs(v) > MAX_QUAT_COMPONENT for v in quat):
        quat = None
    norm = math.hypot(*quat) if quat is not None else 0.0  # hypot: no overflow on squares
    if quat is None or norm < 1e-9:
        bad(
            "carrier.quat",
            f"expected 4 finite numbers (w, x, y, z), each within +-{MAX_QUAT_COMPONENT:g}, "
            "not all 0",
        )
        return Carrier()
    carrier = Carrier(robot, at, pos, tuple(v / norm for v in quat))  # type: ignore[arg-type]
    try:
        _carrier_xml(carrier)  # the robot and the body or site exist
    except ValueError as exc:
        bad("carrier.at", str(exc))
    except RobotwrightError as exc:  # $HURODES_ASSETS_PATH may hold another of that name
        bad("carrier.robot", str(exc))
    return carrier


def _postures(raw: Any, carrier: Carrier, bad: Any) -> tuple[tuple[str, Carrier], ...]:
    """``carrier.postures``: name -> {joint: value}, each checked against the carrier."""
    if raw is None:
        return ()
    where = "carrier.postures"
    if not isinstance(raw, dict) or not 1 <= len(raw) <= MAX_POSTURES:
        bad(where, f"expected a mapping of 1 to {MAX_POSTURES} postures (name: {{joint: value}})")
        return ()
    out = []
    for name, joints in raw.items():
        here = f"{where}.{shown_key(name)}"
        if not isinstance(name, str) or name_problem(name) is not None:
            bad(here, f"expected a posture name (at most {MAX_NAME_LENGTH} characters)")
            continue
        if joints is None:
            joints = {}
        if not isinstance(joints, dict):
            bad(here, "expected a mapping of joint name to value (rad or m)")
            continue
        values = []
        for joint, value in joints.items():
            number = finite_number(value)
            if not isinstance(joint, str) or number is None or abs(number) > MAX_POSTURE_VALUE:
                bad(
                    f"{here}.{shown_key(joint)}",
                    f"expected a joint value within +-{MAX_POSTURE_VALUE:g} (rad or m), "
                    f"got {shown(value)}",
                )
                continue
            values.append((joint, number))
        if len(values) != len(joints):
            continue
        posed = replace(carrier, posture=tuple(values))
        try:
            _carrier_xml(posed)  # every joint exists and every value is in its range
        except ValueError as exc:
            bad(here, str(exc))
            continue
        out.append((name, posed))
    return tuple(out)


def _section(key: str, raw: Any, bad: Any) -> dict[str, Any]:
    if raw is None:
        return {}
    if not isinstance(raw, dict):
        bad(key, f"expected a mapping of {', '.join(_SECTIONS[key])}")
        return {}
    if key == "track" and "scale" in raw and "radius" in raw:
        bad("track.scale", "give radius [m] or scale (of the design's reach), not both")
    out: dict[str, Any] = {}
    for name, value in raw.items():
        where = f"{key}.{shown_key(name)}"
        if name not in _SECTIONS[key]:
            bad(where, f"unknown key; expected {', '.join(_SECTIONS[key])}")
        elif name in ("low", "high", "center"):
            if name == "center" and value == "display":
                out[name] = None
                continue
            point = _point(value)
            if point is None:
                display = (
                    ", or display (the tool point at the design's display pose)"
                    if name == "center"
                    else ""
                )
                bad(
                    where,
                    f"expected [x, y, z] of finite numbers [m] in the mount frame, each "
                    f"within +-{MAX_OFFSET:g}{display}",
                )
            else:
                out[name] = point
        elif name == "path":
            waypoints = _waypoints(value)
            if waypoints is None:
                bad(
                    where,
                    f"expected 2 to {MAX_WAYPOINTS} waypoints [x, y, z] of finite numbers "
                    f"[m], each within +-{MAX_OFFSET:g}",
                )
            else:
                out[name] = waypoints
        else:
            bound = SETTING_BOUNDS[name]
            number = bound.check(value)
            if number is None:
                bad(where, f"{bound.expected()}, got {shown(value)}")
            else:
                out[name] = number
    if key == "track" and "scale" in out:
        out["radius"] = None  # the circle follows the design's reach
    return out


def _point(value: Any) -> tuple[float, float, float] | None:
    """A point [m]: 3 finite numbers, each within +-:data:`MAX_OFFSET`; else None."""
    point = _vector(value, 3)
    if point is None or any(abs(v) > MAX_OFFSET for v in point):
        return None
    return point  # type: ignore[return-value]


def _waypoints(value: Any) -> tuple[tuple[float, float, float], ...] | None:
    if not isinstance(value, list) or not 2 <= len(value) <= MAX_WAYPOINTS:
        return None
    points = [_point(p) for p in value]
    if any(p is None for p in points):
        return None
    return tuple(points)  # type: ignore[arg-type]
