"""``--strict`` is a physics gate: it passes conversions whose notes are cosmetic (a name
given, a material reduced to its colour, a light dropped, an element carried in another
exact form) and fails those that change what MuJoCo simulates; ``--strict-all`` fails on
cosmetic notes too. Notes say which kind they are."""

from __future__ import annotations

import subprocess
import sys

import pytest

COSMETIC = """<mujoco model="c">
  <asset>
    <material name="shiny" rgba="0.2 0.4 0.6 1" specular="0.9" shininess="0.8"/>
  </asset>
  <worldbody>
    <light pos="0 0 3"/>
    <body name="b" pos="0 0 1">
      <freejoint/>
      <geom type="box" size="0.1 0.1 0.1" material="shiny"/>
    </body>
  </worldbody>
</mujoco>
"""

PHYSICAL = """<mujoco model="p">
  <worldbody>
    <body name="b" pos="0 0 1">
      <freejoint name="root"/>
      <geom type="box" size="0.1 0.1 0.1" fluidshape="ellipsoid"/>
    </body>
  </worldbody>
</mujoco>
"""


def _convert(tmp_path, text, *flags):
    (tmp_path / "src.xml").write_text(text)
    return subprocess.run(
        [sys.executable, "-m", "robotwright", "convert", "src.xml", "-o", "out.xml", "-v", *flags],
        capture_output=True,
        text=True,
        cwd=tmp_path,
    )


def test_cosmetic_notes_pass_strict_and_say_so(tmp_path):
    run = _convert(tmp_path, COSMETIC, "--strict")
    assert run.returncode == 0, run.stderr
    notes = [ln for ln in run.stderr.splitlines() if ln.startswith("note:")]
    assert len(notes) == 3 and all("(cosmetic)" in ln for ln in notes), notes
    assert (tmp_path / "out.xml").is_file()


def test_strict_all_fails_on_cosmetic_notes(tmp_path):
    run = _convert(tmp_path, COSMETIC, "--strict-all")
    assert run.returncode == 2
    assert "unnamed joint" in run.stderr and "(cosmetic)" in run.stderr
    assert "Traceback" not in run.stderr and not (tmp_path / "out.xml").exists()


@pytest.mark.parametrize("flag", ["--strict", "--strict-all"])
def test_a_physical_loss_fails_both(tmp_path, flag):
    run = _convert(tmp_path, PHYSICAL, flag)
    assert run.returncode == 2
    assert "fluid" in run.stderr and "(cosmetic)" not in run.stderr
    assert not (tmp_path / "out.xml").exists()


def test_strict_and_strict_all_exclude_each_other(tmp_path):
    run = _convert(tmp_path, PHYSICAL, "--strict", "--strict-all")
    assert run.returncode == 2 and "--strict-all" in run.stderr
    assert not (tmp_path / "out.xml").exists()


def test_an_output_of_no_kind_is_refused_before_overwrite_is_asked(tmp_path):
    (tmp_path / "existing.png").write_bytes(b"\x89PNG")
    run = _convert(tmp_path, PHYSICAL, "-o", "existing.png")
    assert run.returncode == 2
    assert "expected a .urdf" in run.stderr and "--overwrite" not in run.stderr
    assert (tmp_path / "existing.png").read_bytes() == b"\x89PNG"
