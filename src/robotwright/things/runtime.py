"""Reading simulation state of a compiled World back through its Things."""

from __future__ import annotations

from typing import Any

from robotwright.things.attrs import ThingAttributeError


def sim_index(thing: Any) -> tuple[Any, Any, int]:
    """(model, data, id in the model) of a Thing inside a built World.

    Builds the World first when its tree changed since the last build.
    """
    world = thing.root
    if not hasattr(world, "_ensure_built"):
        raise ThingAttributeError(
            f"{thing._label()} is not inside a World; attach it to one to simulate it"
        )
    model, data, index = world._ensure_built()
    try:
        return model, data, index[thing.ID]
    except KeyError:
        raise ThingAttributeError(
            f"{thing._label()} has no element in the compiled model"
        ) from None
