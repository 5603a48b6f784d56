"""Cost of the proof of a conversion: ``convert`` with and without it, on one robot.

The proof compiles the source and the output with MuJoCo and compares every per-object
array (see :mod:`robotwright.proof.compare`); issue 20 keeps ``convert`` within 1.5x of
its time without it. Prints the median of each over ``--repeat`` runs (each in a fresh
temporary folder, after one warm-up of each) and their ratio.

    python benchmarks/convert_proof.py                         # the G1 (29 DoF), as HRDF
    python benchmarks/convert_proof.py SRC --asset-root DIR --out out.xml --repeat 5
"""

from __future__ import annotations

import argparse
import logging
import statistics
import tempfile
import time
import warnings
from pathlib import Path

from _machine import measured

from robotwright._paths import trusted_asset_roots
from robotwright.proof.convert import convert

ROOT = Path(__file__).resolve().parents[1]
G1 = ROOT / ".testdata" / "hurodes-fixtures" / "sources" / "g1_29.xml"


def _once(src: Path, out: str, proof: bool, asset_root: Path | None) -> float:
    with tempfile.TemporaryDirectory(prefix="convert-proof-") as tmp:
        t0 = time.perf_counter()
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            if asset_root is None:
                convert(src, Path(tmp) / out, proof=proof)
            else:
                with trusted_asset_roots((asset_root,)):
                    convert(src, Path(tmp) / out, proof=proof)
        return time.perf_counter() - t0


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("src", nargs="?", default=str(G1))
    p.add_argument("--asset-root", default=str(ROOT / ".testdata" / "mjlab"))
    p.add_argument("--out", default="robot", help="output name: folder (HRDF), .xml, .urdf")
    p.add_argument("--repeat", type=int, default=5)
    args = p.parse_args()
    logging.disable(logging.WARNING)
    src, root = Path(args.src), Path(args.asset_root) if args.asset_root else None
    times: dict[bool, list[float]] = {False: [], True: []}
    for proof in (False, True):
        _once(src, args.out, proof, root)  # warm-up: imports, file cache
    for _ in range(args.repeat):
        for proof in (False, True):  # interleaved: a load change hits both alike
            times[proof].append(_once(src, args.out, proof, root))
    off, on = statistics.median(times[False]), statistics.median(times[True])
    print(f"source: {src} -> {args.out}  ({args.repeat} runs each, median)")
    print(
        f"convert without proof  {off:8.3f} s   (runs: {', '.join(f'{t:.2f}' for t in times[False])})"
    )
    print(
        f"convert with proof     {on:8.3f} s   (runs: {', '.join(f'{t:.2f}' for t in times[True])})"
    )
    print(f"ratio                  {on / off:8.2f}x")


if __name__ == "__main__":
    with measured(("trimesh",)):
        main()
