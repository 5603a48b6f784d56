"""A robot whose physics is refused, made showable: pictures need geometry only.

The generators refuse a robot whose masses or inertias MuJoCo would refuse (a massless
moving link, principal moments breaking the triangle inequality: example-robot-data's
go1 base). ``view`` and ``render`` still show it: :func:`for_display` replaces the
refused values of those bodies only, and says so (one line naming the bodies); what it
returns is for drawing, never written anywhere.
"""

from __future__ import annotations

import dataclasses

from robotwright.errors import HRDFError
from robotwright.hrdf.model import HRDF

__all__ = ["for_display"]

#: Mass [kg] and principal moments [kg m^2] given to a refused body: at least MuJoCo's
#: smallest accepted value, small enough not to move the picture's centre of mass.
_DISPLAY_MASS = 1e-6

#: Columns of body.csv whose refusal :func:`for_display` repairs.
_PHYSICS_COLUMNS = {"mass", "diag_inertia"}


def for_display(hrdf: HRDF, refused: HRDFError) -> tuple[HRDF, list[str]]:
    """A copy of ``hrdf`` whose bodies refused for their mass or inertia (``refused``'s
    problems) carry a small valid mass and equal principal moments instead, and the
    warning saying so.

    Raises:
        HRDFError: ``refused`` itself, when any problem is not one of a body's mass or
            inertia (nothing to show), or the copy is still refused.
    """
    problems = [p for p in refused.problems if p.severity == "error"]
    rows = {p.row for p in problems if p.file == "body.csv" and p.column in _PHYSICS_COLUMNS}
    if (
        not rows
        or None in rows
        or any(p.file != "body.csv" or p.column not in _PHYSICS_COLUMNS for p in problems)
    ):
        raise refused
    bodies = list(hrdf.bodies)
    for i in sorted(rows):
        b = bodies[i]
        d = max((*b.diag_inertia, _DISPLAY_MASS) if len(b.diag_inertia) == 3 else (_DISPLAY_MASS,))
        bodies[i] = dataclasses.replace(b, mass=max(b.mass, _DISPLAY_MASS), diag_inertia=(d, d, d))
    shown = dataclasses.replace(hrdf, bodies=bodies)
    from robotwright.hrdf.validate import check_model

    if any(p.severity == "error" for p in check_model(shown, check_files=False, finite=False)):
        raise refused
    names = ", ".join(bodies[i].name for i in sorted(rows))
    reason = problems[0].message
    return shown, [
        f"robot '{hrdf.name}': physics refused ({reason}"
        + (f"; {len(problems) - 1} more" if len(problems) > 1 else "")
        + f"); shown with placeholder mass and inertia on {len(rows)} body(ies): {names}. "
        "Its geometry is as given; convert, export and simulation refuse it until the "
        "physics is repaired (convert's --balance-inertia, --bound-mass, --bound-inertia)"
    ]
