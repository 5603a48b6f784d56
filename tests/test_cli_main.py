"""The ``robotwright`` entry point: start-up imports, --version, notes, overwrite rule,
names, format from the file name."""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
from pathlib import Path

import mujoco
import numpy as np
import pytest

import robotwright
from robotwright.cli import build_parser, main
from robotwright.generators import MJCFHumanoidGenerator
from robotwright.hrdf import HRDF

HEAVY = ("mujoco", "numpy", "trimesh", "matplotlib", "warp", "mujoco_warp", "torch", "scipy")


def test_building_the_parser_imports_no_heavy_library() -> None:
    # In a fresh interpreter: `robotwright --help` must not pay for MuJoCo or numpy.
    code = (
        "import sys\n"
        "import robotwright.cli as cli\n"
        "parser = cli.build_parser()\n"
        "for command in parser._subparsers._group_actions[0].choices.values():\n"
        "    command.format_help()\n"
        f"print(sorted(m for m in {HEAVY!r} if m in sys.modules))\n"
    )
    # Without MUJOCO_GL: where it is set, import robotwright imports MuJoCo at once, by
    # design (robotwright._mujoco_gl); importing mjlab, as other tests do, sets it to egl.
    env = {k: v for k, v in os.environ.items() if k != "MUJOCO_GL"}
    run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env)
    assert run.returncode == 0, run.stderr
    assert run.stdout.strip() == "[]"


def test_every_option_has_help(capsys) -> None:
    parser = build_parser()
    from robotwright.cli.main import _all_parsers

    missing = [
        f"{p.prog} {'/'.join(a.option_strings) or a.dest}"
        for p in _all_parsers(parser)
        for a in p._actions
        if not a.help and not isinstance(a, argparse._SubParsersAction)
    ]
    assert missing == []


def test_version(capsys) -> None:
    with pytest.raises(SystemExit) as exc:
        main(["--version"])
    assert exc.value.code == 0
    out = capsys.readouterr().out
    assert out.startswith(f"robotwright {robotwright.__version__} (MuJoCo {mujoco.__version__}")


def test_misspelt_command_and_choice_suggest_the_close_name(capsys) -> None:
    with pytest.raises(SystemExit) as exc:
        main(["exprot", "arm6"])
    assert exc.value.code == 2
    assert "did you mean 'export'?" in capsys.readouterr().err
    with pytest.raises(SystemExit):
        main(["grammar", "search", "--objective", "reac"])
    # Other objectives may be close too: 'reach' is among the suggestions.
    suggested = capsys.readouterr().err.split("did you mean", 1)[1]
    assert "'reach'" in suggested


def test_unknown_robot_suggests_the_close_name(capsys) -> None:
    assert main(["info", "mini_humanoi"]) == 2
    err = capsys.readouterr().err
    # Installed description packages add names: the close one is among the suggestions.
    assert "no robot named 'mini_humanoi'" in err and "did you mean" in err
    assert "'mini_humanoid'" in err.split("did you mean")[1]
    assert "Traceback" not in err


def test_notes_one_summary_line_and_every_note_with_v(tmp_path: Path, capsys) -> None:
    argv = ["export", "mini_humanoid", "--format", "urdf", "--copy-meshes"]
    assert main([*argv, "-o", str(tmp_path / "a.urdf")]) == 0
    captured = capsys.readouterr()
    assert captured.out.startswith("wrote ")
    (line,) = captured.err.splitlines()
    count = int(line.split()[0])
    # 20 armatures, 8 capsules, 2 sensors, 1 IMU (geom colours are written as visuals)
    assert count > 20 and "joint.csv armature" in line and "-v lists each" in line
    # `-v` before or after the command: each note on its own line, then the same summary.
    for verbose in (["-v", *argv], [*argv, "--verbose"]):
        out = tmp_path / f"{len(verbose[0])}.urdf"
        assert main([*verbose, "-o", str(out)]) == 0
        err = capsys.readouterr().err.splitlines()
        assert sum(e.startswith("note: ") for e in err) == count == int(err[-1].split()[0])


