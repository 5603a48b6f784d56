"""``robotwright demo`` end to end: every system's output is there and is right."""

from __future__ import annotations

import json
import re
import subprocess
import sys
from pathlib import Path

import mujoco
import numpy as np


def test_demo_writes_every_part(tmp_path: Path) -> None:
    out = tmp_path / "demo"
    run = subprocess.run(
        [sys.executable, "-m", "robotwright", "demo", "-o", str(out)],
        capture_output=True,
        text=True,
    )
    assert run.returncode == 0, run.stderr
    assert "[6/7] semantic LiDAR scan" in run.stdout
    summary = json.loads((out / "summary.json").read_text())
    assert len(summary) == 7

    for name, nu in (("mini_humanoid", 20), ("arm6", 6)):
        model = mujoco.MjModel.from_xml_path(str(out / "robots" / f"{name}.xml"))
        assert model.nu == nu
        from_urdf = mujoco.MjModel.from_xml_path(str(out / "robots" / f"{name}.urdf"))
        assert np.isclose(from_urdf.body_mass.sum(), model.body_mass.sum(), rtol=1e-9)

    worn = mujoco.MjModel.from_xml_path(str(out / "srl" / "mini_humanoid_with_srl.xml"))
    plain = mujoco.MjModel.from_xml_path(str(out / "robots" / "mini_humanoid.xml"))
    assert worn.nv > plain.nv and worn.body_mass.sum() > plain.body_mass.sum()

    scene = mujoco.MjModel.from_xml_path(str(out / "scene" / "semantic_scene.xml"))
    data = mujoco.MjData(scene)
    for _ in range(200):
        mujoco.mj_step(scene, data)
    assert np.isfinite(data.qpos).all()
    assert scene.nu == worn.nu + 6

    scan = np.load(out / "lidar" / "scan.npz")
    labels, dist = scan["labels"], scan["distances"]
    assert labels.shape == dist.shape == (20000,)
    # Each class of the demo mapping is seen: terrain, obstacle, valuable, the arm.
    assert {1, 2, 3, 4} <= set(np.unique(labels).tolist())
    hit = np.isfinite(dist)
    assert (scan["mesh_ids"][hit] >= 0).all() and (labels[~hit] == 0).all()
    assert (out / "lidar" / "scan.png").stat().st_size > 20_000
    # Shaded pictures of each robot and of the scene, with and without the scan's points.
    import matplotlib.image as mpimg

    pictures = {}
    for name in ("mini_humanoid", "arm6", "humanoid_with_limb", "scene", "scene_lidar"):
        pictures[name] = mpimg.imread(out / "pictures" / f"{name}.png")[..., :3]
        assert pictures[name].shape == (480, 640, 3)
        assert pictures[name].std() > 0.05  # not a blank picture
    # The points change the scene picture where they are drawn, not everywhere.
    changed = np.abs(pictures["scene_lidar"] - pictures["scene"]).max(axis=2) > 0.1
    assert 0.02 < changed.mean() < 0.9
    assert "renderer" in summary["pictures of the robots and the scene (render)"]
    rt = (out / "robots" / "roundtrip_mini_humanoid_urdf.txt").read_text()
    assert "result:    PASS" in rt and "FAIL" not in rt

    # The notes the steps announce are the lines of the notes file: one per value.
    announced = sum(int(n) for n in re.findall(r"(\d+) conversion note\(s\)", run.stdout))
    listed = (out / "conversion_notes.txt").read_text(encoding="utf-8").splitlines()
    assert announced == len([line for line in listed if line]) > 40

    # One labelling rule: the command line with the demo's saved mapping labels the
    # demo's scene exactly as the demo did (the arm as `robot`, the wearer not scanned).
    from robotwright.cli import main

    again = tmp_path / "again.npz"
    argv = ["lidar", str(out / "scene" / "semantic_scene.xml"), "--sensor", "h_head_lidar"]
    assert main([*argv, "--mapping", str(out / "lidar" / "classes.json"), "-o", str(again)]) == 0
    cli_scan = np.load(again)
    assert list(cli_scan["class_names"]) == list(scan["class_names"])
    assert "robot" in list(scan["class_names"])
    assert np.array_equal(cli_scan["labels"], labels)
    assert np.array_equal(cli_scan["mesh_ids"], scan["mesh_ids"])


def test_demo_output_that_is_a_file_is_a_clear_error(tmp_path: Path, capsys) -> None:
    from robotwright.cli import main

    plain = tmp_path / "plain.txt"
    plain.write_text("keep", encoding="utf-8")
    assert main(["demo", "-o", str(plain)]) == 2
    assert "plain.txt: is a file; expected a folder for the demo output" in capsys.readouterr().err
    assert main(["demo", "-o", str(plain / "sub")]) == 2
    assert "plain.txt is a file, not a folder" in capsys.readouterr().err
    assert plain.read_text(encoding="utf-8") == "keep"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["plain.txt"]
