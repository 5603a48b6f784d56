"""HRDF -> URDF: structure, what cannot be expressed, and two independent readers."""

from __future__ import annotations

import dataclasses
import warnings
import xml.etree.ElementTree as ET

import mujoco
import numpy as np
import pytest

from robotwright.errors import ConversionError, ConversionWarning
from robotwright.generators import URDFHumanoidGenerator
from robotwright.generators.urdf import (
    DUMMY_LINK_INERTIA,
    DUMMY_LINK_MASS,
    MUJOCO_DRAWN_GROUPS,
    drawn_by_mujoco,
)
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
    hinges = sum(1 for j in hrdf.joints if j.type == "hinge")
    assert hinges == 29 and len(urdf.actuated_joint_names) == hinges + 1  # + floating base
    g1_meshes = len(list((g1_hrdf_dir / "meshes").iterdir()))
    assert g1_meshes > 30 and mujoco.MjModel.from_xml_path(str(path)).nmesh == g1_meshes


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


# -- visuals: every geom MuJoCo draws ---------------------------------------------------------
def _elements(g) -> int:
    """URDF elements one geom becomes: a capsule is a cylinder plus two end spheres."""
    return {"capsule": 3, "ellipsoid": 0}.get(getattr(g, "type", "mesh"), 1)


def _expected_per_link(hrdf: HRDF) -> dict[str, tuple[list[tuple[float, ...]], int]]:
    """Per link: the rgba of each expected <visual> and the number of <collision>s."""
    out: dict[str, tuple[list[tuple[float, ...]], int]] = {b.name: ([], 0) for b in hrdf.bodies}
    for g in [*hrdf.meshes, *hrdf.simple_geoms]:
        colours, ncol = out[g.body]
        collide = bool(g.contact_type or g.contact_affinity)
        if drawn_by_mujoco(g) or not collide:
            colours.extend([tuple(g.rgba)] * _elements(g))
        out[g.body] = (colours, ncol + (_elements(g) if collide else 0))
    return out


def test_drawn_by_mujoco_follows_the_default_viewer() -> None:
    from robotwright.hrdf.model import SimpleGeom

    g = SimpleGeom(body="b", type="sphere", size=(0.1, 0, 0))
    assert MUJOCO_DRAWN_GROUPS == (0, 1, 2)
    assert drawn_by_mujoco(g) and drawn_by_mujoco(dataclasses.replace(g, group=2))
    assert not drawn_by_mujoco(dataclasses.replace(g, group=3))
    assert not drawn_by_mujoco(dataclasses.replace(g, group=5))
    assert not drawn_by_mujoco(dataclasses.replace(g, rgba=(1.0, 0.0, 0.0, 0.0)))
    # The viewer's defaults, read from MuJoCo itself.
    assert tuple(np.flatnonzero(mujoco.MjvOption().geomgroup)) == MUJOCO_DRAWN_GROUPS


@pytest.mark.parametrize("name", ["arm6", "mini_humanoid"])
def test_bundled_urdf_has_a_visual_per_drawn_geom(name, tmp_path):
    """arm6's geoms all collide: each is written as a visual (with its colour) and a
    collision; yourdfpy's scene (built from visuals, as RViz draws) holds every one."""
    hrdf = HRDF.from_robot_name(name)
    path = tmp_path / f"{name}.urdf"
    _export(hrdf, path)
    root = ET.parse(path).getroot()
    colours = {
        m.get("name"): tuple(float(v) for v in m.find("color").get("rgba").split())
        for m in root.findall("material")
    }
    expected = _expected_per_link(hrdf)
    n_visuals = 0
    for link in root.findall("link"):
        want_colours, want_collisions = expected.get(link.get("name"), ([], 0))
        got = [colours[v.find("material").get("name")] for v in link.findall("visual")]
        assert sorted(got) == sorted(want_colours), link.get("name")
        assert len(link.findall("collision")) == want_collisions, link.get("name")
        n_visuals += len(got)
    assert n_visuals >= len(hrdf.simple_geoms) > 0
    urdf = yourdfpy.URDF.load(str(path), load_meshes=False)
    assert len(urdf.scene.geometry) == n_visuals
    seen = sum(len(link.visuals) for link in urdf.robot.links)
    assert seen == n_visuals


