"""HRDF: the folder-based robot description (hurodes-compatible, extended)."""

from typing import TYPE_CHECKING

from robotwright._lazy import attach

if TYPE_CHECKING:
    from robotwright.hrdf.model import (
        ACTUATOR_TYPES,
        FORMAT_VERSION,
        FRAME_OBJTYPES,
        HRDF,
        JOINT_TYPES,
        SENSOR_OBJTYPES,
        SIMPLE_GEOM_TYPES,
        Actuator,
        Body,
        BodyNameConfig,
        Geom,
        GroundConfig,
        ImuConfig,
        Joint,
        MeshGeom,
        Meta,
        Sensor,
        SimpleGeom,
        SimulatorConfig,
        Site,
    )

__all__ = [
    "ACTUATOR_TYPES",
    "FORMAT_VERSION",
    "FRAME_OBJTYPES",
    "HRDF",
    "JOINT_TYPES",
    "SENSOR_OBJTYPES",
    "SIMPLE_GEOM_TYPES",
    "Actuator",
    "Body",
    "BodyNameConfig",
    "Geom",
    "GroundConfig",
    "ImuConfig",
    "Joint",
    "MeshGeom",
    "Meta",
    "Sensor",
    "SimpleGeom",
    "SimulatorConfig",
    "Site",
]

attach(__name__, __file__)