def test_format_follows_the_output_extension(tmp_path: Path, capsys) -> None:
    assert main(["export", "arm6", "-o", str(tmp_path / "arm.urdf")]) == 0
    assert "(urdf, robot 'arm6'" in capsys.readouterr().out
    model = mujoco.MjModel.from_xml_path(str(tmp_path / "arm.urdf"))
    hrdf = HRDF.from_robot_name("arm6")
    assert model.njnt == len(hrdf.joints)
    assert np.isclose(model.body_mass.sum(), hrdf.total_mass)
    assert main(["compose", "arm6", "-o", str(tmp_path / "scene.mjcf")]) == 0
    assert "(mjcf, robots: arm6)" in capsys.readouterr().out
    assert main(["export", "arm6", "-o", str(tmp_path / "arm.sdf")]) == 2
    assert "cannot tell the format from '.sdf'" in capsys.readouterr().err


@pytest.mark.filterwarnings("ignore::robotwright.errors.ConversionWarning")  # the reference
def test_things_takes_a_bundled_robot_name(tmp_path: Path, capsys) -> None:
    assert main(["things", "arm6", str(tmp_path / "arm.xml")]) == 0
    model = mujoco.MjModel.from_xml_path(str(tmp_path / "arm.xml"))
    reference = MJCFHumanoidGenerator.from_robot_name("arm6").to_model()
    assert model.nu == reference.nu and model.njnt == reference.njnt
    assert np.allclose(model.body_mass, reference.body_mass)
    assert np.allclose(model.body_inertia, reference.body_inertia)
    assert main(["things", "arm66", str(tmp_path / "x.xml")]) == 2
    assert "'arm6'" in capsys.readouterr().err.split("did you mean")[1]


def _scene(tmp_path: Path) -> Path:
    scene = tmp_path / "scene.xml"
    assert main(["compose", "mini_humanoid", "-o", str(scene)]) == 0
    return scene


def test_lidar_unknown_sensor_suggests_the_prefixed_site(tmp_path: Path, capsys) -> None:
    scene = _scene(tmp_path)
    argv = ["lidar", str(scene), "--sensor", "head_lidar", "-o", str(tmp_path / "s.npz")]
    assert main(argv) == 2
    assert "did you mean 'mini_humanoid_head_lidar'?" in capsys.readouterr().err
    assert not (tmp_path / "s.npz").exists()


def _cases(tmp_path: Path) -> list[tuple[list[str], Path]]:
    """(argv, output) of every command that writes one output."""
    scene = _scene(tmp_path)
    design = tmp_path / "design.txt"
    design.write_text("# grammar=srl\n", encoding="utf-8")
    return [
        (["export", "arm6", "-o", "{out}.xml"], Path("{out}.xml")),
        (["compose", "arm6", "mini_humanoid", "-o", "{out}.xml"], Path("{out}.xml")),
        (["convert", "arm6", "-o", "{out}.urdf"], Path("{out}.urdf")),
        (["convert", "arm6", "-o", "{out}"], Path("{out}")),
        (["things", "arm6", "{out}.xml"], Path("{out}.xml")),
        (["things", "arm6", "{out}"], Path("{out}")),
        (
            ["lidar", str(scene), "--sensor", "mini_humanoid_head_lidar", "--pattern", "grid"]
            + ["-o", "{out}.npz"],
            Path("{out}.npz"),
        ),
        (["grammar", "sample", "--no-picture", "--max-links", "2", "-o", "{out}"], Path("{out}")),
    ]