def _geoms_of(model: mujoco.MjModel) -> dict[str, dict]:
    """Compiled geoms by name: type, size, pose in the body, contacts, colour, drawn."""
    out = {}
    for i in range(model.ngeom):
        g = model.geom(i)
        used = {2: 1, 3: 2, 5: 2, 7: 0}.get(int(g.type[0]), 3)
        out[g.name] = {
            "body": model.body(int(g.bodyid[0])).name,
            "type": int(g.type[0]),
            "size": g.size[:used].copy(),
            "pos": g.pos.copy(),
            "quat": g.quat.copy(),
            "contact": (int(g.contype[0]), int(g.conaffinity[0]), int(g.condim[0])),
            "friction": g.friction.copy(),
            "rgba": g.rgba.copy(),
            "drawn": int(g.group[0]) in MUJOCO_DRAWN_GROUPS and g.rgba[3] > 0,
        }
    return out


def _urdf_roundtrip(hrdf: HRDF, tmp_path, tag: str) -> HRDF:
    from robotwright.parsers import urdf_to_hrdf

    path = tmp_path / f"{tag}.urdf"
    _export(hrdf, path)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return urdf_to_hrdf(path, fixed_joints="site")


def _assert_same_geom(a: dict, b: dict, what: str) -> None:
    assert (a["body"], a["type"], a["contact"], a["drawn"]) == (
        b["body"],
        b["type"],
        b["contact"],
        b["drawn"],
    ), what
    for key in ("size", "pos", "friction", "rgba"):
        np.testing.assert_array_equal(a[key], b[key], err_msg=f"{what} {key}")
    # q and -q are one rotation
    sign = 1.0 if np.dot(a["quat"], b["quat"]) >= 0 else -1.0
    np.testing.assert_allclose(a["quat"], sign * b["quat"], atol=1e-15, err_msg=what)


@pytest.mark.parametrize("name", ["arm6", "mini_humanoid"])
def test_bundled_hrdf_urdf_hrdf_round_trip_is_exact(name, tmp_path):
    """HRDF -> URDF (visual + collision pairs) -> HRDF, both compiled by MuJoCo: the same
    bodies, masses, inertias and FK, and every geom again once with its type, size, pose,
    contact bits, friction and colour, drawn where it was drawn. A capsule comes back as
    the cylinder and two end spheres URDF holds it as (the same solid; reported)."""
    from robotwright.parsers.reference import view_from_model
    from robotwright.proof.roundtrip.run import compare_views, our_mjcf_model

    hrdf = HRDF.from_robot_name(name)
    back = _urdf_roundtrip(hrdf, tmp_path, name)
    # A URDF joint has a name: an unnamed free joint comes back as "floating_base".
    free = [j.name for j in hrdf.joints if j.type == "free"]
    if free == [None]:
        assert [j.name for j in back.joints if j.type == "free"] == ["floating_base"]
        joints = [dataclasses.replace(j, name=None) if j.type == "free" else j for j in back.joints]
        back = dataclasses.replace(back, joints=joints)
    ref_model, our_model = our_mjcf_model(hrdf), our_mjcf_model(back)
    rows = compare_views(view_from_model(ref_model), view_from_model(our_model), configs=10)
    kept = ("bodies", "body masses", "inertia", "centres", "FK", "joints", "joint types")
    checked = [r for r in rows if r.check.startswith((*kept, "joint axes", "joint ranges"))]
    assert len(checked) == 9 and all(r.ok for r in checked), checked  # armature: no URDF form
    ref, ours = _geoms_of(ref_model), _geoms_of(our_model)
    capsules = [n for n, g in ref.items() if g["type"] == mujoco.mjtGeom.mjGEOM_CAPSULE]
    assert set(ours) == (set(ref) - set(capsules)) | {
        f"{n}{end}" for n in capsules for end in ("", "_end1", "_end2")
    }
    for n, g in ref.items():
        if n not in capsules:
            _assert_same_geom(g, ours[n], n)
            continue
        cyl = dict(g, type=int(mujoco.mjtGeom.mjGEOM_CYLINDER))
        _assert_same_geom(cyl, ours[n], n)
        r, half = g["size"]
        axis = np.zeros(3)
        mujoco.mju_rotVecQuat(axis, np.array([0.0, 0.0, 1.0]), g["quat"])
        for end, sign in (("_end1", 1.0), ("_end2", -1.0)):
            s = ours[f"{n}{end}"]
            assert s["type"] == mujoco.mjtGeom.mjGEOM_SPHERE and s["size"][0] == r
            assert (s["contact"], s["drawn"]) == (g["contact"], g["drawn"])
            np.testing.assert_array_equal(s["rgba"], g["rgba"])
            np.testing.assert_allclose(s["pos"], g["pos"] + sign * half * axis, atol=1e-15)
    # A second trip changes nothing at all: the URDF form is a fixed point.
    again = _geoms_of(our_mjcf_model(_urdf_roundtrip(back, tmp_path, f"{name}_2")))
    assert set(again) == set(ours)
    for n, g in ours.items():
        _assert_same_geom(g, again[n], n)


