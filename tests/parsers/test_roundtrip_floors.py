"""roundtrip (issue 20): input it refuses exits 2 with one located error, never 1 "FAIL";
relative tolerances have an absolute floor (a zero inertia's round-off, the URDF form's
dummy-link masses on a robot of a gram)."""

from __future__ import annotations

import random
import sysconfig
from pathlib import Path

import pytest

from robotwright.cli import main
from robotwright.proof.roundtrip import run as rt
from robotwright.proof.roundtrip.compare import _rel

pytestmark = pytest.mark.usefixtures("quiet_parsers")


def _urdf(ixx: float, iyy: float, izz: float, ixy: float = 0.0) -> str:
    return f"""<robot name="bad">
  <link name="base"><inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01"
    ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="arm"><inertial><mass value="0.5"/><inertia ixx="{ixx!r}" iyy="{iyy!r}"
    izz="{izz!r}" ixy="{ixy!r}" ixz="0" iyz="0"/></inertial>
    <collision><geometry><sphere radius="0.05"/></geometry></collision></link>
  <joint name="j" type="continuous"><parent link="base"/><child link="arm"/>
    <axis xyz="0 0 1"/></joint>
</robot>
"""


def _non_physical() -> list:
    """Inertias no rigid body has: named families, then seeded random ones."""
    out = [
        pytest.param((1e-3, 1e-3, 5e-3, 0.0), id="triangle-inequality"),
        pytest.param((1e-3, 1e-3, 1e-3, 2e-3), id="negative-eigenvalue"),
        pytest.param((1e-3, 2e-3, 4e-3, 0.0), id="a-plus-b-below-c"),
    ]
    rng = random.Random(20)
    for k in range(5):
        a, b = rng.uniform(1e-4, 1e-2), rng.uniform(1e-4, 1e-2)
        c = (a + b) * rng.uniform(1.5, 10.0)  # beyond A + B >= C
        order = rng.sample((a, b, c), 3)
        out.append(pytest.param((*order, 0.0), id=f"random-{k}"))
    return out


@pytest.mark.parametrize("inertia", _non_physical())
def test_refused_input_exits_2_with_one_located_error(
    tmp_path: Path, capsys: pytest.CaptureFixture, inertia: tuple
) -> None:
    src = tmp_path / "bad.urdf"
    src.write_text(_urdf(*inertia))
    assert main(["roundtrip", str(src), "--configs", "2"]) == 2
    out, err = capsys.readouterr()
    errors = [line for line in err.splitlines() if line.startswith("error:")]
    assert len(errors) == 1 and str(src) in errors[0], err
    assert "Traceback" not in err
    assert "result:" not in out  # no table: nothing was compared


ERD = Path(sysconfig.get_paths()["purelib"]) / "cmeel.prefix/share/example-robot-data/robots"
#: example-robot-data files whose inertias are not physical (MuJoCo refuses them).
NON_PHYSICAL = [
    "allegro_hand_description/urdf/allegro_left_hand.urdf",
    "allegro_hand_description/urdf/allegro_right_hand.urdf",
    "alex_description/urdf/alex_psyonic_hands.urdf",
]


@pytest.mark.realdata
@pytest.mark.parametrize("rel", NON_PHYSICAL)
def test_corpus_non_physical_inertias_exit_2(rel: str, capsys: pytest.CaptureFixture) -> None:
    path = ERD / rel
    if not path.is_file():
        pytest.skip(f"example-robot-data absent: {path}")
    assert main(["roundtrip", str(path), "--configs", "2"]) == 2
    out, err = capsys.readouterr()
    assert any(line.startswith("error:") and str(path) in line for line in err.splitlines())
    assert "Traceback" not in err and "FAIL" not in out


def test_floor_makes_round_off_of_a_zero_inertia_zero() -> None:
    # Relative to itself, 6e-36 against 0 is an error of 1; against the floor, none.
    assert _rel(0.0, 6e-36) == 1.0
    assert _rel(0.0, 6e-36, rt.FLOOR * 0.1) <= rt.TOL_EXACT
    # The floor does not hide a real difference of a value above it.
    assert _rel(1.0, 1.0 + 1e-6, rt.FLOOR * 1.0) > rt.TOL_EXACT


