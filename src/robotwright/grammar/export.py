"""Write a design's files: MJCF and URDF (through the generators), design text and JSON,
design tree as Graphviz DOT, and a PNG picture. All or nothing: files are written into
a temporary folder that is renamed into place."""

from __future__ import annotations

import warnings
from pathlib import Path

from robotwright._atomic import atomic_dir
from robotwright._names import file_stem
from robotwright.errors import ConversionWarning
from robotwright.grammar.build import Limb, build
from robotwright.grammar.derive import replay
from robotwright.grammar.design import Design, to_dot
from robotwright.grammar.draw import display_pose, draw_limb
from robotwright.grammar.rules import Grammar
from robotwright.hrdf.model import HRDF


def export_mjcf(hrdf: HRDF, path: Path) -> None:
    """MJCF of a robot through :class:`robotwright.generators.MJCFHumanoidGenerator`."""
    from robotwright.generators import MJCFHumanoidGenerator

    MJCFHumanoidGenerator.from_hrdf(hrdf).export(path)


def export_urdf(hrdf: HRDF, path: Path) -> None:
    """URDF of a robot through :class:`robotwright.generators.URDFHumanoidGenerator`,
    with the ``<mujoco>`` tag so that MuJoCo loads it as written (several joints on one
    body become a chain of near-massless links, as URDF needs)."""
    from robotwright.generators import URDFHumanoidGenerator

    URDFHumanoidGenerator.from_hrdf(hrdf).export(path, add_mujoco_tag=True)


def export_design(
    grammar: Grammar,
    design: Design,
    out_dir: str | Path,
    *,
    name: str = "srl",
    picture: bool = True,
    overwrite: bool = False,
) -> Path:
    """Write ``out_dir`` with ``<name>.xml`` (MJCF), ``<name>.urdf`` (``name`` made a safe
    file name, :func:`~robotwright._names.file_stem`), ``design.txt``,
    ``design.json``, ``tree.dot`` and ``picture.png`` (if ``picture``).

    What a format cannot hold (for example actuator peak velocity in MJCF) is reported
    by the generators as a ``ConversionWarning``; those messages are also written to
    ``warnings.txt`` so that nothing is lost silently.

    Returns:
        ``out_dir``. Raises ``FileExistsError`` when it exists and not ``overwrite``.
    """
    out = Path(out_dir)
    if out.exists() and not overwrite:
        raise FileExistsError(f"{out} exists; pass overwrite=True to replace it")
    tree = replay(grammar, design)
    limb: Limb = build(grammar, design, name=name)
    hrdf = limb.to_hrdf()
    with atomic_dir(out, kind="design") as tmp:  # replaces only a design output
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always", ConversionWarning)
            stem = file_stem(name, "srl")
            export_mjcf(hrdf, tmp / f"{stem}.xml")
            export_urdf(hrdf, tmp / f"{stem}.urdf")
        for w in caught:
            if not issubclass(w.category, ConversionWarning):
                warnings.warn_explicit(w.message, w.category, w.filename, w.lineno)
        notes = [str(w.message) for w in caught if issubclass(w.category, ConversionWarning)]
        if notes:
            (tmp / "warnings.txt").write_text("\n".join(notes) + "\n", encoding="utf-8")
        (tmp / "design.txt").write_text(design.to_text(), encoding="utf-8")
        (tmp / "design.json").write_text(design.to_json() + "\n", encoding="utf-8")
        (tmp / "tree.dot").write_text(to_dot(tree, design.hash()), encoding="utf-8")
        if picture:
            draw_limb(
                limb,
                tmp / "picture.png",
                q=display_pose(limb),
                title=f"{name}, design {design.hash()} (revolute at +-0.5 rad, "
                "prismatic at mid-stroke)",
            )
    return out
