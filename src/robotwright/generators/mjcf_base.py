"""``MJCFGeneratorBase``: MuJoCo XML output, simulator settings and the scene.

No ``<default>`` classes are written (seed): every element carries its own values, so a
generated file reads without resolving class inheritance.
"""

from __future__ import annotations

import os
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from typing import Any

from robotwright.errors import GeneratorError
from robotwright.generators.base import GeneratorBase
from robotwright.generators.xmlfmt import fmt_float, fmt_vec
from robotwright.hrdf.model import SimulatorConfig


@dataclass(frozen=True)
class SceneDefaults:
    """What ``add_scene`` uses where ``simulator_config`` says nothing.

    Lengths in metres; colours RGB(A) in 0..1; friction is MuJoCo's (sliding, torsional,
    rolling) triple.
    """

    floor_name: str = "floor"
    ground_type: str = "plane"
    #: plane half-sizes: 0 0 = infinite; the third value is the grid spacing for drawing.
    ground_size: tuple[float, float, float] = (0.0, 0.0, 0.05)
    ground_contype: int = 1
    ground_conaffinity: int = 1
    ground_friction: tuple[float, float, float] = (1.0, 0.005, 0.0001)
    texture_name: str = "groundplane"
    material_name: str = "groundplane"
    texture_rgb1: tuple[float, float, float] = (0.2, 0.3, 0.4)
    texture_rgb2: tuple[float, float, float] = (0.1, 0.2, 0.3)
    texture_mark_rgb: tuple[float, float, float] = (0.8, 0.8, 0.8)
    texture_size: int = 300
    texture_repeat: tuple[float, float] = (5.0, 5.0)
    material_reflectance: float = 0.2
    skybox_rgb1: tuple[float, float, float] = (0.3, 0.5, 0.7)
    skybox_rgb2: tuple[float, float, float] = (0.0, 0.0, 0.0)
    skybox_width: int = 512
    skybox_height: int = 3072
    light_pos: tuple[float, float, float] = (0.0, 0.0, 3.5)
    light_dir: tuple[float, float, float] = (0.0, 0.0, -1.0)
    headlight_diffuse: tuple[float, float, float] = (0.6, 0.6, 0.6)
    headlight_ambient: tuple[float, float, float] = (0.3, 0.3, 0.3)
    headlight_specular: tuple[float, float, float] = (0.0, 0.0, 0.0)
    haze: tuple[float, float, float, float] = (0.15, 0.25, 0.35, 1.0)
    azimuth: float = 160.0
    elevation: float = -20.0


#: The scene defaults; frozen, so ``add_scene`` can never change them for later calls.
DEFAULT_SCENE = SceneDefaults()

#: MJCF attributes whose value is the name of another element (prefixed with names).
REFERENCE_ATTRS: frozenset[str] = frozenset(
    {
        "joint", "joint1", "joint2", "jointinparent",
        "body", "body1", "body2",
        "site", "site1", "site2", "refsite", "cranksite", "slidersite", "sidesite",
        "tendon", "tendon1", "tendon2",
        "geom", "geom1", "geom2",
        "actuator", "objname", "refname", "instance",
        "mesh", "material", "texture", "hfield", "camera", "target", "flex",
    }
)  # fmt: skip

#: Namespace of named elements in ``<worldbody>`` and ``<asset>`` (other sections: one
#: namespace per section, e.g. every child of ``<actuator>`` is an actuator).
BODY_NAMESPACES: dict[str, str] = {
    "body": "body", "joint": "joint", "freejoint": "joint", "geom": "geom", "site": "site",
    "camera": "camera", "light": "light", "frame": "frame",
    "mesh": "mesh", "material": "material", "texture": "texture", "hfield": "hfield",
    "skin": "skin",
}  # fmt: skip

#: Top-level sections in the order they are written.
SECTION_ORDER: tuple[str, ...] = (
    "compiler", "option", "size", "extension", "visual", "statistic", "asset", "worldbody",
    "contact", "equality", "tendon", "actuator", "sensor", "keyframe",
)  # fmt: skip


def prefix_tree(elem: ET.Element, prefix: str | None) -> None:
    """Prefix every ``name`` and every name reference under ``elem`` (in place)."""
    if not prefix:
        return
    for node in elem.iter():
        for attr in ("name", *REFERENCE_ATTRS):
            value = node.get(attr)
            if value is not None and not (attr == "name" and node.tag in _UNPREFIXED_NAME_TAGS):
                node.set(attr, f"{prefix}_{value}")


