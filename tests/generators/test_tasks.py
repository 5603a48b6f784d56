"""``export_robot`` and ``compose_scene`` (used by ``robotwright demo``)."""

from __future__ import annotations

import mujoco
import pytest

from robotwright.errors import GeneratorError
from robotwright.tasks import compose_scene, export_robot

pytestmark = pytest.mark.filterwarnings("ignore::UserWarning")


def test_export_robot_writes_loadable_pair(synth, tmp_path):
    paths = export_robot(synth, tmp_path / "out")
    assert paths == {
        "mjcf": tmp_path / "out" / "synth.xml",
        "urdf": tmp_path / "out" / "synth.urdf",
    }
    (synth.root_dir / "meshes" / "box.stl").unlink()  # the folder is self-contained
    mj = mujoco.MjModel.from_xml_path(str(paths["mjcf"]))
    ur = mujoco.MjModel.from_xml_path(str(paths["urdf"]))
    assert ur.body_mass.sum() == pytest.approx(mj.body_mass.sum(), abs=1e-6)


@pytest.mark.parametrize("fmt,suffix", [("mjcf", "xml"), ("urdf", "urdf")])
def test_compose_scene_places_robots(fmt, suffix, tmp_path):
    out = compose_scene(
        {"a": "arm6", "b": "arm6"},
        tmp_path / f"scene.{suffix}",
        {"b": (1.0, 0.0, 0.0, 0.5)},
        fmt=fmt,
    )
    m = mujoco.MjModel.from_xml_path(str(out))
    d = mujoco.MjData(m)
    mujoco.mj_forward(m, d)
    assert d.xpos[m.body("b_base_link").id][0] == pytest.approx(1.0)
    assert m.nu == (12 if fmt == "mjcf" else 0)  # URDF carries no actuators


def test_compose_scene_bad_format(tmp_path):
    with pytest.raises(GeneratorError, match="format 'sdf'"):
        compose_scene({"a": "arm6"}, tmp_path / "x.sdf", fmt="sdf")
