"""Carry benchmarks/gpu_suite.py's wheels to a GPU machine that cannot download.

The GPU machine has Python 3.12 and torch, nothing else, no network; a call to it
carries at most 64 MiB. Here (with network):

    python tools/gpu_wheels.py prepare .gpu-wheels      # mjlab, MuJoCo (Warp), warp, ...

downloads the x86-64 CPython 3.12 wheels of the mjlab environment (torch and its CUDA
libraries left out: the machine has them), cuts files over :data:`PIECE` bytes into
``.partNN`` pieces and groups everything into batches of at most :data:`BATCH` bytes
(``batches.json``). Each device call carries one batch folder (``.gpu-wheels/batch-K``,
ignored by git) and, on the machine, the last one runs:

    python tools/gpu_wheels.py join .gpu-wheels && \\
      pip install --no-index --find-links .gpu-wheels/wheels -e ".[mjlab]" example-robot-data

``join`` puts the pieces back together and checks each wheel's SHA-256 against the one
recorded when it was cut.
"""

from __future__ import annotations

import argparse
import hashlib
import json
import shutil
import subprocess
import sys
from pathlib import Path

#: Largest piece of a wheel, and largest batch one device call carries [bytes].
PIECE = 30 * 2**20
BATCH = 60 * 2**20
#: What the mjlab sections of the suite need (the versions CI's 3.11 stage pins).
REQUIREMENTS = (
    "mjlab==1.6.0",
    "mujoco==3.11.0",
    "mujoco-warp==3.11.0",
    "example-robot-data",
    "setuptools>=77",
    "wheel",
)
#: Distributions the GPU machine has already (torch and what it brings).
PRESENT = ("torch", "nvidia_", "triton")


def _sha256(path: Path) -> str:
    h = hashlib.sha256()
    with path.open("rb") as fh:
        for block in iter(lambda: fh.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()


def cut(wheels: Path, out: Path, piece: int = PIECE, batch: int = BATCH) -> list[list[str]]:
    """Cut every file of ``wheels`` over ``piece`` bytes into pieces under ``out`` and
    group files and pieces into batches of at most ``batch`` bytes; writes
    ``out/batches.json`` (the batches, and each cut wheel's size and SHA-256)."""
    if piece > batch:
        raise ValueError(f"piece {piece} > batch {batch}")
    items: list[Path] = []
    cuts: dict[str, dict[str, object]] = {}
    for wheel in sorted(wheels.iterdir()):
        if wheel.stat().st_size <= piece:
            items.append(wheel)
            continue
        cuts[wheel.name] = {"size": wheel.stat().st_size, "sha256": _sha256(wheel)}
        with wheel.open("rb") as fh:
            for k, block in enumerate(iter(lambda: fh.read(piece), b"")):
                part = out / "pieces" / f"{wheel.name}.part{k:02d}"
                part.parent.mkdir(parents=True, exist_ok=True)
                part.write_bytes(block)
                items.append(part)
    batches: list[list[str]] = [[]]
    used = 0
    for item in sorted(items, key=lambda p: -p.stat().st_size):
        size = item.stat().st_size
        if used + size > batch and batches[-1]:
            batches.append([])
            used = 0
        batches[-1].append(item.name)
        used += size
    for k, names in enumerate(batches):
        folder = out / f"batch-{k}"
        folder.mkdir(parents=True, exist_ok=True)
        for name in names:
            src = wheels / name if (wheels / name).exists() else out / "pieces" / name
            shutil.copy2(src, folder / name)
    shutil.rmtree(out / "pieces", ignore_errors=True)
    (out / "batches.json").write_text(json.dumps({"batches": batches, "cut": cuts}, indent=1))
    return batches


def join(out: Path) -> Path:
    """Gather every batch folder's files into ``out/wheels``, rejoining cut wheels and
    checking their size and SHA-256; returns the wheel folder."""
    index = json.loads((out / "batches.json").read_text())
    wheels = out / "wheels"
    wheels.mkdir(exist_ok=True)
    found = {p.name: p for p in out.glob("batch-*/*")}
    for name, p in found.items():
        if ".part" not in name:
            shutil.copy2(p, wheels / name)
    for name, meta in index["cut"].items():
        parts = sorted(n for n in found if n.startswith(name + ".part"))
        target = wheels / name
        with target.open("wb") as fh:
            for n in parts:
                fh.write(found[n].read_bytes())
        if target.stat().st_size != meta["size"] or _sha256(target) != meta["sha256"]:
            target.unlink()
            raise SystemExit(f"join: {name}: pieces missing or damaged ({len(parts)} found)")
    return wheels


def prepare(out: Path) -> None:
    download = out / "download"
    download.mkdir(parents=True, exist_ok=True)
    cmd = [sys.executable, "-m", "pip", "download", "--dest", str(download)]
    cmd += ["--only-binary=:all:", "--python-version", "3.12", "--implementation", "cp"]
    cmd += ["--platform", "manylinux_2_28_x86_64", "--platform", "manylinux2014_x86_64"]
    cmd += ["--platform", "manylinux_2_17_x86_64", "--platform", "any", *REQUIREMENTS]
    subprocess.run(cmd, check=True)
    for wheel in download.iterdir():
        if wheel.name.lower().startswith(PRESENT):
            wheel.unlink()
    batches = cut(download, out)
    shutil.rmtree(download)
    print(f"{len(batches)} batches in {out}: carry {out}/batch-K (one a call)")


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("action", choices=("prepare", "join"))
    ap.add_argument("folder", type=Path)
    args = ap.parse_args(argv)
    if args.action == "prepare":
        prepare(args.folder)
    else:
        print(join(args.folder))
    return 0


if __name__ == "__main__":
    sys.exit(main())