def test_one_overwrite_rule_for_every_command(tmp_path: Path, capsys) -> None:
    for i, (argv, output) in enumerate(_cases(tmp_path)):
        out = str(tmp_path / f"out{i}")
        argv = [a.replace("{out}", out) for a in argv]
        target = Path(str(output).replace("{out}", out))
        if target.suffix:
            # A file is kept as it is, with exit 2 naming the flag; --overwrite replaces it.
            target.write_text("mine", encoding="utf-8")
            assert main(argv) == 2, argv
            err = capsys.readouterr().err
            assert f"{target}: " in err and "give --overwrite to replace it" in err, err
            assert target.read_text(encoding="utf-8") == "mine"
            assert main([*argv, "--overwrite"]) == 0, (argv, capsys.readouterr().err)
            capsys.readouterr()
            assert target.read_bytes() != b"mine"
            continue
        # A folder of the user's is never replaced, --overwrite or not (exit 2).
        target.mkdir()
        (target / "mine.txt").write_text("mine", encoding="utf-8")
        for flags in ([], ["--overwrite"]):
            assert main([*argv, *flags]) == 2, argv
            err = capsys.readouterr().err
            assert f"{target}: " in err and "robotwright did not write" in err, err
            assert (target / "mine.txt").read_text(encoding="utf-8") == "mine"
        # An empty folder holds nothing to lose: it is written into; the output written
        # there is refused without --overwrite and replaced with it.
        empty = tmp_path / f"empty{i}"
        empty.mkdir()
        mine = [a.replace(out, str(empty)) for a in argv]
        assert main(mine) == 0, argv
        assert any(empty.iterdir())
        capsys.readouterr()
        assert main(mine) == 2
        assert "give --overwrite to replace it" in capsys.readouterr().err
        assert main([*mine, "--overwrite"]) == 0, (argv, capsys.readouterr().err)
        capsys.readouterr()


def test_interrupt_is_one_line_and_exit_130(monkeypatch, capsys) -> None:
    from robotwright.cli import hrdf as hrdf_cli

    def interrupted(args):
        raise KeyboardInterrupt

    monkeypatch.setattr(hrdf_cli, "_info", interrupted)
    assert main(["info", "arm6"]) == 130
    assert capsys.readouterr().err == "interrupted\n"


def test_render_prints_no_notes_line_unless_verbose(tmp_path, capsys) -> None:
    """render only shows a model: the notes of loading it are listed with -v only."""
    from robotwright.cli import main

    # A link without <inertial> and a joint velocity limit: two notes when loaded.
    urdf = tmp_path / "t.urdf"
    urdf.write_text(
        '<robot name="t"><link name="base"><inertial><mass value="1"/>'
        '<inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>'
        '<visual><geometry><box size="0.1 0.1 0.1"/></geometry></visual></link>'
        '<link name="arm"><collision><geometry><box size="0.1 0.1 0.3"/></geometry>'
        '</collision></link><joint name="j" type="revolute"><parent link="base"/>'
        '<child link="arm"/><axis xyz="0 0 1"/>'
        '<limit lower="-1" upper="1" effort="5" velocity="2"/></joint></robot>'
    )
    out = tmp_path / "t.png"
    assert main(["render", str(urdf), "-o", str(out), "--size", "160x120"]) == 0
    assert out.is_file()
    assert "conversion note" not in capsys.readouterr().err
    assert (
        main(["render", str(urdf), "-o", str(out), "--size", "160x120", "--overwrite", "-v"]) == 0
    )
    assert "conversion note" in capsys.readouterr().err


@pytest.mark.parametrize(
    "geom",
    [
        '<geom type="box" size="0.1 0.1 0.1" mass="-1"/>',
        '<geom type="box" size="0.1 0.1 0.1" density="-5"/>',
        '<geom type="sphere" size="0.1" fromto="0 0 0 0 0 0"/>',
        '<geom type="mesh" mesh="nothing"/>',
    ],
)
def test_a_model_mujoco_refuses_is_one_error_line(tmp_path: Path, capsys, geom: str) -> None:
    # MuJoCo's own message names the element on a second line; the user gets one line.
    src = tmp_path / "bad.xml"
    src.write_text(f'<mujoco><worldbody><body name="b"><joint/>{geom}</body></worldbody></mujoco>')
    out = tmp_path / "out.xml"
    assert main(["convert", str(src), "-o", str(out)]) == 2
    err = capsys.readouterr().err
    assert err.startswith("error: ") and err.count("\n") == 1, err
    assert str(src) in err and not out.exists()