def test_mujoco_imports_our_urdf_with_its_visuals(tmp_path, capfd):
    """MuJoCo's own URDF importer: with our MuJoCo tag (visuals kept) each drawn
    colliding geom is a collision geom and a visual geom, the name on the collision one,
    and MuJoCo warns about no duplicate name; without the tag (its default, visuals
    dropped) the collision geoms carry the HRDF names."""
    hrdf = HRDF.from_robot_name("arm6")
    tagged, plain = tmp_path / "tagged.urdf", tmp_path / "plain.urdf"
    _export(hrdf, tagged, add_mujoco_tag=True)
    _export(hrdf, plain)
    capfd.readouterr()
    with_visuals = mujoco.MjModel.from_xml_path(str(tagged))
    default = mujoco.MjModel.from_xml_path(str(plain))
    warned = "".join(capfd.readouterr())
    # MuJoCo 3.x's importer warns about cylinders' names even though only the
    # <collision> carries one (4.x does not); the geoms it builds are the same.
    if int(mujoco.__version__.split(".")[0]) >= 4:
        assert "duplicate name" not in warned
    n = sum(_elements(g) for g in hrdf.simple_geoms)
    colliding = with_visuals.geom_contype != 0
    assert colliding.sum() == n and (~colliding).sum() == n
    assert default.ngeom == n and (default.geom_contype == 1).all()
    names = {default.geom(i).name for i in range(default.ngeom)}
    assert {g.name for g in hrdf.simple_geoms} <= names
    # The visual geoms have the HRDF colours.
    want = sorted(tuple(g.rgba) for g in hrdf.simple_geoms for _ in range(_elements(g)))
    got = sorted(
        tuple(float(v) for v in with_visuals.geom_rgba[i]) for i in np.flatnonzero(~colliding)
    )
    assert np.allclose(got, want, atol=1e-7)
    # Visual geoms add no mass: the links' <inertial> holds it all.
    total = sum(b.mass for b in hrdf.bodies)
    assert with_visuals.body_mass.sum() == pytest.approx(total, rel=1e-12)


def test_hidden_and_transparent_geoms(synth_urdf_safe):
    """A colliding geom MuJoCo hides (group 3 or alpha 0) is a collision only; one that
    neither collides nor is drawn keeps a visual (nothing is lost) and the warning says
    URDF viewers show it."""
    from robotwright.hrdf.model import SimpleGeom

    extra = [
        SimpleGeom(body="link3", name="hidden_col", type="box", size=(0.01, 0.02, 0.03), group=3),
        SimpleGeom(body="link3", name="clear_col", type="sphere", size=(0.01, 0, 0),
                   rgba=(1.0, 0.0, 0.0, 0.0)),
        SimpleGeom(body="link3", name="marker", type="sphere", size=(0.02, 0, 0), group=4,
                   contact_type=0, contact_affinity=0),
    ]  # fmt: skip
    hrdf = dataclasses.replace(
        synth_urdf_safe, simple_geoms=[*synth_urdf_safe.simple_geoms, *extra]
    )
    with pytest.warns(ConversionWarning) as rec:
        root = ET.fromstring(URDFHumanoidGenerator.from_hrdf(hrdf).export())
    message = "\n".join(str(r.message) for r in rec)
    assert "group 4 (hidden by MuJoCo's default viewer; written as a <visual>" in message
    assert "colour (not drawn by MuJoCo" in message
    link3 = next(link for link in root.findall("link") if link.get("name") == "link3")
    named = {e.get("name"): e.tag for e in link3 if e.get("name")}
    assert named["hidden_col"] == named["clear_col"] == "collision"
    assert named["marker"] == "visual"
    visual_shapes = [v.find("geometry")[0].tag for v in link3.findall("visual")]
    assert sorted(visual_shapes) == ["sphere", "sphere"]  # link3_ball (drawn) and marker