# Elements whose "name" is not a MuJoCo object name (none today; kept explicit).
_UNPREFIXED_NAME_TAGS: frozenset[str] = frozenset()


def name_clashes(root: ET.Element) -> dict[str, list[str]]:
    """Names used more than once within one MuJoCo namespace: ``{namespace: [names]}``."""
    seen: set[tuple[str, str]] = set()
    dups: set[tuple[str, str]] = set()
    for section in root:
        tag = section.tag
        body_like = tag in ("worldbody", "asset")
        for node in section.iter():
            name = node.get("name")
            if name is None or node is section:
                continue
            if body_like:
                ns = BODY_NAMESPACES.get(node.tag)
                if ns is None:
                    continue
            else:
                ns = node.tag if tag == "contact" else tag
            key = (ns, name)
            if key in seen:
                dups.add(key)
            else:
                seen.add(key)
    out: dict[str, list[str]] = {}
    for ns, name in sorted(dups):
        out.setdefault(ns, []).append(name)
    return out


def fill_option(option: ET.Element, sim: SimulatorConfig) -> None:
    """Set ``sim.option``'s attributes on ``option`` and add its ``<flag>`` switches
    (names and values were checked against :mod:`robotwright.hrdf.options` at load)."""
    for key, value in sorted(sim.option.items()):
        if isinstance(value, str):
            option.set(key, value)
        elif isinstance(value, int) and not isinstance(value, bool):
            option.set(key, str(value))
        elif isinstance(value, (list, tuple)):
            option.set(key, fmt_vec(value))
        else:
            option.set(key, fmt_float(value))
    if sim.flag:
        ET.SubElement(option, "flag", dict(sorted(sim.flag.items())))


