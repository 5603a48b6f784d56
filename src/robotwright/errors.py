"""Exception and warning types that carry file / row / column / element context."""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class Problem:
    """One problem found in an input.

    Attributes:
        file: the file the problem is in (path as given, or a file name inside a folder).
        message: what is wrong and what was expected.
        row: 0-based data row of a CSV table (header not counted), or None.
        column: the CSV column or YAML key, or None.
        element: an XML element description (e.g. ``<joint name="knee">``), or None.
        severity: ``"error"`` or ``"warning"``.
        cosmetic: a note that changes nothing MuJoCo simulates (a name given, a material
            reduced to its colour, a light or camera dropped, an element carried in
            another exact form); shown as ``(cosmetic)``. ``strict=True`` fails on the
            other notes only, ``strict="all"`` on these too (see :func:`strict_failures`).
    """

    file: str
    message: str
    row: int | None = None
    column: str | None = None
    element: str | None = None
    severity: str = "error"
    cosmetic: bool = False

    def __str__(self) -> str:
        where = [self.file]
        if self.row is not None:
            where.append(f"row {self.row}")
        if self.column is not None:
            where.append(f"column '{self.column}'")
        if self.element is not None:
            where.append(self.element)
        return f"{': '.join(where)}: {'(cosmetic) ' if self.cosmetic else ''}{self.message}"


#: ``strict=`` values: ``False`` (notes only), ``True`` (fail on a note that changes the
#: physics), ``"all"`` (fail on any note, cosmetic ones too; ``--strict-all``).
Strictness = bool | str


def strict_failures(problems: list[Problem], strict: Strictness) -> list[Problem]:
    """The notes that fail a conversion under ``strict`` (see :class:`Problem`)."""
    if strict not in (False, True, "all"):
        raise ValueError(f"strict={strict!r}: expected False, True or 'all'")
    if not strict:
        return []
    return [p for p in problems if strict == "all" or not p.cosmetic]


class RobotwrightError(Exception):
    """Base class of every error raised by robotwright."""


class ProblemsError(RobotwrightError):
    """An error carrying a list of :class:`Problem` (all problems found, not only the first)."""

    def __init__(self, problems: list[Problem], summary: str | None = None) -> None:
        self.problems = list(problems)
        errors = [p for p in self.problems if p.severity == "error"]
        if len(self.problems) == 1 and summary is None:
            # One problem already names its file, element and field: one line.
            super().__init__(str(self.problems[0]))
            return
        head = summary or f"{len(errors)} problem(s) found"
        body = "\n".join(f"  - {p}" for p in self.problems)
        super().__init__(f"{head}:\n{body}" if body else head)


class HRDFError(ProblemsError):
    """An HRDF folder or model is invalid."""


class GeneratorError(RobotwrightError):
    """A generator was used wrongly (e.g. generate before load) or cannot represent its input."""


class ConversionError(ProblemsError):
    """A conversion would lose or change meaning and ``strict=True`` was requested, or it failed."""


class SensorError(RobotwrightError, ValueError):
    """A sensor configuration does not fit its model (unknown body, empty pattern, bad range, ...)."""


class GrammarError(ProblemsError):
    """A grammar, component library or design is invalid (names file, rule/component, field)."""


class OutputPathError(RobotwrightError, OSError):
    """An output path cannot be written: it exists (without overwrite), it is a folder
    where a file is expected (or the reverse), or a component of its folder is a file.

    Also an ``OSError`` (``FileExistsError`` callers keep working through the subclass
    :class:`OutputExistsError`)."""


class OutputExistsError(OutputPathError, FileExistsError):
    """The output exists and replacing it was not allowed."""


class UnsafePathError(RobotwrightError, ValueError):
    """A file path read from an input (a mesh, texture or include path) leaves the folder
    it must stay in: ``..``, an absolute path or a symbolic link pointing elsewhere
    (see :mod:`robotwright._paths`). Folders can be trusted explicitly (``asset_roots``,
    ``--asset-root``).

    Attributes:
        file: the input file the path was read from, when known.
        element: the element holding it (e.g. ``<mesh name="leg" file="../x.stl">``).
        reason: the message without file and element.
    """

    def __init__(
        self, message: str, *, file: str | None = None, element: str | None = None
    ) -> None:
        self.file = file
        self.element = element
        self.reason = message
        where = ": ".join(x for x in (file, element) if x)
        super().__init__(f"{where}: {message}" if where else message)


class InputFileError(RobotwrightError, ValueError):
    """An input file cannot be read as what it must be: not a regular file (a FIFO, a
    device, a folder), larger than its size limit, not UTF-8 text, or nested deeper than
    the limit (see :mod:`robotwright._inputs`).

    Attributes:
        path: the file, as given.
        reason: what is wrong with it (the message without the path).
    """

    def __init__(self, path: object, reason: str) -> None:
        self.path = str(path)
        self.reason = reason
        super().__init__(f"{path}: {reason}")


class RobotSetupWarning(UserWarning):
    """A robot written for simulation will not behave as a user training it expects (no
    drives, a fixed base on a legged robot, a drive without damping): shown always,
    naming the robot and what to give."""

    #: read by :func:`robotwright._notes.collect_notes`: printed as it is, never folded
    #: into a count of conversion notes
    always_shown = True


class ConversionWarning(UserWarning):
    """An element was dropped or approximated during a conversion (named in the message).

    A warning that lists many values (``robot 'arm6' to MJCF: 6 value(s) not written:``
    then one ``"\n  - "`` line per value) is shown by Python's warnings display as one
    line: its head and how many values of each kind, ending ``str(warning) lists each``.
    ``str(warning)`` keeps every value (programs, the command line's ``-v``)."""

    def __format__(self, spec: str) -> str:
        # Python's warnings display writes the message with an f-string, which calls
        # __format__: a call that loses 30 values prints one line, not 30. str() (what
        # programs and the command line read) is untouched.
        from robotwright._notes import one_line

        text = str(self)
        short = one_line(text)
        if spec or short == text:
            return format(text, spec)
        return f"{short}; str(warning) lists each"
