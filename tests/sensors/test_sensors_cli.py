"""``robotwright lidar`` and scan_to_files: files written, contents consistent, clean errors."""

from __future__ import annotations

import json

import mujoco
import numpy as np
import pytest
from lidar_scenes import CLUTTER_XML

from robotwright.cli import main
from robotwright.sensors import scan_to_files


def test_cli_writes_npz_and_png(tmp_path, capsys):
    scene = tmp_path / "scene.xml"
    scene.write_text(CLUTTER_XML, encoding="utf-8")
    npz, png = tmp_path / "scan.npz", tmp_path / "scan.png"
    rc = main(
        [
            "lidar",
            str(scene),
            "--sensor",
            "lidar",
            "--pattern",
            "mid360",
            "-o",
            str(npz),
            "--png",
            str(png),
            "--view-radius",
            "5",
        ]
    )
    assert rc == 0
    out = capsys.readouterr().out
    assert "20000 rays" in out and str(npz) in out
    with np.load(npz) as z:
        assert z["distances"].shape == (20000,) and z["points"].shape == (20000, 3)
        hit = np.isfinite(z["distances"])
        np.testing.assert_array_equal(hit, z["mesh_ids"] >= 0)
        np.testing.assert_array_equal(np.isnan(z["points"]).any(axis=1), ~hit)
        assert list(z["class_names"]) == ["unknown", "terrain", "dynamic_obstacle", "valuable"]
        # Points lie at distance along the ray from the sensor.
        d = np.linalg.norm(z["points"][hit] - z["sensor_pos"], axis=1)
        np.testing.assert_allclose(d, z["distances"][hit], atol=1e-9)
        assert (z["labels"][~hit] == 0).all() and set(np.unique(z["labels"][hit])) >= {1, 2}
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert not list(tmp_path.glob("*.tmp"))


def test_cli_bad_sensor_writes_nothing(tmp_path, capsys):
    scene = tmp_path / "scene.xml"
    scene.write_text(CLUTTER_XML, encoding="utf-8")
    rc = main(["lidar", str(scene), "--sensor", "lidr", "-o", str(tmp_path / "scan.npz")])
    assert rc == 2
    err = capsys.readouterr().err
    # In the command's own terms (the option, not the Python field), with the close name.
    assert "--sensor 'lidr': no body or site" in err and "prim_path" not in err
    assert "did you mean 'lidar'" in err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["scene.xml"]


def test_cli_custom_mapping(tmp_path):
    scene = tmp_path / "scene.xml"
    scene.write_text(CLUTTER_XML, encoding="utf-8")
    mapping = tmp_path / "mapping.json"
    mapping.write_text(json.dumps({"light": ["lamp"], "terrain": ["ground"]}), encoding="utf-8")
    npz = tmp_path / "scan.npz"
    assert (
        main(
            [
                "lidar",
                str(scene),
                "--sensor",
                "lidar",
                "--pattern",
                "vlp16",
                "--mapping",
                str(mapping),
                "-o",
                str(npz),
            ]
        )
        == 0
    )
    with np.load(npz) as z:
        assert list(z["class_names"]) == ["unknown", "light", "terrain"]
        paths = z["geom_paths"]
        lamp = [i for i, p in enumerate(paths) if "lamp" in p]
        sel = np.isin(z["mesh_ids"], lamp)
        assert sel.any() and (z["labels"][sel] == 1).all()


def test_scan_to_files_summary(tmp_path):
    model = mujoco.MjModel.from_xml_string(CLUTTER_XML)
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    summary = scan_to_files(model, data, "lidar", "vlp16", tmp_path / "a.npz", None)
    assert summary["num_rays"] == 28800 and summary["png"] is None
    assert sum(summary["class_counts"].values()) == summary["num_hits"] > 0
    assert not (tmp_path / "a.png").exists()


@pytest.mark.warp
def test_cli_warp_engine_matches_mujoco(tmp_path):
    pytest.importorskip("mujoco_warp", reason="robotwright[warp] not installed")
    scene = tmp_path / "scene.xml"
    scene.write_text(CLUTTER_XML, encoding="utf-8")
    out = {}
    for engine in ("mujoco", "warp"):
        npz = tmp_path / f"{engine}.npz"
        assert (
            main(["lidar", str(scene), "--sensor", "lidar", "--engine", engine, "-o", str(npz)])
            == 0
        )
        with np.load(npz) as z:
            out[engine] = (z["mesh_ids"], z["distances"])
    same = out["mujoco"][0] == out["warp"][0]
    assert same.mean() >= 0.999
    hit = same & (out["mujoco"][0] >= 0)
    np.testing.assert_allclose(out["warp"][1][hit], out["mujoco"][1][hit], atol=1e-5)


def test_cli_bad_png_path_fails_before_writing_the_npz(tmp_path, capsys):
    scene = tmp_path / "scene.xml"
    scene.write_text(CLUTTER_XML, encoding="utf-8")
    (tmp_path / "plain.txt").write_text("x", encoding="utf-8")
    npz = tmp_path / "scan.npz"
    rc = main(["lidar", str(scene), "--sensor", "lidar", "-o", str(npz), "--png",
               str(tmp_path / "plain.txt" / "scan.png")])  # fmt: skip
    assert rc == 2
    assert "plain.txt is a file, not a folder" in capsys.readouterr().err
    assert not npz.exists()
    rc = main(["lidar", str(scene), "--sensor", "lidar", "-o", str(tmp_path / "no" / "s.npz")])
    assert rc == 2
    assert "does not exist" in capsys.readouterr().err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["plain.txt", "scene.xml"]


def test_cli_refuses_xml_entities_and_bad_view_radius(tmp_path, capsys):
    bomb = tmp_path / "bomb.xml"
    bomb.write_text(
        '<?xml version="1.0"?><!DOCTYPE m [<!ENTITY a "aaaa"><!ENTITY b "&a;&a;&a;">]>'
        '<mujoco model="&b;"><worldbody><body name="s"><geom size=".1"/></body>'
        "</worldbody></mujoco>",
        encoding="utf-8",
    )
    assert main(["lidar", str(bomb), "--sensor", "s", "-o", str(tmp_path / "s.npz")]) == 2
    assert "unsafe XML refused" in capsys.readouterr().err
    scene = tmp_path / "scene.xml"
    scene.write_text(CLUTTER_XML, encoding="utf-8")
    rc = main(["lidar", str(scene), "--sensor", "lidar", "--png", str(tmp_path / "s.png"),
               "--view-radius", "-2"])  # fmt: skip
    assert rc == 2
    assert "--view-radius: expected a positive distance" in capsys.readouterr().err
    assert not (tmp_path / "s.npz").exists() and not (tmp_path / "s.png").exists()


def test_cli_wrong_output_extensions_are_refused(tmp_path, capsys):
    scene = tmp_path / "scene.xml"
    scene.write_text(CLUTTER_XML, encoding="utf-8")
    assert main(["lidar", str(scene), "--sensor", "lidar", "-o", str(tmp_path / "s.txt")]) == 2
    assert "-o " in (err := capsys.readouterr().err) and "ending in .npz" in err
    assert main(["lidar", str(scene), "--sensor", "lidar", "--png", str(tmp_path / "s.npz")]) == 2
    assert "--png" in (err := capsys.readouterr().err) and "ending in .png" in err
    assert [p.name for p in tmp_path.iterdir()] == ["scene.xml"]
