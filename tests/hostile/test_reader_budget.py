"""Files that declare more than a robot needs (issue 26, item 4): declared sizes are
refused before MuJoCo allocates them, the confined reader has a memory and CPU budget,
xacro one-line bombs end at once, deep robots still convert to flat formats, and an
error line stays short.

Each bomb must end with one ``error:`` line, exit 2 and no output. The time a bomb takes
is not asserted as a speed (tests never time the code): a generous bound only says the
command ended instead of running on (the bombs ran for minutes before).
"""

from __future__ import annotations

import random
import time
from pathlib import Path

import pytest

from robotwright._confine import confinement
from robotwright._reader_budget import reader_budget
from robotwright.cli import main
from robotwright.errors import RobotwrightError
from robotwright.parsers import mjcf_to_hrdf

ENDED = 60.0  # seconds: only says the command ended (the bombs ran for minutes before)

BODY = '<worldbody><body name="b"><freejoint/><geom size=".1"/></body></worldbody>'


def _file(folder: Path, text: str, name: str = "bomb.xml") -> Path:
    path = folder / name
    path.write_text(text)
    return path


def _refused_in_one_line(path: Path, tmp_path: Path, capsys, *extra: str) -> str:
    out = tmp_path / "out.xml"
    start = time.monotonic()
    code = main(["convert", str(path), "-o", str(out), *extra])
    assert time.monotonic() - start < ENDED
    err = capsys.readouterr().err
    assert code == 2, err
    assert err.startswith("error:") and err.count("\n") == 1, err
    assert not out.exists()
    return err


def _declared(rng: random.Random) -> list[tuple[str, str]]:
    """Elements declaring far more than the reader's budget, fixed and random."""
    out = [
        ("nuserdata", f'<size nuserdata="300000000"/>{BODY}'),
        ("nuser_body", f'<size nuser_body="900000000"/>{BODY}'),
        ("nuser_geom", f'<size nuser_geom="2000000000"/>{BODY}'),
        (
            "replicate",
            "<worldbody>"
            + '<replicate count="100" offset=".1 0 0">' * 4
            + '<body><geom size=".01"/></body>'
            + "</replicate>" * 4
            + "</worldbody>",
        ),
        (
            "flexcomp",
            '<worldbody><flexcomp name="f" type="grid" count="3000 3000 1" '
            'spacing=".01 .01 .01" dim="2"/></worldbody>',
        ),
    ]
    fields = ["nuserdata", "nuser_body", "nuser_jnt", "nuser_site", "nuser_actuator"]
    for _ in range(6):
        field = rng.choice(fields)
        out.append((field, f'<size {field}="{rng.randint(300_000_000, 2_000_000_000)}"/>{BODY}'))
        depth = rng.randint(3, 5)
        count = rng.randint(40, 400)
        out.append(
            (
                "replicate",
                "<worldbody>"
                + f'<replicate count="{count}" offset=".1 0 0">' * depth
                + '<body><geom size=".01"/></body>'
                + "</replicate>" * depth
                + "</worldbody>",
            )
        )
    return [(label, f"<mujoco>{text}</mujoco>") for label, text in out]


def test_declared_sizes_are_refused_before_mujoco_allocates(tmp_path: Path, capsys) -> None:
    rng = random.Random(26)
    for label, text in _declared(rng):
        err = _refused_in_one_line(_file(tmp_path, text), tmp_path, capsys)
        assert "--max-reader-mb" in err, label
        assert label.split("_")[0] in err or "replicate" in err or "flexcomp" in err, err


def test_a_model_within_the_budget_still_converts(tmp_path: Path) -> None:
    """Controls: modest declared sizes and replicates convert."""
    text = (
        '<mujoco><size nuserdata="100" nuser_body="2"/><worldbody><body name="base">'
        '<freejoint/><geom size=".1"/><replicate count="4" offset=".5 0 0">'
        '<body><geom size=".1"/></body></replicate></body></worldbody></mujoco>'
    )
    hrdf = mjcf_to_hrdf(_file(tmp_path, text))
    assert len(hrdf.bodies) == 5


def test_the_budget_is_the_users_to_raise(tmp_path: Path, capsys) -> None:
    """The same file refused under a lower budget and read under the default."""
    text = f'<mujoco><size nuserdata="50000000"/>{BODY}</mujoco>'  # 400 MB
    path = _file(tmp_path, text)
    _refused_in_one_line(path, tmp_path, capsys, "--max-reader-mb", "100")
    with reader_budget(100), pytest.raises(RobotwrightError, match="nuserdata"):
        mjcf_to_hrdf(path)


