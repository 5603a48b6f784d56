"""``robotwright render``: writes a PNG of the requested size; bad input exits 2."""

from __future__ import annotations

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
        (["arm6", "--size", "4x4"], "picture width 4: expected an integer in 16..4096"),
        (["arm6", "--size", "big"], "argument --size: 'big': expected WIDTHxHEIGHT"),
        (["arm6", "--backend", "vulkan"], "invalid choice: 'vulkan'"),
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
