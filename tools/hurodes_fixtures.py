"""HRDF folders written by hurodes 0.1.9 itself, for the compatibility and equivalence
tests and the benchmarks (called by ``fetch_test_data.py``).

Output, under ``.testdata/hurodes-fixtures/``:

- ``g1_29/``: the Unitree G1 (29 DoF, floating base) as hurodes' MJCF parser converts it,
  plus ``g1_29/exported/robot.xml``, the MJCF that hurodes' ``MJCFHumanoidGenerator``
  exports from that folder (meshdir ``../meshes``).
- ``synth_baseline_hinge/``: a two-body hinge robot (one mesh geom, one capsule, one motor).
- ``sources/``: the MJCF files hurodes was given; tests compile them with MuJoCo to derive
  what the folders must hold (masses, counts, tree) instead of hard-coding numbers.

The G1 is mjlab's MJCF (``.testdata/mjlab``). That file has no actuators (mjlab adds
them in Python), and hurodes takes a robot's motors from the MJCF's ``<actuator>``
section, so one ``<motor>`` per hinge is added with ``ctrlrange`` = ± the joint's effort
limit from Unitree's G1 URDF in ``example-robot-data`` (the ``test`` extra): the same
robot, joints of the same names. Nothing else of mjlab's file is changed; its meshes are
read in place (``sources/g1_29.xml`` points at them).

Cached: ``.hurodes-fixtures.json`` records hurodes' version and a hash of everything the
result depends on (source MJCF texts, mesh bytes, the writer script); a re-run with the
same inputs keeps the folders (about 2 s to check) instead of running hurodes again.
"""

from __future__ import annotations

import hashlib
import json
import os
import shutil
import subprocess
import sysconfig
import xml.etree.ElementTree as ET
from pathlib import Path

import defusedxml.ElementTree as SafeET

HURODES_VERSION = "0.1.9"
WRITER = Path(__file__).resolve().with_name("hurodes_write_fixture.py")
MJLAB_G1 = Path("mjlab/mjlab/asset_zoo/robots/unitree_g1/xmls/g1.xml")
ERD_G1_URDF = (
    Path(sysconfig.get_paths()["purelib"])
    / "cmeel.prefix/share/example-robot-data/robots/g1_description/urdf/g1_29dof_rev_1_0.urdf"
)

#: The synthetic robot: a floating base with a box mesh, one hinged capsule link, a motor.
SYNTH_MJCF = """<mujoco model="synth_baseline_hinge">
  <compiler angle="radian" meshdir="meshes"/>
  <option timestep="0.002"/>
  <asset>
    <mesh name="box" file="box.stl"/>
  </asset>
  <worldbody>
    <body name="base" pos="0 0 1">
      <freejoint/>
      <inertial pos="0 0 0" mass="1" diaginertia="0.01 0.01 0.01"/>
      <geom type="mesh" mesh="box" rgba="0.5 0.5 0.5 1"/>
      <body name="l1" pos="0 0 -0.2">
        <inertial pos="0 0 0" mass="1" diaginertia="0.01 0.01 0.01"/>
        <joint name="j1" axis="0 1 0" range="-1 1"/>
        <geom type="capsule" size="0.02 0.1" rgba="0.5 0.5 0.5 1"/>
      </body>
    </body>
  </worldbody>
  <actuator>
    <motor joint="j1" ctrlrange="-5 5" ctrllimited="true"/>
  </actuator>
</mujoco>
"""


def _g1_effort_limits(urdf: Path) -> dict[str, float]:
    """Joint name -> ``<limit effort>`` (N·m) of every revolute joint of the G1 URDF."""
    limits = {}
    for joint in SafeET.parse(urdf).getroot().iter("joint"):
        limit = joint.find("limit")
        if joint.get("type") == "revolute" and limit is not None and limit.get("effort"):
            limits[joint.get("name")] = float(limit.get("effort"))
    return limits


