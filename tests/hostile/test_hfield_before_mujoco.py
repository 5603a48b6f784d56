"""A height field declaring more samples than the asset limit is refused before MuJoCo's
XML reader runs: that reader allocates the declared samples as it reads the element
(7 GB resident for 30,000 x 30,000), so the check on the parsed model came too late.

MuJoCo's readers are replaced by ones that fail the test if called; every command that
reads an MJCF must still refuse the file with its one-line error, exit 2, nothing written.
"""

from __future__ import annotations

import random
from pathlib import Path

import mujoco
import pytest

from robotwright.cli import main

HFIELD = '<hfield name="{name}" nrow="{nrow}" ncol="{ncol}" size="1 1 0.1 0.1"/>'
SCENE = """<mujoco><asset>{asset}</asset>
<worldbody><geom type="hfield" hfield="{name}"/></worldbody></mujoco>"""
INCLUDED = "<mujoco><asset>{asset}</asset></mujoco>"
INCLUDING = """<mujoco><include file="assets.xml"/>
<worldbody><geom type="hfield" hfield="{name}"/></worldbody></mujoco>"""


def _sizes() -> list[tuple[int, int]]:
    """Declared (nrow, ncol) over the default limit, 512 MB (4 bytes a sample)."""
    sizes = [
        (11_314, 11_314),
        (30_000, 30_000),
        (100_000, 100_000),
        (2**31 - 1, 2**31 - 1),
        (1, 2**28),
    ]
    rng = random.Random(23)
    while len(sizes) < 9:
        nrow, ncol = rng.randint(1, 10**6), rng.randint(1, 10**6)
        if nrow * ncol * 4 > 512 * 10**6:
            sizes.append((nrow, ncol))
    return sizes


class _NoReader:
    """Stands in for ``mujoco.MjSpec``: any read fails the test."""

    @staticmethod
    def from_file(*args, **kwargs):
        raise AssertionError("MuJoCo's reader ran on a refused height field")

    from_string = from_file


def _commands(scene: Path, out: Path) -> dict[str, list[str]]:
    return {
        "convert": ["convert", str(scene), "-o", str(out / "o.xml")],
        "render": ["render", str(scene), "-o", str(out / "o.png")],
        "things": ["things", str(scene), str(out / "t.xml")],
    }


@pytest.mark.parametrize("command", ["convert", "render", "things"])
@pytest.mark.parametrize("included", [False, True], ids=["main", "include"])
@pytest.mark.parametrize(("nrow", "ncol"), _sizes())
def test_oversized_height_field_is_refused_before_mujoco_reads_it(
    nrow: int, ncol: int, included: bool, command: str, tmp_path: Path, monkeypatch, capsys
) -> None:
    folder = tmp_path / "in"
    folder.mkdir()
    asset = HFIELD.format(name="ground", nrow=nrow, ncol=ncol)
    scene = folder / "scene.xml"
    if included:
        (folder / "assets.xml").write_text(INCLUDED.format(asset=asset), encoding="utf-8")
        scene.write_text(INCLUDING.format(name="ground"), encoding="utf-8")
    else:
        scene.write_text(SCENE.format(asset=asset, name="ground"), encoding="utf-8")
    out = tmp_path / "out"
    out.mkdir()
    monkeypatch.setattr(mujoco, "MjSpec", _NoReader)
    code = main(_commands(scene, out)[command])
    err = capsys.readouterr().err
    assert code == 2, err
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: "), err
    assert '<hfield name="ground">: declares nrow x ncol' in err and "512 MB limit" in err
    assert ("assets.xml" if included else "scene.xml") in err  # the file declaring it
    assert list(out.iterdir()) == []


@pytest.mark.parametrize("nrow", [1, 100, 11_313])  # 11,313^2 x 4 bytes: just under 512 MB
def test_height_fields_within_the_limit_still_reach_mujoco(
    nrow: int, tmp_path: Path, monkeypatch, capsys
) -> None:
    scene = tmp_path / "scene.xml"
    scene.write_text(
        SCENE.format(asset=HFIELD.format(name="h", nrow=nrow, ncol=nrow), name="h"),
        encoding="utf-8",
    )
    monkeypatch.setattr(mujoco, "MjSpec", _NoReader)
    with pytest.raises(AssertionError, match="MuJoCo's reader ran"):
        main(["convert", str(scene), "-o", str(tmp_path / "o.xml")])
