"""HRDF -> URDF: structure, what cannot be expressed, and two independent readers."""

from __future__ import annotations

import warnings
import xml.etree.ElementTree as ET

import mujoco
import numpy as np
import pytest

from robotwright.errors import ConversionError, ConversionWarning
from robotwright.generators import URDFHumanoidGenerator
from robotwright.generators.urdf import DUMMY_LINK_INERTIA, DUMMY_LINK_MASS
from robotwright.hrdf.model import HRDF

yourdfpy = pytest.importorskip("yourdfpy")


def _export(hrdf, path=None, **kw):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ConversionWarning)
        return URDFHumanoidGenerator.from_hrdf(hrdf).export(path, **kw)


def _yourdfpy_errors(path) -> list[str]:
    urdf = yourdfpy.URDF.load(str(path), load_meshes=False, build_scene_graph=True)
    errors: list[str] = []
    urdf.validate(validation_fn=lambda errs: errors.extend(str(e) for e in errs) or True)
    return errors


@pytest.mark.parametrize("name", ["mini_humanoid", "arm6"])
def test_bundled_urdf_valid_for_yourdfpy_and_mujoco(name, tmp_path):
    hrdf = HRDF.from_robot_name(name)
    path = tmp_path / f"{name}.urdf"
    _export(hrdf, path, add_mujoco_tag=True)
    # These robots give peak torque and velocity for every actuated joint: strictly valid.
    assert _yourdfpy_errors(path) == []
    urdf = yourdfpy.URDF.load(str(path), load_meshes=False)
    assert set(urdf.link_map) >= {b.name for b in hrdf.bodies}
    m = mujoco.MjModel.from_xml_path(str(path))
    assert m.nq == MJ_NQ[name]


MJ_NQ = {"mini_humanoid": 27, "arm6": 6}


@pytest.mark.hurodes
def test_g1_urdf_readers(g1_hrdf_dir, tmp_path):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        hrdf = HRDF.from_dir(g1_hrdf_dir)
    path = tmp_path / "g1.urdf"
    _export(hrdf, path, add_mujoco_tag=True)
    errors = _yourdfpy_errors(path)
    # hurodes' G1 has no peak velocities: the only complaint allowed is the missing
    # velocity attribute (we do not invent one).
    assert errors and all("velocity" in e for e in errors)
    urdf = yourdfpy.URDF.load(str(path), load_meshes=True)
    assert len(urdf.actuated_joint_names) == 30  # 29 hinges + the floating base
    assert mujoco.MjModel.from_xml_path(str(path)).nmesh == 36


def test_joint_types_limits_dynamics(synth_urdf_safe):
    root = ET.fromstring(_export(synth_urdf_safe))
    joints = {j.get("name"): j for j in root.findall("joint")}
    assert joints["root"].get("type") == "floating"
    assert joints["j1a"].get("type") == "revolute"
    lim = joints["j1a"].find("limit")
    assert (lim.get("lower"), lim.get("upper"), lim.get("effort")) == ("-1", "1", "5")
    assert joints["j1a"].find("dynamics").attrib == {"damping": "0.3", "friction": "0.1"}
    assert joints["j1b"].get("type") == "continuous"  # hinge without range
    assert joints["j1b"].find("limit").get("effort") == "3"  # from the force range
    assert joints["j2"].get("type") == "prismatic"
    assert joints["tool_fixed_joint"].get("type") == "fixed"
    assert joints["tool_tip_joint"].get("type") == "fixed"  # site as frame link
    # link1 has two joints: j1a -> link1_dummy1 -> j1b -> link1
    assert joints["j1a"].find("child").get("link") == "link1_dummy1"
    assert joints["j1b"].find("parent").get("link") == "link1_dummy1"


def test_dummy_links_carry_tiny_mass_and_are_reported(synth_urdf_safe):
    """MuJoCo refuses and SDFormat drops massless moving links: dummy links always get
    1e-9 kg (with or without the MuJoCo tag), and the warning names them."""
    with pytest.warns(ConversionWarning, match=r"body 'link1' .*'link1_dummy1'.* 1e-09 kg"):
        text = URDFHumanoidGenerator.from_hrdf(synth_urdf_safe).export()
    for root in (ET.fromstring(text), ET.fromstring(_export(synth_urdf_safe, add_mujoco_tag=True))):
        dummy = next(link for link in root.findall("link") if link.get("name") == "link1_dummy1")
        assert float(dummy.find("inertial/mass").get("value")) == DUMMY_LINK_MASS
        assert float(dummy.find("inertial/inertia").get("ixx")) == DUMMY_LINK_INERTIA
    assert root.find("mujoco/compiler").get("strippath") == "false"


def test_anchor_off_body_origin_ends_in_dummy_and_fixed_joint(synth_urdf_safe):
    # link3's hinge is anchored at (0, 0, 0.01): link3's link keeps the body frame.
    root = ET.fromstring(_export(synth_urdf_safe))
    joints = {j.get("name"): j for j in root.findall("joint")}
    assert joints["j3"].find("child").get("link") == "link3_dummy1"
    anchor = joints["link3_anchor_joint"]
    assert anchor.get("type") == "fixed"
    assert anchor.find("child").get("link") == "link3"
    assert [float(v) for v in anchor.find("origin").get("xyz").split()] == [0, 0, -0.01]