ZERO_INERTIA = """<mujoco model="z">
  <worldbody>
    <body name="base">
      <freejoint/>
      <geom type="box" size="0.1 0.1 0.1" mass="2"/>
      <body name="marker" pos="0.1 0 0" quat="0.9238795 0 0.3826834 0">
        <inertial pos="0.01 0.02 0" quat="0.8 0.6 0 0" mass="0" diaginertia="0 0 0"/>
      </body>
      <body name="arm" pos="0 0 0.2">
        <joint name="j" axis="0 1 0" range="-1 1"/>
        <geom type="capsule" size="0.03" fromto="0 0 0 0 0 0.3" mass="0.5"/>
      </body>
    </body>
  </worldbody>
</mujoco>
"""


def test_zero_inertia_body_passes(tmp_path: Path) -> None:
    src = tmp_path / "z.xml"
    src.write_text(ZERO_INERTIA)
    report = rt.roundtrip(src, configs=3)
    assert report.ok, report.table()


#: A robot of about 0.88 g whose body with two joints needs a dummy link in URDF
#: (1e-9 kg each: over 1e-6 of this robot's mass, within its floor).
TINY = """<mujoco model="tiny">
  <worldbody>
    <body name="thorax">
      <freejoint/>
      <geom type="sphere" size="0.001" mass="0.0008"/>
      <body name="wing" pos="0.001 0 0">
        <joint name="yaw" axis="0 0 1" range="-1 1"/>
        <joint name="pitch" axis="0 1 0" range="-1 1"/>
        <geom type="box" size="0.002 0.0005 0.0001" mass="0.00008"/>
      </body>
    </body>
  </worldbody>
</mujoco>
"""


def test_urdf_dummy_link_masses_allowed(tmp_path: Path) -> None:
    src = tmp_path / "tiny.xml"
    src.write_text(TINY)
    # The URDF form adds a dummy link (1e-9 kg): 1.1e-6 of this robot's mass.
    hrdf = rt.parse_source(src).hrdf
    assert rt.our_urdf(hrdf).dummy_links
    assert 1e-9 / sum(b.mass for b in hrdf.bodies) > rt.TOL_URDF
    report = rt.roundtrip(src, configs=3)
    rows = {r.check: r for r in report.rows}
    assert any(k.startswith("URDF:") for k in rows), report.table()
    assert report.ok, report.table()


def test_urdf_refused_like_the_source_is_not_a_failure(tmp_path: Path) -> None:
    # A zero principal moment: MuJoCo refuses the source's full inertia (eigenvalues must
    # be positive), the parser keeps it with a note, our MJCF compiles; MuJoCo refuses our
    # URDF for the source's reason: nothing to compare there, not a failure of ours.
    # (a tip welded to the link gives the moving body what MuJoCo needs, as in
    # example-robot-data's finger_edu)
    tip = (
        '<link name="tip"><inertial><mass value="0.01"/><inertia ixx="1e-6" iyy="1e-6" '
        'izz="1e-6" ixy="0" ixz="0" iyz="0"/></inertial></link><joint name="t" '
        'type="fixed"><parent link="arm"/><child link="tip"/><origin xyz="0 0 0.1"/></joint>'
    )
    src = tmp_path / "flat.urdf"
    src.write_text(_urdf(1.2e-4, 1.2e-4, 0.0).replace("</robot>", tip + "</robot>"))
    report = rt.roundtrip(src, configs=2)
    assert report.reference.startswith("yourdfpy (MuJoCo refuses"), report.table()
    (row,) = [r for r in report.rows if r.check == "URDF: our URDF loads in MuJoCo"]
    assert row.ok and not row.applicable, report.table()
    assert report.ok and report.input_error is None, report.table()
    assert any("non-physical inertia" in w for w in report.warnings), report.warnings


@pytest.mark.realdata
def test_corpus_finger_edu_urdf_refused_like_the_source(capsys: pytest.CaptureFixture) -> None:
    path = ERD / "finger_edu_description/robots/finger_edu.urdf"
    if not path.is_file():
        pytest.skip(f"example-robot-data absent: {path}")
    assert main(["roundtrip", str(path), "--configs", "2"]) == 0
    assert "n/a  URDF: our URDF loads in MuJoCo" in capsys.readouterr().out
