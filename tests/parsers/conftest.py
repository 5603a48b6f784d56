"""Fixtures of the parser tests: small MJCF models written to a temporary folder."""

from __future__ import annotations

import logging
from pathlib import Path

import mujoco
import numpy as np
import pytest
import trimesh

MODEL = """<mujoco model="probe">
  <compiler angle="degree"/>
  <option timestep="0.004" gravity="0 0 -9.7"/>
  <default>
    <joint damping="0.3" armature="0.01"/>
    <default class="leg"><joint range="-45 45" frictionloss="0.2"/>
      <geom rgba="0.1 0.2 0.3 1" friction="0.8 0.01 0.001" condim="4" group="1"/></default>
  </default>
  <asset><mesh name="tet" file="tet.stl" scale="0.5 0.5 2"/>
    <material name="shiny" rgba="0.9 0.8 0.7 1"/></asset>
  <worldbody>
    <geom name="floor" type="plane" size="5 5 .1"/>
    <light pos="0 0 3"/>
    <body name="torso" pos="0 0 1" euler="0 0 30">
      <freejoint name="root"/>
      <geom type="capsule" fromto="0 -.1 0 0 .1 0" size=".05" mass="3"/>
      <geom type="mesh" mesh="tet" pos=".1 0 0" euler="10 20 30" material="shiny"/>
      <site name="imu" pos="0 0 .05" euler="0 90 0"/>
      <body name="hip" pos="0 .1 -.1" childclass="leg">
        <joint name="hip_x" axis="1 0 0"/>
        <joint name="hip_y" axis="0 1 0" pos="0 0 .01"/>
        <geom type="box" size=".02 .03 .1" pos="0 0 -.1"/>
        <body name="shin" pos="0 0 -.2">
          <joint name="knee" type="slide" axis="0 0 1" range="-.05 .05"/>
          <geom type="cylinder" fromto="0 0 0 0 0 -.2" size=".02"/>
          <site name="foot" pos="0 0 -.2"/>
          <body name="ankle" pos="0 0 -.2"><joint name="ankle" type="ball" range="0 30"/>
            <geom type="sphere" size=".03" mass=".2"/></body>
        </body>
      </body>
      <body name="arm" pos="0 -.1 0" quat="0.9 0.1 0.2 0.3">
        <joint name="shoulder" axis="0 1 0" stiffness="2" springref="10" ref="5"/>
        <geom type="ellipsoid" size=".03 .04 .05"/>
      </body>
    </body>
  </worldbody>
  <tendon><fixed name="coupling" stiffness="3.14159265358979" springlength="0.1">
      <joint joint="hip_x" coef="1"/><joint joint="shoulder" coef="-0.123456789012345"/></fixed>
    <spatial name="cable" width="0.004" rgba="0.1 0.9 0.2 1" range="0 2" damping="0.7">
      <site site="imu"/><site site="foot"/><pulley divisor="2"/><site site="foot"/><site site="imu"/>
    </spatial>
  </tendon>
  <equality><joint joint1="hip_y" joint2="hip_x" polycoef="0.123456789012345 2.71828182845905 0 0 0"/>
    <weld body1="arm" body2="torso" solref="0.01 1.3"/>
    <weld body1="ankle" body2="shin" relpose="0 0 -.2 1 0 0 0" torquescale="0.5"/>
    <connect body1="shin" body2="hip" anchor="0 0 -.1" active="false"/></equality>
  <contact><exclude body1="torso" body2="hip"/></contact>
  <actuator>
    <motor name="m_hip" joint="hip_x" gear="40" ctrlrange="-1 1"/>
    <position name="p_knee" joint="knee" kp="300" kv="5" forcerange="-90 90"/>
    <velocity name="v_sh" joint="shoulder" kv="12"/>
  </actuator>
  <sensor>
    <gyro name="gyro" site="imu"/>
    <framequat name="fq" objtype="site" objname="foot" reftype="body" refname="torso"/>
    <jointpos name="jp" joint="knee" noise="0.01"/>
    <touch name="touch" site="foot"/>
  </sensor>
  <keyframe><key name="home" qpos="0 0 1 1 0 0 0 .1 .2 .01 1 0 0 0 .3" ctrl=".5 .01 0"/></keyframe>
</mujoco>
"""