class MJCFGeneratorBase(GeneratorBase):
    """Base of MJCF generators: holds ``simulator_config`` and adds the scene.

    Attributes:
        simulator_config: timestep (s), gravity (m/s^2), integrator and ground; written
            to ``<option>`` and used by ``add_scene``. ``None`` = MuJoCo's defaults.
    """

    def __init__(self, simulator_config: SimulatorConfig | None = None, **kwargs: Any) -> None:
        super().__init__(**kwargs)
        self.simulator_config = simulator_config
        # A composite checks names once on the merged tree, not in each robot.
        self._check_names = True

    def _xml_root_init(self) -> ET.Element:
        return ET.Element("mujoco", {"model": self._model_name()})

    def _model_name(self) -> str:
        return "robot"

    # -- sections -----------------------------------------------------------------------
    def add_compiler(self) -> ET.Element:
        """``<compiler angle="radian">``: every angle we write is in radians."""
        compiler = self.get_elem("compiler")
        compiler.set("angle", "radian")
        return compiler

    def add_option(self) -> ET.Element:
        """``<option>`` from ``simulator_config`` (only the values it sets)."""
        option = self.get_elem("option")
        sim = self.simulator_config
        if sim is not None:
            if sim.timestep is not None:
                option.set("timestep", fmt_float(sim.timestep))
            if sim.gravity is not None:
                option.set("gravity", fmt_vec(sim.gravity))
            if sim.integrator is not None:
                option.set("integrator", sim.integrator)
            fill_option(option, sim)
        return option

    def add_scene(self, skybox: bool = True) -> None:
        """Add a ground (from ``simulator_config.ground``, else :data:`DEFAULT_SCENE`), a
        directional light, a checker material for the ground, head light settings and
        optionally a gradient skybox. Scene names (``floor``, ``groundplane``) are not
        prefixed: a scene is added once per file."""
        d = DEFAULT_SCENE
        ground = self.simulator_config.ground if self.simulator_config is not None else None
        gtype = ground.type if ground is not None and ground.type is not None else d.ground_type
        if gtype != "plane":
            raise GeneratorError(
                f"simulator_config.ground.type '{gtype}': only 'plane' grounds are supported"
            )
        contype = d.ground_contype
        conaffinity = d.ground_conaffinity
        friction = d.ground_friction
        if ground is not None:
            if ground.contact_type is not None:
                contype = ground.contact_type
            if ground.contact_affinity is not None:
                conaffinity = ground.contact_affinity
            if ground.friction is not None:
                friction = (ground.friction, *d.ground_friction[1:])

        visual = self.get_elem("visual")
        ET.SubElement(
            visual,
            "headlight",
            {
                "diffuse": fmt_vec(d.headlight_diffuse),
                "ambient": fmt_vec(d.headlight_ambient),
                "specular": fmt_vec(d.headlight_specular),
            },
        )
        ET.SubElement(visual, "rgba", {"haze": fmt_vec(d.haze)})
        ET.SubElement(
            visual,
            "global",
            {"azimuth": fmt_float(d.azimuth), "elevation": fmt_float(d.elevation)},
        )
        asset = self.get_elem("asset")
        if skybox:
            ET.SubElement(
                asset,
                "texture",
                {
                    "type": "skybox",
                    "builtin": "gradient",
                    "rgb1": fmt_vec(d.skybox_rgb1),
                    "rgb2": fmt_vec(d.skybox_rgb2),
                    "width": str(d.skybox_width),
                    "height": str(d.skybox_height),
                },
            )
        ET.SubElement(
            asset,
            "texture",
            {
                "name": d.texture_name,
                "type": "2d",
                "builtin": "checker",
                "mark": "edge",
                "rgb1": fmt_vec(d.texture_rgb1),
                "rgb2": fmt_vec(d.texture_rgb2),
                "markrgb": fmt_vec(d.texture_mark_rgb),
                "width": str(d.texture_size),
                "height": str(d.texture_size),
            },
        )
        ET.SubElement(
            asset,
            "material",
            {
                "name": d.material_name,
                "texture": d.texture_name,
                "texuniform": "true",
                "texrepeat": fmt_vec(d.texture_repeat),
                "reflectance": fmt_float(d.material_reflectance),
            },
        )
        worldbody = self.get_elem("worldbody")
        ET.SubElement(
            worldbody,
            "light",
            {"pos": fmt_vec(d.light_pos), "dir": fmt_vec(d.light_dir), "directional": "true"},
        )
        ET.SubElement(
            worldbody,
            "geom",
            {
                "name": d.floor_name,
                "type": gtype,
                "size": fmt_vec(d.ground_size),
                "material": d.material_name,
                "contype": str(contype),
                "conaffinity": str(conaffinity),
                "friction": fmt_vec(friction),
            },
        )

    # -- post-processing ----------------------------------------------------------------
    def _layout_meshes(self, relative: bool) -> None:
        """Rebase mesh files on their common folder: ``<compiler meshdir>`` = that folder
        (relative to ``output_dir`` when asked), each ``file`` relative to it.

        Expects every ``<mesh file>`` to hold an absolute path (as generation writes them).
        """
        asset = self.xml_root.find("asset")
        meshes = [] if asset is None else [m for m in asset.findall("mesh") if m.get("file")]
        if not meshes:
            return
        files = [m.get("file", "") for m in meshes]
        if self._mesh_copy:
            files = [self._mesh_file(f) for f in files]
        common = os.path.commonpath({os.path.dirname(f) for f in files})
        head = common.rstrip("/") + "/"
        for elem, f in zip(meshes, files, strict=True):
            rel = f[len(head) :] if f.startswith(head) else os.path.relpath(f, common)
            elem.set("file", rel.replace(os.sep, "/"))
        self.get_elem("compiler").set("meshdir", self._reference(common, relative))

    def _order_sections(self) -> None:
        """Drop empty top-level sections and put the rest in :data:`SECTION_ORDER`."""
        root = self.xml_root
        children = [c for c in root if len(c) or c.attrib]
        rank = {tag: i for i, tag in enumerate(SECTION_ORDER)}
        children.sort(key=lambda c: rank.get(c.tag, len(rank)))
        for c in list(root):
            root.remove(c)
        root.extend(children)

    # -- MuJoCo objects -----------------------------------------------------------------
    def to_spec(self, **kwargs: Any) -> Any:
        """The generated model as a ``mujoco.MjSpec`` (mesh paths absolute)."""
        import mujoco

        kwargs.setdefault("relative_mesh_path", False)
        return mujoco.MjSpec.from_string(self.export(None, **kwargs))

    def to_model(self, **kwargs: Any) -> Any:
        """The generated model compiled: a ``mujoco.MjModel``."""
        return self.to_spec(**kwargs).compile()
