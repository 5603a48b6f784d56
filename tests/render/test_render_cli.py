"""``robotwright render``: writes a PNG of the requested size; bad input exits 2."""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

import matplotlib.image as mpimg
import pytest

from robotwright.cli import main


def test_cli_writes_png_of_requested_size(tmp_path: Path, capsys) -> None:
    out = tmp_path / "arm.png"
    code = main(["render", "arm6", "-o", str(out), "--size", "200x150", "--camera", "front"])
    assert code == 0
    img = mpimg.imread(out)
    assert img.shape[:2] == (150, 200)
    assert img[..., :3].std() > 0.05
    said = capsys.readouterr().out
    assert f"wrote {out} (200x150, " in said and "renderer, camera front" in said


def test_cli_existing_output_needs_overwrite(tmp_path: Path, capsys) -> None:
    out = tmp_path / "a.png"
    out.write_bytes(b"old")
    assert main(["render", "arm6", "-o", str(out), "--size", "64x48"]) == 2
    assert "give --overwrite" in capsys.readouterr().err
    assert out.read_bytes() == b"old"
    assert main(["render", "arm6", "-o", str(out), "--size", "64x48", "--overwrite"]) == 0
    assert mpimg.imread(out).shape[:2] == (48, 64)


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["no_such_robot"], "no robot named 'no_such_robot'"),
        (["arm6", "--camera", "sideways"], "camera 'sideways': not a camera of the model"),
        (["arm6", "--camera", "isso"], "did you mean 'iso'?"),
        (["arm6", "--size", "4x4"], "picture width 4: expected an integer in 16..4096"),
        (["arm6", "--size", "big"], "argument --size: 'big': expected WIDTHxHEIGHT"),
        (["arm6", "--backend", "vulkan"], "invalid choice: 'vulkan'"),
        # angles mistyped are refused before the robot is read (it does not exist here)
        (["no_such_robot", "--camera", "150 -25"], "camera '150 -25': expected AZIMUTH"),
        (["no_such_robot", "--camera", "150"], "camera '150': expected AZIMUTH"),
    ],
)
def test_cli_bad_input_exits_2_with_message(tmp_path: Path, capsys, args, message) -> None:
    out = tmp_path / "x.png"
    try:
        code = main(["render", *args[:1], "-o", str(out), *args[1:]])
    except SystemExit as exc:  # argparse's own errors exit 2 too
        code = exc.code
    assert code == 2
    err = capsys.readouterr().err
    assert message in err and "Traceback" not in err
    assert not out.exists() and list(tmp_path.iterdir()) == []


def test_cli_output_must_be_png(tmp_path: Path, capsys) -> None:
    assert main(["render", "arm6", "-o", str(tmp_path / "x.jpg")]) == 2
    assert "x.jpg: expected a .png output file" in capsys.readouterr().err


def test_cli_scan_needs_a_scan_for_scene(tmp_path: Path, capsys) -> None:
    scene = tmp_path / "scene.xml"
    scene.write_text("<mujoco><worldbody><geom size='1 1 0.1' type='plane'/></worldbody></mujoco>")
    out = tmp_path / "x.png"
    assert main(["render", "arm6", "-o", str(out), "--scene", str(scene)]) == 2
    assert "applies to a scan (.npz), not to 'arm6'" in capsys.readouterr().err
    assert not out.exists()


_NOTED_URDF = """<robot name="noted"><link name="base"><inertial><mass value="1"/>
<inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>
<collision><geometry><box size="0.2 0.2 0.2"/></geometry></collision></link>
<link name="arm"><inertial><mass value="0.5"/>
<inertia ixx="0.001" iyy="0.001" izz="0.001" ixy="0" ixz="0" iyz="0"/></inertial>
<collision><geometry><cylinder radius="0.03" length="0.3"/></geometry></collision></link>
<joint name="j" type="revolute"><parent link="base"/><child link="arm"/>
<limit lower="-1" upper="1" effort="10" velocity="2"/></joint></robot>"""


#: A progress line of ``robotwright._progress.working``: ``  drawing noted.png (2 s)``.
_PROGRESS = re.compile(r"^  drawing \S+ \(\d[^()]*\)$")


@pytest.mark.parametrize("verbose", [False, True])
def test_reading_notes_are_shown_with_v_only(tmp_path: Path, verbose) -> None:
    """A drawing writes no conversion: what reading the robot noted (here its effort and
    velocity limits) is listed with -v only, also when the read ran in the confined
    reader, whose log comes back to this process. Run as the command runs (its own
    process: pytest's log capture would hide a stray log line)."""
    (tmp_path / "noted.urdf").write_text(_NOTED_URDF)
    out = tmp_path / "noted.png"
    args = ["render", "noted.urdf", "-o", "noted.png", "--size", "64x48"]
    run = subprocess.run(
        [sys.executable, "-m", "robotwright", *args, *(["-v"] if verbose else [])],
        cwd=tmp_path,
        capture_output=True,
        text=True,
    )
    assert run.returncode == 0, run.stderr
    assert out.is_file()
    assert ("effort/velocity limits" in run.stderr) is verbose
    if not verbose:  # nothing but the progress of a slow drawing (a busy machine)
        assert [ln for ln in run.stderr.splitlines() if not _PROGRESS.match(ln)] == []
