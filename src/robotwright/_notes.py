"""Conversion notes: the values and elements a command could not carry into its output.

robotwright reports each loss as a warning (see :class:`~robotwright.errors.ConversionWarning`);
one warning may list many values, one per ``"\\n  - "`` line (``robot 'arm6' to URDF: 7
value(s) not written: ...``). A *note* is one such value or element. The command line
and the demo count and list notes with the functions here, so the number a summary
line shows is the number of lines its full list holds.
"""

from __future__ import annotations

import re
import warnings
from collections import Counter
from collections.abc import Iterable, Iterator, Sequence
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path

__all__ = [
    "Note",
    "collect_notes",
    "is_ours",
    "kind_counts",
    "name_list",
    "notes_of",
    "one_line",
    "summary_line",
]

_PACKAGE_DIR = str(Path(__file__).resolve().parent)

#: ``joint.csv: row 3: column 'armature': ...`` -> kind ``joint.csv armature``.
_TABLE = re.compile(
    r"^(?P<file>\w+\.csv|meta\.yaml|joint_mapping\.yaml|extra\.xml)(?:: row \d+)?"
    r"(?:: column '(?P<column>[^']+)')?:"
)
#: ``t.xml: <joint name="a">: ...`` -> kind ``<joint>``.
_ELEMENT = re.compile(r"<(?P<tag>[A-Za-z_][\w-]*)[\s>/]")


def name_list(names: Sequence[str], limit: int = 12) -> str:
    """``"a, b, c"``, cut after ``limit`` names with ``"... (N more)"``: a warning about
    a 10,000-joint robot stays one readable line."""
    shown = ", ".join(names[:limit])
    return shown if len(names) <= limit else f"{shown}, ... ({len(names) - limit} more)"


@dataclass(frozen=True)
class Note:
    """One value or element a conversion did not keep (or kept approximately).

    Attributes:
        kind: what sort of value: an HRDF file and column (``joint.csv armature``), an
            XML element tag (``<tendon>``), or ``other``.
        text: the full message for this value, with the context of its warning.
    """

    kind: str
    text: str


def _kind(text: str, fallback: str) -> str:
    m = _TABLE.match(text)
    if m:
        return f"{m['file']} {m['column']}" if m["column"] else m["file"]
    m = _ELEMENT.search(text)
    if m:
        return f"<{m['tag']}>"
    return fallback


def notes_of(message: str) -> list[Note]:
    """Split one warning message into its notes (one per listed value, or the message)."""
    head, *items = str(message).split("\n  - ")
    # One line per note: a list file holds as many lines as the count says.
    head = " ".join(head.split())
    if not items:
        return [Note(_kind(head, "other"), head)]
    head = head.rstrip(":")
    return [Note(_kind(item, "other"), f"{head}: {' '.join(item.split())}") for item in items]


def is_ours(w: warnings.WarningMessage) -> bool:
    """Whether a caught warning comes from robotwright (its class or the warning code)."""
    return w.category.__module__.startswith("robotwright") or str(w.filename).startswith(
        _PACKAGE_DIR
    )


def _always_shown(w: warnings.WarningMessage) -> bool:
    """A warning the command line prints as it is, never folded into the notes' count
    (its class says ``always_shown``, as :class:`~robotwright.errors.RobotSetupWarning`
    does: what the user must act on)."""
    return bool(getattr(w.category, "always_shown", False))


def _unique(items: Iterable[Note]) -> list[Note]:
    return list(dict.fromkeys(items))


@dataclass
class CaughtNotes:
    """What :func:`collect_notes` caught: ``notes`` from robotwright (duplicates removed,
    in order) and ``others``, the warnings of other libraries, shown as they are."""

    notes: list[Note]
    others: list[warnings.WarningMessage]


@contextmanager
def collect_notes() -> Iterator[CaughtNotes]:
    """Catch the warnings raised inside the block; fill the yielded :class:`CaughtNotes`
    when the block ends (also when it raises)."""
    caught_notes = CaughtNotes([], [])
    with warnings.catch_warnings(record=True) as caught:
        # Every robotwright loss counts, even when the same line warned before; other
        # libraries' warnings keep their usual filters (deprecations stay hidden).
        warnings.simplefilter("always", UserWarning)
        try:
            yield caught_notes
        finally:
            notes: list[Note] = []
            for w in caught:
                if is_ours(w) and not _always_shown(w):
                    notes += notes_of(str(w.message))
                else:
                    caught_notes.others.append(w)
            caught_notes.notes = _unique(notes)


def summary_line(notes: Sequence[Note], where: str | None = None) -> str:
    """``N conversion note(s) (...): 22 joint.csv armature, 11 simple_geom.csv, ...; WHERE``
    (``where``: the file holding the full list, or how to print it)."""
    tail = f"; {where}" if where else ""
    return (
        f"{len(notes)} conversion note(s) (values or elements not kept or approximated): "
        f"{kind_counts(notes)}{tail}"
    )


def kind_counts(notes: Sequence[Note]) -> str:
    """``"22 joint.csv armature, 11 simple_geom.csv"``: how many notes of each kind, the
    most frequent first."""
    counts = Counter(n.kind for n in notes)
    return ", ".join(f"{c} {k}" for k, c in sorted(counts.items(), key=lambda kv: (-kv[1], kv[0])))


def one_line(message: str) -> str:
    """A warning that lists values (``head:\n  - a\n  - b``) as one line: its head and
    how many values of each kind (``robot 'arm6' to MJCF: 6 value(s) not written: 6
    actuator.csv peak_velocity``); a message without a list as it is."""
    head, sep, _ = str(message).partition("\n  - ")
    if not sep:
        return str(message)
    return f"{' '.join(head.split()).rstrip(':')}: {kind_counts(notes_of(message))}"