@pytest.mark.skipif(
    not confinement().startswith("landlock"), reason=f"no confined reader: {confinement()}"
)
def test_the_confined_reader_stops_at_its_memory_budget(tmp_path: Path, capsys) -> None:
    """Keyframes of a wide model pass the keyframe cap but not the memory budget:
    the confined reader runs out of its address space and says so."""
    bodies = "".join(
        f'<body name="b{k}" pos="{k} 0 0"><freejoint/><geom size=".1"/></body>' for k in range(400)
    )
    text = f'<mujoco><size nkey="9000"/><worldbody>{bodies}</worldbody></mujoco>'
    err = _refused_in_one_line(_file(tmp_path, text), tmp_path, capsys, "--max-reader-mb", "50")
    assert "memory" in err and "--max-reader-mb" in err


XACRO_BOMBS = [
    "round(10**1000, -10**9)",
    "math.prod(range(1, 999999))",
    "round(1, 10**8)",
    "math.prod([2**4000, 2**4000, 2**4000])",
]


@pytest.mark.parametrize("expression", XACRO_BOMBS)
def test_xacro_one_line_bombs_end_at_once(tmp_path: Path, capsys, expression: str) -> None:
    pytest.importorskip("xacro", reason="the xacro extra is not installed")
    path = tmp_path / "bomb.urdf.xacro"
    path.write_text(
        '<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro">'
        f'<xacro:property name="v" value="${{{expression}}}"/><link name="l${{v}}"/></robot>'
    )
    start = time.monotonic()
    assert main(["info", str(path)]) == 2
    assert time.monotonic() - start < ENDED
    err = capsys.readouterr().err
    assert err.startswith("error:") and err.count("\n") == 1


def test_xacro_cwd_is_refused(tmp_path: Path, capsys) -> None:
    """``$(cwd)`` would write the working folder into link names, as ``$(env)`` would
    write the environment."""
    pytest.importorskip("xacro", reason="the xacro extra is not installed")
    path = tmp_path / "cwd.urdf.xacro"
    path.write_text(
        '<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro"><link name="l$(cwd)"/></robot>'
    )
    assert main(["info", str(path)]) == 2
    assert "$(cwd)" in capsys.readouterr().err


def _chain(path: Path, n: int) -> Path:
    inertial = (
        '<inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01" '
        'ixy="0" ixz="0" iyz="0"/></inertial>'
    )
    links = "".join(f'<link name="l{i}">{inertial}</link>' for i in range(n))
    joints = "".join(
        f'<joint name="j{i}" type="revolute"><parent link="l{i - 1}"/><child link="l{i}"/>'
        '<origin xyz="0 0 0.1"/><axis xyz="0 1 0"/>'
        '<limit lower="-1" upper="1" effort="1" velocity="1"/></joint>'
        for i in range(1, n)
    )
    path.write_text(f'<robot name="chain">{links}{joints}</robot>')
    return path


def test_a_robot_deeper_than_mjcf_nests_converts_to_flat_formats(tmp_path: Path, capsys) -> None:
    """A 600-link chain: HRDF and URDF hold it (with a note that no MJCF proof was
    possible); MJCF is refused with a message saying why."""
    from robotwright.hrdf.model import HRDF

    src = _chain(tmp_path / "chain.urdf", 600)
    assert main(["convert", str(src), "-o", str(tmp_path / "chain"), "-v"]) == 0
    err = capsys.readouterr().err
    assert "proof: not made" in err
    assert len(HRDF.from_dir(tmp_path / "chain").bodies) == 600
    assert main(["convert", str(src), "-o", str(tmp_path / "chain.out.urdf")]) == 0
    assert (tmp_path / "chain.out.urdf").read_text().count('<link name="l') == 600
    capsys.readouterr()
    assert main(["convert", str(src), "-o", str(tmp_path / "chain.xml")]) == 2
    assert "nested" in capsys.readouterr().err
    assert not (tmp_path / "chain.xml").exists()


def test_error_lines_are_capped(tmp_path: Path, capsys) -> None:
    """A message built from a file (a world of 5,000 bodies, each named in it when the
    robot asked for is not one of them) stays one line of at most about 1 KB, saying
    how much was left out."""
    bodies = "".join(f'<body name="b{k}"><geom size=".1"/></body>' for k in range(5000))
    text = f"<mujoco><worldbody>{bodies}</worldbody></mujoco>"
    src = str(_file(tmp_path, text))
    code = main(["convert", src, "--root-body", "robot", "-o", str(tmp_path / "o.xml")])
    err = capsys.readouterr().err
    assert code == 2
    assert err.count("\n") == 1 and len(err) < 1200, len(err)
    assert "more characters" in err
