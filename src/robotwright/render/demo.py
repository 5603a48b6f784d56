"""The demo's pictures: each robot, the furnished scene, and the scene with its scan."""

from __future__ import annotations

import warnings
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from robotwright.errors import ConversionWarning
from robotwright.render.core import RenderOptions, render_model
from robotwright.render.png import save_png
from robotwright.render.scan import render_scan

__all__ = ["demo_pictures"]

#: The demo pictures' size [px]: small enough for a quick demo, large enough to read.
SIZE = (640, 480)
#: The scene is seen from above the south-east corner, close enough that the robots
#: are not lost in the room (its far walls are cut by the frame).
SCENE_CAMERA = "135,-50,7.5"


def demo_pictures(
    out: Path,
    ctx: Mapping[str, Any],
    scan_npz: Path,
    mapping: Mapping[str, Sequence[str]],
) -> str:
    """Write ``<robot>.png`` for each robot of ``ctx`` (``mini_humanoid``, ``arm6``,
    ``wearer``: the humanoid with its limb), ``scene.png`` and ``scene_lidar.png``
    into ``out``; return a one-line summary naming the renderer that drew them."""
    from robotwright.generators import MJCFHumanoidGenerator

    out.mkdir(parents=True, exist_ok=True)
    w, h = SIZE
    # The limb is worn on the back: that picture is taken from behind, to the right.
    views = {
        "mini_humanoid": ("mini_humanoid (bundled robot)", "iso"),
        "arm6": ("arm6 (bundled robot)", "iso"),
        "wearer": ("mini_humanoid wearing the grammar-generated limb (from behind)", "-35,-20"),
    }
    written, backends = [], set()
    for key, (title, camera) in views.items():
        with warnings.catch_warnings():
            # The export step already reported what MJCF cannot hold for these robots;
            # the same notes again would only double the demo's list.
            warnings.simplefilter("ignore", ConversionWarning)
            model = MJCFHumanoidGenerator.from_hrdf(ctx[key]).to_model()
        picture = render_model(model, None, RenderOptions(width=w, height=h, camera=camera))
        name = "humanoid_with_limb.png" if key == "wearer" else f"{key}.png"
        save_png(picture, out / name, title=title)
        written.append(name)
        backends.add(picture.backend)
    model, data = ctx["scene_model"], ctx["scene_data"]
    scene_opts = RenderOptions(width=w, height=h, camera=SCENE_CAMERA)
    picture = render_model(model, data, scene_opts)
    save_png(picture, out / "scene.png", title="Composed scene: two robots among furniture")
    backends.add(picture.backend)
    with np.load(scan_npz, allow_pickle=False) as npz:
        points, labels = npz["points"], npz["labels"]
        names = [str(n) for n in npz["class_names"]]
    picture = render_scan(
        model,
        data,
        points,
        labels,
        names,
        out / "scene_lidar.png",
        scene_opts,
        mapping=mapping,
        title="Semantic LiDAR points in the scene (hidden behind surfaces)",
    )
    backends.add(picture.backend)
    written += ["scene.png", "scene_lidar.png"]
    return f"{', '.join(written)} ({' and '.join(sorted(backends))} renderer)"
