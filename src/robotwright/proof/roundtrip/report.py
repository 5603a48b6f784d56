"""The round trip's fidelity table: its tolerances, its rows and the report of one robot."""

from __future__ import annotations

from dataclasses import dataclass, field

import mujoco

from robotwright.errors import ConversionError
from robotwright.parsers.report import ParseResult

TOL_EXACT = 1e-9

TOL_URDF = 1e-6

#: A body's mass or inertia below FLOOR times the robot's largest is compared relative to
#: that instead of to itself (the absolute floor of the relative tolerances).
FLOOR = 1e-6


@dataclass
class Row:
    """One line of the fidelity table."""

    check: str
    value: str
    ok: bool
    note: str = ""
    #: How many items the row compared (None: a measurement, always applicable). A row
    #: that compared nothing (0 of 0 sensors) is shown as "n/a", not counted as passed.
    compared: int | None = None

    @property
    def applicable(self) -> bool:
        return self.compared != 0


@dataclass
class RoundTripReport:
    """The fidelity table of one robot."""

    source: str
    reference: str
    rows: list[Row] = field(default_factory=list)
    warnings: list[str] = field(default_factory=list)
    error: str | None = None
    #: The parser's refusal of the input itself (a missing mesh, a bad value, a lost one
    #: under ``strict``), also summed up in ``error``: the command line reports it as bad
    #: input (exit 2), as ``convert`` does.
    input_error: ConversionError | None = field(default=None, repr=False)
    #: The parse of the source the table is about (None when it failed): a caller that
    #: needs the robot too reads it here instead of parsing the file again. Meshes the
    #: parse staged stay only when ``roundtrip`` was given a ``work_dir``.
    parse: ParseResult | None = field(default=None, repr=False)
    #: MuJoCo's compile of our MJCF of that robot (None when not written or refused).
    mjcf_model: mujoco.MjModel | None = field(default=None, repr=False)
    #: Our MJCF as the simulation row steps it: ``mjcf_model``, or for a URDF source the
    #: same compiled without visual geoms, as MuJoCo's import of the source leaves them.
    simulated_model: mujoco.MjModel | None = field(default=None, repr=False)
    #: The source as the simulation row steps it: ``reference_model``, or for a URDF
    #: read with ``fixed_joints="merge"`` MuJoCo's import with its fixed links fused
    #: (``fusestatic``), as ``convert``'s proof steps it (kept apart, their geoms would
    #: touch geoms that the merged robot holds in one body, which MuJoCo never collides).
    simulated_reference: mujoco.MjModel | None = field(default=None, repr=False)
    #: MuJoCo's model of the source (None when the reference is not MuJoCo's).
    reference_model: mujoco.MjModel | None = field(default=None, repr=False)

    @property
    def ok(self) -> bool:
        return self.error is None and all(r.ok for r in self.rows)

    def failures(self) -> list[Row]:
        return [r for r in self.rows if not r.ok]

    def passed(self) -> list[Row]:
        """Rows that compared something and agree (``n/a`` rows are not passed checks)."""
        return [r for r in self.rows if r.ok and r.applicable]

    def table(self) -> str:
        lines = [f"source:    {self.source}", f"reference: {self.reference}"]
        if self.error:
            lines.append(f"ERROR: {self.error}")
        width = max((len(r.check) for r in self.rows), default=10)
        for r in self.rows:
            mark = "FAIL" if not r.ok else ("ok  " if r.applicable else "n/a ")
            note = f"  ({r.note})" if r.note else ""
            lines.append(f"  {mark} {r.check:<{width}}  {r.value}{note}")
        lines.append(f"warnings:  {len(self.warnings)}")
        lines.append("result:    " + ("PASS" if self.ok else "FAIL"))
        return "\n".join(lines)