def _tet_stl(path: Path) -> None:
    """A binary STL tetrahedron (MuJoCo reads binary STL only) with well separated
    principal moments, so that its principal axes are well conditioned."""
    tet = trimesh.Trimesh(
        vertices=[[0, 0, 0], [1, 0, 0], [0, 2.5, 0], [0, 0, 6]],
        faces=[[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]],
    )
    tet.export(str(path), file_type="stl")


@pytest.fixture
def probe(tmp_path: Path) -> Path:
    _tet_stl(tmp_path / "tet.stl")
    path = tmp_path / "probe.xml"
    path.write_text(MODEL)
    return path


ARM = """<mujoco model="arm2">
  <compiler angle="radian"/>
  <worldbody>
    <body name="base"><geom type="cylinder" size=".05 .02" mass="1"/>
      <body name="link1" pos="0 0 .05"><joint name="j1" axis="0 0 1" range="-2 2"/>
        <geom type="capsule" fromto="0 0 0 .3 0 0" size=".02"/><site name="tip1" pos=".3 0 0"/>
        <body name="link2" pos=".3 0 0"><joint name="j2" axis="0 1 0"/>
          <geom type="box" size=".1 .02 .02" pos=".1 0 0"/></body></body></body>
  </worldbody>
  <actuator><position name="a1" joint="j1" kp="50"/><motor name="a2" joint="j2"/></actuator>
</mujoco>
"""


@pytest.fixture
def arm_mjcf(tmp_path: Path) -> Path:
    path = tmp_path / "arm2.xml"
    path.write_text(ARM)
    return path


@pytest.fixture
def write_tet():
    """Writes a binary STL tetrahedron to the path given."""
    return _tet_stl


@pytest.fixture
def quiet_parsers():
    """Parser warnings off while a test runs (restored after: other tests read them).
    Real-robot tests use it: a corpus file may warn about hundreds of values."""
    logger = logging.getLogger("robotwright.parsers")
    old = logger.level
    logger.setLevel(logging.ERROR)
    yield
    logger.setLevel(old)


def _every_body_inertia(ref: mujoco.MjModel, ours: mujoco.MjModel, root: str | None) -> list[str]:
    """Bodies whose mass, centre of mass or world inertia tensor differ (1e-9 relative),
    massless ones included (the round-trip table skips bodies without mass)."""
    from robotwright.parsers.reference import view_from_model

    a, b = view_from_model(ref, root=root), view_from_model(ours)
    bad = []
    for name in a.bodies:
        if name not in b.mass:
            continue  # merged or turned into a site: the round-trip table covers it
        scale = max(1.0, abs(a.mass[name]))
        (ca, ia), (cb, ib) = a.inertia_world[name], b.inertia_world[name]
        iscale = max(np.abs(ia).max(), np.abs(ib).max(), 1e-300)
        if (
            abs(a.mass[name] - b.mass[name]) > 1e-9 * scale
            or np.abs(ia - ib).max() > 1e-9 * iscale
            or (a.mass[name] > 0 and np.abs(ca - cb).max() > 1e-9)
        ):
            bad.append(f"{name}: mass {a.mass[name]}/{b.mass[name]}, inertia {ia.diagonal()}")
    return bad


@pytest.fixture
def body_differences():
    """``(ref, ours, root) -> list[str]``: the bodies whose mass, centre of mass or world
    inertia tensor differ between two compiled models (the corpus tests' body check)."""
    return _every_body_inertia


@pytest.fixture
def layout_package():
    """``path -> {NAME: folder}``: see :func:`_named_layout_package`."""
    return _named_layout_package


def _named_layout_package(path: Path) -> dict[str, Path]:
    """The package a user names for a URDF in the ROS layout without its
    ``package.xml`` (``NAME/urdf/robot.urdf`` naming ``package://NAME/...``, as several
    wheels ship robots): ``--package NAME=DIR``. robotwright reaches ``NAME/`` by itself
    only where pip installed it (docs/security.md); the corpora are unzipped wheels."""
    folder = path.resolve().parent
    if folder.name == "urdf" and not (folder.parent / "package.xml").exists():
        return {folder.parent.name: folder.parent}
    return {}
