"""Close-name suggestions for unknown names (robots, bodies, sites, objectives)."""

from __future__ import annotations

from collections.abc import Iterable

__all__ = ["close_names", "did_you_mean"]


def close_names(name: str, candidates: Iterable[str], n: int = 3) -> list[str]:
    """Up to ``n`` candidates close to ``name``: those that contain it or end with it
    (``head_lidar`` -> ``mini_humanoid_head_lidar``, the prefixed name a composite
    writes), then difflib's close matches; case-insensitive, in that order."""
    import difflib  # only when a name is unknown: not on every start-up

    names = sorted({c for c in candidates if c})
    key = name.lower()
    if not key:
        return []
    contained = sorted(
        (c for c in names if key in c.lower() and c.lower() != key),
        key=lambda c: (not c.lower().endswith(key), len(c), c),
    )
    lowered = {c.lower(): c for c in names}
    fuzzy = [lowered[c] for c in difflib.get_close_matches(key, list(lowered), n=n, cutoff=0.6)]
    return list(dict.fromkeys(contained + fuzzy))[:n]


def did_you_mean(name: str, candidates: Iterable[str], n: int = 3) -> str:
    """``"; did you mean 'a' or 'b'?"`` for the close names, or ``""`` when none is close."""
    close = close_names(name, candidates, n)
    if not close:
        return ""
    quoted = [repr(c) for c in close]
    listed = quoted[0] if len(quoted) == 1 else f"{', '.join(quoted[:-1])} or {quoted[-1]}"
    return f"; did you mean {listed}?"
