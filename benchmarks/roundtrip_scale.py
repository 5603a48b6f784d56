"""Round trip of large URDF trees: total time and MuJoCo's own URDF import, per size.

A tree of N links (link i hangs from link (i-1)//4, so MJCF's depth limit is far), each
with a box visual and collision geom, on revolute joints. Prints, per size, the time of
``roundtrip`` (5 configurations) and of one ``mujoco.MjModel.from_xml_path`` of the same
file, and their ratio. The round trip has MuJoCo import three models (the source, our
MJCF, our URDF); the three imports run at once, on threads, beside our own work, so past
a few thousand links MuJoCo's import of the source bounds it from below.

    python benchmarks/roundtrip_scale.py [N ...]      # default 500 1000 2500
"""

from __future__ import annotations

import logging
import sys
import tempfile
import time
import warnings
from pathlib import Path

import mujoco
from _machine import measured

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests" / "parsers"))
from test_roundtrip_scale import tree_urdf  # noqa: E402

from robotwright.proof.roundtrip.run import roundtrip  # noqa: E402


def main(sizes: list[int]) -> None:
    logging.getLogger("robotwright").setLevel(logging.ERROR)  # the per-file parse warnings
    print(f"MuJoCo {mujoco.__version__}")
    print(f"{'links':>7} {'roundtrip (s)':>14} {'MuJoCo URDF import (s)':>23} {'ratio':>6}  result")
    with tempfile.TemporaryDirectory() as tmp:
        for n in sizes:
            path = Path(tmp) / f"tree{n}.urdf"
            path.write_text(tree_urdf(n))
            t0 = time.perf_counter()
            mujoco.MjModel.from_xml_path(str(path))
            t_import = time.perf_counter() - t0
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                t0 = time.perf_counter()
                report = roundtrip(path, configs=5)
                t_rt = time.perf_counter() - t0
            result = "PASS" if report.ok else "FAIL"
            ratio = t_rt / t_import
            print(f"{n:>7} {t_rt:>14.2f} {t_import:>23.2f} {ratio:>6.1f}  {result}", flush=True)


if __name__ == "__main__":
    with measured(()):
        main([int(a) for a in sys.argv[1:]] or [500, 1000, 2500])
