"""Hostile input to the inertia of URDF links without ``<inertial>`` (computed by MuJoCo
from their collision geoms): bad ``--density`` / ``density=`` values, geom sizes from
zero to overflow, degenerate and escaping meshes. Each is either converted with finite
values equal to MuJoCo's own URDF import, or refused in one line naming the link (exit
2, nothing written, no traceback); never a non-finite mass written.
"""

from __future__ import annotations

import math
import random
import struct
import subprocess
import sys
from pathlib import Path

import mujoco
import numpy as np
import pytest

from robotwright.errors import RobotwrightError
from robotwright.parsers import URDFOptions
from robotwright.parsers.api import urdf_to_hrdf_with_warnings

BAD_DENSITIES = ["0", "-1", "-0", "nan", "NaN", "inf", "-inf", "1e400", "1e-400", "abc", "", "1,5"]


def _run(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run(
        [sys.executable, "-m", "robotwright", *args], capture_output=True, text=True, timeout=300
    )


def _robot(folder: Path, geoms: str, joint: str = "revolute") -> Path:
    folder.mkdir(parents=True, exist_ok=True)
    limit = '<limit lower="-1" upper="1" effort="0" velocity="0"/>' if joint == "revolute" else ""
    text = (
        '<robot name="h"><link name="base"><inertial><mass value="1"/>'
        '<inertia ixx="1" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/></inertial></link>'
        f'<link name="arm">{geoms}</link>'
        f'<joint name="j" type="{joint}"><parent link="base"/><child link="arm"/>'
        f'<axis xyz="0 0 1"/>{limit}</joint></robot>'
    )
    path = folder / "h.urdf"
    path.write_text(text)
    return path


def _collision(shape: str) -> str:
    return f"<collision><geometry>{shape}</geometry></collision>"


def _one_line_error(done: subprocess.CompletedProcess) -> None:
    assert done.returncode == 2, done.stderr
    assert "Traceback" not in done.stderr
    assert "error" in done.stderr


@pytest.mark.parametrize("value", BAD_DENSITIES)
def test_bad_density_on_the_command_line(value: str, tmp_path: Path) -> None:
    path = _robot(tmp_path / "r", _collision('<box size="0.1 0.1 0.1"/>'))
    out = tmp_path / "out.xml"
    done = _run("convert", str(path), "-o", str(out), f"--density={value}")
    _one_line_error(done)
    assert "--density" in done.stderr
    assert not out.exists()


@pytest.mark.parametrize("value", ["sometimes", "", "AUTO", "never;rm", "0"])
def test_bad_mode_on_the_command_line(value: str, tmp_path: Path) -> None:
    path = _robot(tmp_path / "r", _collision('<box size="0.1 0.1 0.1"/>'))
    out = tmp_path / "out.xml"
    done = _run("convert", str(path), "-o", str(out), f"--inertia-from-geoms={value}")
    _one_line_error(done)
    assert not out.exists()


@pytest.mark.parametrize(
    "value", [0, -1.0, -0.0, math.nan, math.inf, -math.inf, 1e-400, "x", None, [1000.0]]
)
def test_bad_density_in_the_api(value) -> None:
    with pytest.raises(ValueError, match="density"):
        URDFOptions(density=value)


def _mujoco_mass(path: Path) -> float:
    text = path.read_text().replace(
        '<robot name="h">', '<robot name="h"><mujoco><compiler fusestatic="false"/></mujoco>'
    )
    model = mujoco.MjModel.from_xml_string(text)
    return float(model.body_mass[model.body("arm").id])


def _sizes(seed: int) -> list[str]:
    """Seeded random collision shapes with sizes from 1e-320 to 1e300, some negative."""
    rng = random.Random(seed)

    def number() -> str:
        sign = "-" if rng.random() < 0.15 else ""
        return f"{sign}{rng.uniform(1, 9):.3f}e{rng.randint(-320, 300)}"

    shapes = []
    for _ in range(rng.randint(1, 3)):
        kind = rng.choice(["box", "sphere", "cylinder", "capsule"])
        if kind == "box":
            shapes.append(f'<box size="{number()} {number()} {number()}"/>')
        elif kind == "sphere":
            shapes.append(f'<sphere radius="{number()}"/>')
        else:
            shapes.append(f'<{kind} radius="{number()}" length="{number()}"/>')
    return shapes


@pytest.mark.parametrize("seed", range(40))
def test_fuzzed_sizes_convert_exactly_or_are_refused_naming_the_link(
    seed: int, tmp_path: Path
) -> None:
    geoms = "".join(_collision(s) for s in _sizes(seed))
    path = _robot(tmp_path / "r", geoms, joint="fixed")
    try:
        result = urdf_to_hrdf_with_warnings(path)
    except RobotwrightError as exc:
        problems = getattr(exc, "problems", [])
        assert any('<link name="arm">' in (p.element or "") for p in problems), str(exc)
        return
    arm = next(b for b in result.hrdf.bodies if b.name == "arm")
    values = [arm.mass, *arm.inertial_pos, *arm.diag_inertia]
    assert all(math.isfinite(v) for v in values), values
    assert arm.mass == pytest.approx(_mujoco_mass(path), rel=1e-12, abs=0)


@pytest.mark.parametrize(
    "shape",
    [
        '<box size="0 0.1 0.1"/>',
        '<box size="-0.1 0.1 0.1"/>',
        '<sphere radius="-1"/>',
        '<cylinder radius="0.1" length="-2"/>',
        '<box size="1e200 1 1"/>',
        '<sphere radius="1e150"/>',
    ],
)
def test_sizes_mujoco_computes_no_mass_for_are_refused(shape: str, tmp_path: Path) -> None:
    path = _robot(tmp_path / "r", _collision(shape))
    out = tmp_path / "out.xml"
    done = _run("convert", str(path), "-o", str(out))
    _one_line_error(done)
    assert 'link name="arm"' in done.stderr
    assert not out.exists()
    # --inertia-from-geoms never does not compute: the refusal is then MuJoCo's (massless
    # moving link) or the geometry's own, never a crash.
    done = _run("convert", str(path), "-o", str(out), "--inertia-from-geoms", "never")
    assert done.returncode == 2 and "Traceback" not in done.stderr


def _stl(path: Path, triangles: np.ndarray) -> None:
    with path.open("wb") as fh:
        fh.write(b"\0" * 80 + struct.pack("<I", len(triangles)))
        for tri in triangles:
            fh.write(struct.pack("<3f", 0, 0, 0))
            for v in tri:
                fh.write(struct.pack("<3f", *v))
            fh.write(b"\0\0")


def test_flat_collision_mesh_is_refused_as_mujoco_refuses_it(tmp_path: Path) -> None:
    folder = tmp_path / "r"
    folder.mkdir()
    flat = np.array([[[0, 0, 0], [1, 0, 0], [1, 1, 0]], [[0, 0, 0], [1, 1, 0], [0, 1, 0]]])
    _stl(folder / "flat.stl", flat)
    path = _robot(folder, _collision('<mesh filename="flat.stl"/>'))
    with pytest.raises(ValueError):
        mujoco.MjModel.from_xml_path(str(path))
    done = _run("convert", str(path), "-o", str(tmp_path / "out.xml"))
    _one_line_error(done)
    assert 'link name="arm"' in done.stderr
    assert not (tmp_path / "out.xml").exists()


@pytest.mark.parametrize(
    "uri", ["../outside.stl", "/etc/passwd", "file:///etc/hostname", "package://nope/x.stl"]
)
def test_escaping_collision_mesh_is_refused_before_any_inertia(uri: str, tmp_path: Path) -> None:
    _stl(tmp_path / "outside.stl", np.array([[[0, 0, 0], [1, 0, 0], [0, 1, 0]]]))
    path = _robot(tmp_path / "r", _collision(f'<mesh filename="{uri}"/>'))
    out = tmp_path / "out.xml"
    done = _run("convert", str(path), "-o", str(out))
    _one_line_error(done)
    assert not out.exists()
