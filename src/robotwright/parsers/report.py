"""Warnings collected while parsing, and the ``strict`` switch.

Every element a parser drops or approximates is recorded as a
:class:`~robotwright.errors.Problem` with ``severity="warning"`` naming the file and the
element. With ``strict=True`` the parse still runs to the end (so that all problems are
found) and then raises one :class:`~robotwright.errors.ConversionError` listing them all.
"""

from __future__ import annotations

import logging
from collections.abc import Iterator
from dataclasses import dataclass, field
from typing import Any

from robotwright.errors import ConversionError, Problem, Strictness, strict_failures
from robotwright.hrdf.model import HRDF

LOG = logging.getLogger("robotwright.parsers")


@dataclass
class ParseResult:
    """The outcome of a parse.

    Attributes:
        hrdf: the robot.
        warnings: every element dropped or approximated, in document order.
        source: the file parsed.
    """

    hrdf: HRDF
    warnings: list[Problem] = field(default_factory=list)
    source: str = ""

    def __iter__(self) -> Iterator[Any]:
        """Unpacks as ``hrdf, warnings = urdf_to_hrdf_with_warnings(...)``."""
        return iter((self.hrdf, self.warnings))


class Reporter:
    """Collects warnings for one source file."""

    def __init__(self, file: str) -> None:
        self.file = file
        self.problems: list[Problem] = []

    def warn(self, message: str, element: str | None = None, *, cosmetic: bool = False) -> None:
        """Record a note; ``cosmetic``: it changes nothing MuJoCo simulates."""
        self.problems.append(
            Problem(self.file, message, element=element, severity="warning", cosmetic=cosmetic)
        )

    def error(self, message: str, element: str | None = None) -> Problem:
        return Problem(self.file, message, element=element)

    def finish(self, strict: Strictness, emit: bool = True) -> list[Problem]:
        """Raise under ``strict`` when a note fails it (``True``: one that changes the
        physics; ``"all"``: any, see :func:`~robotwright.errors.strict_failures`); else
        log each warning on the ``robotwright.parsers`` logger and return them."""
        failing = strict_failures(self.problems, strict)
        if failing:
            raise ConversionError(
                [
                    Problem(p.file, p.message, element=p.element, cosmetic=p.cosmetic)
                    for p in failing
                ],
                summary=f"strict conversion of {self.file}: {len(failing)} element(s) "
                "would be dropped or approximated",
            )
        if emit:
            for p in self.problems:
                LOG.warning("%s", p)
        return list(self.problems)


def warn_massless_moving(hrdf: HRDF, rep: Reporter, element: str) -> None:
    """Warn about each body with joints that MuJoCo (and so the generators) will refuse:
    no mass and inertia of its own nor in a body welded to it. ``element`` is a format
    string for the body's element in the source (``{}`` = body name)."""
    from robotwright.hrdf.validate import moving_bodies_without_mass

    for name in moving_bodies_without_mass(hrdf):
        rep.warn(
            "body with joints and no mass or principal inertia >= 1e-15 kg (m^2), itself or "
            "in a body welded to it: MuJoCo refuses it, so generation will fail "
            "(fixed_joints='merge', --fixed-joints merge, folds fixed links into it; "
            "bound_mass/bound_inertia, --bound-mass/--bound-inertia, raise it)",
            element.format(name),
        )
