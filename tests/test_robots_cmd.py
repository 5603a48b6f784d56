"""``robotwright robots``: the robots loadable by name, and each name in every command."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import mujoco
import pytest

from robotwright.cli import main
from robotwright.hrdf.assets import BUNDLED_ROBOTS_DIR

MJCF = """<mujoco model="{name}"><worldbody><body name="b" pos="0 0 0.3">
<joint name="j" type="hinge"/><geom type="sphere" size="0.1" mass="1"/></body>
</worldbody></mujoco>"""


def _listing(capsys) -> list[dict]:
    assert main(["robots", "--json"]) == 0
    return json.loads(capsys.readouterr().out)


def test_json_schema_and_bundled_robots(capsys):
    rows = _listing(capsys)
    for row in rows:
        assert set(row) == {"name", "qualified", "source", "format", "path", "on_disk"}
        assert row["format"] in ("hrdf", "urdf", "xacro", "mjcf")
        # every robot is on disk, but a Menagerie one not downloaded (listed, marked so)
        assert Path(row["path"]).exists() == row["on_disk"]
        assert row["on_disk"] or row["source"] == "menagerie"
        assert row["qualified"] == f"{row['source']}:{row['qualified'].split(':', 1)[1]}"
    names = [r["name"] for r in rows]
    assert len(names) == len(set(names))  # every name typed picks one robot
    bundled = {r["name"] for r in rows if r["source"] == "bundled"}
    assert {"arm6", "mini_humanoid"} <= bundled


def test_text_listing_has_one_line_per_robot(capsys):
    rows = _listing(capsys)
    assert main(["robots"]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert len(lines) == len(rows) + 2  # header and count


def test_assets_clash_with_bundled_is_source_qualified(tmp_path, monkeypatch, capsys):
    robots = tmp_path / "robots"
    robots.mkdir()
    shutil.copytree(BUNDLED_ROBOTS_DIR / "arm6", robots / "arm6")
    monkeypatch.setenv("HURODES_ASSETS_PATH", str(tmp_path))
    rows = _listing(capsys)
    arm = [r for r in rows if r["qualified"] in ("assets:arm6", "bundled:arm6")]
    by_source = {r["source"]: r["name"] for r in arm}
    assert by_source == {"assets": "arm6", "bundled": "bundled:arm6"}
    # The qualified name loads the bundled one, the plain name the user's copy.
    assert main(["info", "bundled:arm6"]) == 0
    assert main(["info", "assets:arm6"]) == 0


def test_robot_descriptions_cache_is_listed_and_loads(tmp_path, monkeypatch, capsys):
    cache = tmp_path / "cache"
    for repo, name in (("repo_a", "zz_bot"), ("repo_b", "zz_bot"), ("repo_b", "zz_other")):
        folder = cache / repo / name
        folder.mkdir(parents=True, exist_ok=True)
        (folder / f"{name}.xml").write_text(MJCF.format(name=name))
    (cache / "repo_b" / "zz_other" / "notes.xml").write_text("<launch/>")  # not MJCF
    monkeypatch.setenv("ROBOT_DESCRIPTIONS_CACHE", str(cache))
    rows = [r for r in _listing(capsys) if r["source"] == "robot_descriptions"]
    # zz_bot is in two repositories: each is named by the folder holding it.
    assert sorted(r["name"] for r in rows) == [
        "repo_a/zz_bot/zz_bot",
        "repo_b/zz_bot/zz_bot",
        "zz_other",
    ]
    assert "notes" not in {r["name"] for r in rows}
    assert {r["format"] for r in rows} == {"mjcf"}
    out = tmp_path / "o.xml"
    assert main(["export", "zz_other", "-o", str(out)]) == 0
    assert mujoco.MjModel.from_xml_path(str(out)).njnt == 1
    assert main(["info", "robot_descriptions:zz_other"]) == 0


def test_same_name_twice_in_one_source_is_named_by_folder(tmp_path, monkeypatch, capsys):
    cache = tmp_path / "cache"
    for pkg in ("a_description", "b_description"):
        folder = cache / "repo" / pkg / "mjcf"
        folder.mkdir(parents=True)
        (folder / "twin.xml").write_text(MJCF.format(name=pkg))
    monkeypatch.setenv("ROBOT_DESCRIPTIONS_CACHE", str(cache))
    names = {r["name"] for r in _listing(capsys) if r["source"] == "robot_descriptions"}
    assert {"a_description/twin", "b_description/twin"} <= names
    assert "twin" not in names
    assert main(["info", "b_description/twin"]) == 0
    assert "robot b_description" in capsys.readouterr().out


def test_an_unknown_source_is_refused_with_the_sources_there(capsys):
    assert main(["robots", "--source", "bundeld"]) == 2
    err = capsys.readouterr().err
    assert "--source 'bundeld': no robot comes from it" in err
    assert "bundled" in err.split("sources here:")[1] and "did you mean 'bundled'?" in err


def test_unknown_name_suggests_close_ones(capsys):
    assert main(["info", "arm66"]) == 2
    err = capsys.readouterr().err
    assert len(err.splitlines()) == 1 and "arm6" in err and "robotwright robots" in err


@pytest.mark.realdata
@pytest.mark.parametrize("name", ["solo12", "talos", "go2", "jvrc1", "panda", "ur5"])
def test_installed_package_robots_load_by_name(name, capsys):
    rows = {r["name"]: r for r in _listing(capsys)}
    if name not in rows:
        pytest.skip(f"{name}: its description package is not installed")
    assert main(["info", name]) == 0
    assert capsys.readouterr().out.startswith("robot ")


@pytest.mark.realdata
def test_go1_renders_with_a_physics_warning_and_does_not_export(tmp_path, capsys):
    rows = {r["name"]: r for r in _listing(capsys)}
    if "go1" not in rows:
        pytest.skip("example-robot-data is not installed")
    out = tmp_path / "go1.png"
    assert main(["render", "go1", "-o", str(out), "--size", "64x48"]) == 0
    assert "physics refused" in capsys.readouterr().err and out.is_file()
    assert main(["export", "go1", "-o", str(tmp_path / "go1.xml")]) == 2
    assert not (tmp_path / "go1.xml").exists()