def test_full_inertia_tensor(synth_urdf_safe):
    root = ET.fromstring(_export(synth_urdf_safe))
    base = next(link for link in root.findall("link") if link.get("name") == "base")
    inertia = base.find("inertial/inertia").attrib
    # base's inertial frame is rotated 0.2 rad about x: a non-zero product of inertia.
    assert float(inertia["iyz"]) != 0.0
    c, s = np.cos(0.2), np.sin(0.2)
    r = np.array([[1, 0, 0], [0, c, -s], [0, s, c]])
    expected = r @ np.diag([0.01, 0.02, 0.015]) @ r.T
    assert float(inertia["iyy"]) == pytest.approx(expected[1, 1], abs=1e-15)
    assert float(inertia["iyz"]) == pytest.approx(expected[1, 2], abs=1e-15)


def test_visual_vs_collision_and_capsule(synth_urdf_safe):
    with pytest.warns(
        ConversionWarning, match="capsule 'link2_caps'.*cylinder plus two end spheres"
    ):
        text = URDFHumanoidGenerator.from_hrdf(synth_urdf_safe).export()
    root = ET.fromstring(text)
    links = {link.get("name"): link for link in root.findall("link")}
    assert links["base"].find("visual/geometry/mesh").get("scale") == "1 2 1"
    assert links["base"].find("collision") is None  # contype = conaffinity = 0
    caps = links["link2"].findall("collision")
    shapes = sorted(c.find("geometry")[0].tag for c in caps)
    assert shapes == ["cylinder", "sphere", "sphere"]
    assert caps[0].find("geometry/cylinder").attrib == {"radius": "0.02", "length": "0.16"}


def test_ball_joint_ellipsoid_restitution_reported(synth):
    with pytest.warns(ConversionWarning) as rec:
        text = URDFHumanoidGenerator.from_hrdf(synth).export()
    message = str(rec[0].message)
    assert "ball joint 'j3'" in message
    assert "value(s) not written" in message
    root = ET.fromstring(text)
    names = {j.get("name") for j in root.findall("joint")}
    assert {"j3_x", "j3_y", "j3_z"} <= names
    assert not any(e.tag == "ellipsoid" for e in root.iter())
    with pytest.raises(ConversionError) as err:
        URDFHumanoidGenerator.from_hrdf(synth).export(strict=True)
    text = str(err.value)
    for what in ("ellipsoid", "restitution", "armature", "sensor 'tip_pos'", "mjcf_extra"):
        assert what in text


def test_site_name_equal_to_body_name_gets_site_suffix(synth_urdf_safe):
    import dataclasses

    site = dataclasses.replace(synth_urdf_safe.sites[0], name="link1")
    body_link = dataclasses.replace(site, name="link2_site", body="link2")
    bad = dataclasses.replace(synth_urdf_safe, sites=[site, body_link], sensors=[])
    with pytest.warns(ConversionWarning, match=r"renamed.*'link1' -> 'link1_site'"):
        root = ET.fromstring(URDFHumanoidGenerator.from_hrdf(bad).export())
    names = [link.get("name") for link in root.findall("link")]
    assert len(names) == len(set(names))
    joints = {j.get("name"): j for j in root.findall("joint")}
    assert joints["link1_site_joint"].find("parent").get("link") == "tool"  # the site's body
    assert joints["link1_site_joint"].find("child").get("link") == "link1_site"
    assert joints["link2_site_joint"].find("child").get("link") == "link2_site"
    # Deterministic: the same names every time.
    again = ET.fromstring(_export(bad))
    assert [link.get("name") for link in again.findall("link")] == names


def test_urdf_prefix_names_links_joints_materials(synth_urdf_safe):
    root = ET.fromstring(_export(synth_urdf_safe, prefix="r"))
    names = [e.get("name") for e in root if e.tag in ("link", "joint", "material")]
    assert all(n == "world" or n.startswith("r_") for n in names), names
    refs = [e.get("link") for e in root.iter() if e.tag in ("parent", "child")]
    assert all(r == "world" or r.startswith("r_") for r in refs)


def test_dummy_and_frame_link_maps(synth_urdf_safe):
    """Readers of the file can tell added links from bodies: dummy links name the body
    they split, frame links the site they carry (prefixed like every link)."""
    import dataclasses

    site = dataclasses.replace(synth_urdf_safe.sites[0], name="link1")
    hrdf = dataclasses.replace(synth_urdf_safe, sites=[site], sensors=[])
    gen = URDFHumanoidGenerator.from_hrdf(hrdf)
    assert gen.dummy_links == {} and gen.frame_links == {}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ConversionWarning)
        root = ET.fromstring(gen.export(prefix="r"))
    # link1: two joints, the last anchored off the origin; link3: one anchored hinge.
    assert gen.dummy_links == {
        "r_link1_dummy1": "link1",
        "r_link1_dummy2": "link1",
        "r_link3_dummy1": "link3",
    }
    assert gen.frame_links["link1"] == "r_link1_site"
    links = {link.get("name") for link in root.findall("link")}
    assert set(gen.dummy_links) | set(gen.frame_links.values()) <= links
    bodies = {f"r_{b.name}" for b in hrdf.bodies}
    assert links == bodies | set(gen.dummy_links) | set(gen.frame_links.values()) | {"world"}
    gen.destroy()
    assert gen.dummy_links == {} and gen.frame_links == {}
