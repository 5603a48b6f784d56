#!/usr/bin/env python
"""Parse time of the Unitree G1 MJCF (mjlab) and G1 URDF (example-robot-data): ours vs
hurodes' parsers (run in their own interpreter via --hurodes-python), same files, one run.
The URDF is given to both as a plain copy (relative mesh paths), since hurodes' URDF
parser cannot resolve ``package://``. Timing covers the parse into an in-memory model
(hurodes: ``parse()``; ours: ``*_to_hrdf``), not writing folders.

Prints the median of --repeat runs for each side and the ratio hurodes / ours.
Usage: python benchmarks/parsers.py --hurodes-python .testdata/hurodes-venv/bin/python
"""

from __future__ import annotations

import argparse
import json
import logging
import statistics
import subprocess
import sysconfig
import time
from pathlib import Path

from _machine import measured, print_peer

ROOT = Path(__file__).resolve().parents[1]
G1_MJCF = ROOT / ".testdata/mjlab/mjlab/asset_zoo/robots/unitree_g1/xmls/g1.xml"
G1_URDF = (
    Path(sysconfig.get_paths()["purelib"])
    / "cmeel.prefix/share/example-robot-data/robots/g1_description/urdf/g1_29dof_rev_1_0.urdf"
)

HURODES = r"""
import json, sys, time, statistics
from hurodes.parsers.mjcf_parser import HumanoidMJCFParser
from hurodes.parsers.urdf_mujoco_parser import HumanoidURDFMujocoParser
kind, path, repeat = sys.argv[1], sys.argv[2], int(sys.argv[3])
cls = HumanoidMJCFParser if kind == "mjcf" else HumanoidURDFMujocoParser
times = []
for _ in range(repeat):
    t = time.perf_counter()
    p = cls(path, "g1_bench")
    p.parse(base_link_name="pelvis")
    times.append(time.perf_counter() - t)
print(json.dumps(times))
"""


def plain_urdf_copy(src: Path, dest_root: Path) -> Path:
    """The G1 URDF as hurodes can read it: ``urdf/`` + ``meshes/`` folders (meshes copied)
    and mesh file names relative (hurodes' URDF path cannot resolve ``package://``)."""
    import re
    import shutil

    mesh_src = src.parent.parent / "meshes"
    shutil.copytree(mesh_src, dest_root / "meshes")
    (dest_root / "urdf").mkdir()
    text = re.sub(r'filename="[^"]*/meshes/', 'filename="../meshes/', src.read_text())
    out = dest_root / "urdf" / src.name
    out.write_text(text)
    return out


def ours(kind: str, path: Path, repeat: int) -> list[float]:
    from robotwright.parsers import mjcf_to_hrdf, urdf_to_hrdf

    fn = mjcf_to_hrdf if kind == "mjcf" else urdf_to_hrdf
    times = []
    for _ in range(repeat):
        t = time.perf_counter()
        fn(path)
        times.append(time.perf_counter() - t)
    return times


def hurodes(python: str, kind: str, path: Path, repeat: int) -> list[float] | str:
    proc = subprocess.run(
        [python, "-c", HURODES, kind, str(path), str(repeat)], capture_output=True, text=True
    )
    if proc.returncode != 0:
        return "failed: " + (proc.stderr.strip().splitlines() or ["?"])[-1][:150]
    return json.loads(proc.stdout.strip().splitlines()[-1])


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--hurodes-python", default=None)
    ap.add_argument("--repeat", type=int, default=7)
    args = ap.parse_args()
    print_peer(args.hurodes_python, "hurodes")
    logging.getLogger("robotwright.parsers").setLevel(logging.ERROR)
    import tempfile

    tmp = tempfile.TemporaryDirectory(prefix="robotwright-bench-")
    urdf = plain_urdf_copy(G1_URDF, Path(tmp.name)) if G1_URDF.is_file() else G1_URDF
    for kind, path in (("mjcf", G1_MJCF), ("urdf", urdf)):
        if not path.is_file():
            print(f"{kind}: {path} absent, skipped")
            continue
        ours_t = statistics.median(ours(kind, path, args.repeat))
        line = f"G1 {kind.upper()}: ours median {ours_t * 1e3:.1f} ms"
        if args.hurodes_python:
            h = hurodes(args.hurodes_python, kind, path, args.repeat)
            if isinstance(h, str):
                line += f"; hurodes {h}"
            else:
                ht = statistics.median(h)
                line += f"; hurodes median {ht * 1e3:.1f} ms; hurodes/ours = {ht / ours_t:.2f}x"
        print(line)
    tmp.cleanup()
    return 0


if __name__ == "__main__":
    with measured():
        raise SystemExit(main())
