"""Sites of the world (an IMU frame such as Menagerie's ``world:origin`` with its gyro and
accelerometer) travel with the robot: ``site.csv`` ``body_name`` ``world``; they used to
be dropped with their sensors."""

from __future__ import annotations

import mujoco
import numpy as np
import pytest

from robotwright.generators import MJCFHumanoidGenerator, URDFHumanoidGenerator
from robotwright.hrdf.model import HRDF
from robotwright.parsers import mjcf_to_hrdf
from robotwright.proof.compare import compare_models
from robotwright.proof.convert import convert

WORLD_FRAME = """<mujoco model="w">
  <worldbody>
    <site name="origin" pos="0.1 0 0.2" quat="0.9238795 0 0 0.3826834"/>
    <body name="b" pos="0 0 1">
      <freejoint name="root"/>
      <geom type="sphere" size="0.05"/>
      <site name="imu" pos="0 0 0.05"/>
    </body>
  </worldbody>
  <sensor>
    <gyro name="world_gyro" site="origin"/>
    <accelerometer name="world_acc" site="origin"/>
    <framepos name="rel" objtype="site" objname="imu" reftype="site" refname="origin"/>
  </sensor>
</mujoco>
"""


@pytest.fixture
def source(tmp_path):
    (tmp_path / "w.xml").write_text(WORLD_FRAME)
    return tmp_path / "w.xml"


def _readings(model, steps=100):
    data = mujoco.MjData(model)
    for _ in range(steps):
        mujoco.mj_step(model, data)
    return data.sensordata.copy()


def test_world_sites_and_their_sensors_convert(source, tmp_path):
    convert(source, tmp_path / "out.xml", strict=True)
    src = mujoco.MjModel.from_xml_path(str(source))
    out = mujoco.MjModel.from_xml_path(str(tmp_path / "out.xml"))
    assert not compare_models(src, out)
    assert out.site_bodyid[out.site("origin").id] == 0
    assert out.nsensor == 3
    assert np.abs(_readings(src) - _readings(out)).max() < 1e-9


def test_world_sites_survive_the_folder_and_say_so_in_urdf(source, tmp_path):
    mjcf_to_hrdf(source).save(tmp_path / "folder")
    loaded = HRDF.from_dir(tmp_path / "folder")
    (origin,) = [s for s in loaded.sites if s.name == "origin"]
    assert origin.body == "world"
    text = MJCFHumanoidGenerator.from_hrdf(loaded).export(None, add_scene=False)
    assert mujoco.MjModel.from_xml_string(text).site("origin").bodyid == 0
    with pytest.warns(Warning, match="site 'origin' of the world"):
        URDFHumanoidGenerator.from_hrdf(loaded).export(tmp_path / "w.urdf")


def test_a_site_on_an_unknown_body_is_still_refused(source, tmp_path):
    mjcf_to_hrdf(source).save(tmp_path / "folder")
    table = tmp_path / "folder" / "site.csv"
    table.write_text(table.read_text().replace(",world,", ",nowhere,"))
    from robotwright.errors import HRDFError

    with pytest.raises(HRDFError, match="unknown body 'nowhere'"):
        HRDF.from_dir(tmp_path / "folder")
