"""tools/gpu_wheels.py: wheels cut into pieces and batches small enough for one device
call each, and put back together byte for byte (a damaged piece is refused)."""

from __future__ import annotations

import importlib.util
import json
import os
from pathlib import Path

import pytest

_SPEC = importlib.util.spec_from_file_location(
    "gpu_wheels", Path(__file__).resolve().parents[1] / "tools" / "gpu_wheels.py"
)
gpu_wheels = importlib.util.module_from_spec(_SPEC)
_SPEC.loader.exec_module(gpu_wheels)


def _wheels(folder: Path) -> dict[str, bytes]:
    folder.mkdir()
    sizes = {"big-1.0-py3-none-any.whl": 2500, "mid-1.0-py3-none-any.whl": 900}
    sizes |= {f"small{k}-1.0-py3-none-any.whl": 100 + k for k in range(5)}
    made = {}
    for name, size in sizes.items():
        made[name] = os.urandom(size)
        (folder / name).write_bytes(made[name])
    return made


def test_cut_batches_stay_under_the_limit_and_join_restores_every_wheel(tmp_path) -> None:
    made = _wheels(tmp_path / "dl")
    out = tmp_path / "carry"
    batches = gpu_wheels.cut(tmp_path / "dl", out, piece=1000, batch=1200)
    assert len(batches) > 1
    for k in range(len(batches)):
        folder = out / f"batch-{k}"
        assert sum(p.stat().st_size for p in folder.iterdir()) <= 1200
        assert all(p.stat().st_size <= 1000 for p in folder.iterdir())
    index = json.loads((out / "batches.json").read_text())
    assert set(index["cut"]) == {"big-1.0-py3-none-any.whl"}
    wheels = gpu_wheels.join(out)
    assert {p.name: p.read_bytes() for p in wheels.iterdir()} == made


def test_a_damaged_piece_is_refused(tmp_path) -> None:
    _wheels(tmp_path / "dl")
    out = tmp_path / "carry"
    gpu_wheels.cut(tmp_path / "dl", out, piece=1000, batch=1200)
    piece = next(out.glob("batch-*/big-1.0-py3-none-any.whl.part01"))
    piece.write_bytes(b"x" + piece.read_bytes()[1:])
    with pytest.raises(SystemExit, match="damaged"):
        gpu_wheels.join(out)
    assert not (out / "wheels" / "big-1.0-py3-none-any.whl").exists()
