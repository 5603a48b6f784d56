"""Benchmark: one picture of a robot and of a scene, MuJoCo's OpenGL renderer vs the
numpy software renderer (``robotwright.render``), on the same model, camera and size.

The OpenGL row is left out where no off-screen platform starts. Prints medians (ms) of
``render_model`` (scene update, drawing, read-back; no PNG encoding) and the ratio.

Run: ``python benchmarks/render.py [--size 800x600] [--repeats 5] [--scene FILE.xml]``
(without ``--scene`` only the bundled robots are timed; the demo writes
``robotwright_demo/scene/semantic_scene.xml``).
"""

from __future__ import annotations

import argparse
import statistics
import time
import warnings

import mujoco
from _machine import measured

from robotwright.errors import ConversionWarning
from robotwright.render import RenderError, RenderOptions, load_model, render_model


def median_ms(fn, repeats: int) -> float:
    fn()  # warm-up: imports, caches, the GL library
    samples = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        fn()
        samples.append(time.perf_counter() - t0)
    return statistics.median(samples) * 1e3


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--size", default="800x600")
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--scene", help="an MJCF scene to time as well")
    args = parser.parse_args()
    width, height = (int(v) for v in args.size.lower().split("x"))
    sources = ["mini_humanoid", "arm6"] + ([args.scene] if args.scene else [])
    print(
        f"{'model':28s} {'mesh faces':>10s} {'software [ms]':>14s} {'OpenGL [ms]':>12s} {'ratio':>6s}"
    )
    for source in sources:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", ConversionWarning)
            loaded = load_model(source)
        model, data = loaded.model, loaded.initial_data()
        soft = RenderOptions(width=width, height=height, backend="software")
        t_soft = median_ms(lambda: render_model(model, data, soft), args.repeats)  # noqa: B023
        gl = RenderOptions(width=width, height=height, backend="gl")
        try:
            backend = render_model(model, data, gl).backend
            t_gl = median_ms(lambda: render_model(model, data, gl), args.repeats)  # noqa: B023
        except RenderError:
            backend, t_gl = "none", None
        faces = int(model.mesh_facenum.sum()) if model.nmesh else 0
        gl_txt = f"{t_gl:12.1f}" if t_gl is not None else f"{'n/a':>12s}"
        ratio = f"{t_soft / t_gl:5.1f}x" if t_gl else f"{'n/a':>6s}"
        name = loaded.title[:28]
        print(f"{name:28s} {faces:10d} {t_soft:14.1f} {gl_txt} {ratio}  ({backend})")
    print(f"MuJoCo {mujoco.__version__}, {width}x{height} pixels")


if __name__ == "__main__":
    with measured(()):
        main()