def g1_source_mjcf(testdata: Path, sources: Path) -> str:
    """mjlab's G1 with a ``<motor>`` per hinge, meshdir relative to ``sources``."""
    src = testdata / MJLAB_G1
    for path, why in ((src, "run fetch_mjlab first"), (ERD_G1_URDF, "install the test extra")):
        if not path.is_file():
            raise SystemExit(f"hurodes fixtures: {path} is absent ({why})")
    root = SafeET.parse(src).getroot()
    compiler = root.find("compiler")
    if compiler is None or root.find("actuator") is not None:
        raise SystemExit(f"{src}: expected a <compiler> and no <actuator> (mjlab's G1)")
    meshdir = src.parent / compiler.get("meshdir", "")
    compiler.set("meshdir", os.path.relpath(meshdir, sources))
    efforts = _g1_effort_limits(ERD_G1_URDF)
    actuator = ET.SubElement(root, "actuator")
    for joint in root.find("worldbody").iter("joint"):
        name = joint.get("name")
        if name not in efforts:
            raise SystemExit(f"{ERD_G1_URDF}: no effort limit for G1 joint {name!r}")
        e = repr(efforts[name])
        ET.SubElement(actuator, "motor", name=name, joint=name, ctrlrange=f"-{e} {e}")
    ET.indent(root)
    return ET.tostring(root, encoding="unicode") + "\n"


def _write_sources(testdata: Path, sources: Path) -> list[Path]:
    """Write the source MJCFs (and the synthetic box mesh); return every input file."""
    import trimesh

    sources.mkdir(parents=True)
    g1 = sources / "g1_29.xml"
    g1.write_text(g1_source_mjcf(testdata, sources))
    synth = sources / "synth_baseline_hinge.xml"
    synth.write_text(SYNTH_MJCF)
    (sources / "meshes").mkdir()
    trimesh.creation.box(extents=(0.1, 0.1, 0.1)).export(sources / "meshes" / "box.stl")
    meshes = sorted((testdata / MJLAB_G1).parent.joinpath("assets").iterdir())
    return [g1, synth, sources / "meshes" / "box.stl", WRITER, *meshes]


def _digest(files: list[Path]) -> str:
    h = hashlib.sha256(HURODES_VERSION.encode())
    for f in files:
        h.update(f.name.encode() + b"\0" + f.read_bytes() + b"\0")
    return h.hexdigest()


def make_hurodes_fixtures(testdata: Path, hurodes_python: Path) -> Path:
    """Write (or keep, when up to date) ``testdata/hurodes-fixtures``; return its path."""
    dest = testdata / "hurodes-fixtures"
    marker = dest / ".hurodes-fixtures.json"
    work = testdata / ".hurodes-fixtures.tmp"  # same depth as dest: relative paths hold
    shutil.rmtree(work, ignore_errors=True)
    digest = _digest(_write_sources(testdata, work / "sources"))
    stamp = {"hurodes": HURODES_VERSION, "inputs_sha256": digest}
    made = ("g1_29/meta.yaml", "g1_29/exported/robot.xml", "synth_baseline_hinge/meta.yaml")
    if (
        marker.is_file()
        and json.loads(marker.read_text()) == stamp
        and all((dest / f).is_file() for f in made)
    ):
        shutil.rmtree(work)
        print(f"hurodes fixtures already in {dest}")
        return dest
    assets = work / "assets"
    env = {**os.environ, "HURODES_ASSETS_PATH": str(assets)}
    for name, export in (("g1_29", True), ("synth_baseline_hinge", False)):
        cmd = [str(hurodes_python), str(WRITER), str(work / "sources" / f"{name}.xml")]
        cmd += [str(assets), name] + (["--export"] if export else [])
        subprocess.run(cmd, check=True, env=env, stdout=subprocess.DEVNULL)
        (assets / "robots" / name).rename(work / name)
    shutil.rmtree(assets)
    (work / ".hurodes-fixtures.json").write_text(json.dumps(stamp, indent=1) + "\n")
    shutil.rmtree(dest, ignore_errors=True)
    work.rename(dest)
    print(f"hurodes {HURODES_VERSION} wrote the G1 and synthetic fixtures into {dest}")
    return dest
