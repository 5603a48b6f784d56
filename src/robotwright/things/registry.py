"""The ID registry: every Thing gets a process-wide unique integer ID on creation."""

from __future__ import annotations

import itertools
import threading
import weakref
from typing import Any


class Registry:
    """Hands out unique IDs and finds live Things by ID (weakly: it keeps nothing alive)."""

    def __init__(self) -> None:
        self._counter = itertools.count(1)
        self._lock = threading.Lock()
        self._things: weakref.WeakValueDictionary[int, Any] = weakref.WeakValueDictionary()

    def register(self, thing: Any) -> int:
        with self._lock:
            new_id = next(self._counter)
        self._things[new_id] = thing
        return new_id

    def get(self, thing_id: int) -> Any | None:
        """The live Thing with this ID, or None when it was garbage-collected."""
        return self._things.get(thing_id)

    def __len__(self) -> int:
        return len(self._things)


#: The global registry all Things take their ``ID`` from.
REGISTRY = Registry()

# Tree versions: a fresh number each time a tree changes, so caches keyed by it never
# confuse two trees or two states of one tree.
_VERSIONS = itertools.count(1)


def next_version() -> int:
    return next(_VERSIONS)


# Assets (materials, textures) live outside any tree; a change to one bumps this epoch so
# every World rebuilds on its next use.
_ASSET_EPOCH = [0]


def bump_asset_epoch() -> None:
    _ASSET_EPOCH[0] += 1


def asset_epoch() -> int:
    return _ASSET_EPOCH[0]
