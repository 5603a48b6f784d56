"""RawElement: an MJCF actuator or sensor kept verbatim because no Thing models it."""

from __future__ import annotations

from typing import Any

from robotwright.things.attrs import Choice, Text
from robotwright.things.base import BaseThing

_RAW_ATTR: dict[str, Any] = {"section": Choice("actuator", "sensor"), "xml": Text(optional=False)}


class RawElement(BaseThing):
    """One element of the ``<actuator>`` or ``<sensor>`` section, as MJCF text.

    Reading MJCF creates these for actuators/sensors whose targets Things do not model
    (tendons, ...), so that their place in ``ctrl``/``sensordata`` is kept. They are
    attached to the World and written in creation order with the other actuators/sensors.
    """

    _NAMESPACE = "raw"
    _NEW_MUJOCO_ATTR = _RAW_ATTR
    _NEW_BLUEPRINTS_ATTR = _RAW_ATTR
    _NEW_DEFAULT_VALS = {"section": "actuator", "xml": ""}

    def __init__(self, name: str | None = None, parent: BaseThing | None = None, **kwargs: Any):
        super().__init__(name=name, parent=parent, **kwargs)
