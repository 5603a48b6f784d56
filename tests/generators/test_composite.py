"""Composites: several robots in one MJCF scene (and one URDF)."""

from __future__ import annotations

import dataclasses
import math
import warnings

import mujoco
import numpy as np
import pytest

from robotwright.errors import ConversionWarning, GeneratorError
from robotwright.generators import (
    MJCFGeneratorComposite,
    MJCFHumanoidGenerator,
    Placement,
    URDFGeneratorComposite,
    URDFHumanoidGenerator,
)
from robotwright.hrdf.model import HRDF

pytestmark = pytest.mark.filterwarnings("ignore::UserWarning")


def _gen(name_or_hrdf):
    if isinstance(name_or_hrdf, HRDF):
        return MJCFHumanoidGenerator.from_hrdf(name_or_hrdf)
    return MJCFHumanoidGenerator.from_robot_name(name_or_hrdf)


def _robot_of(m: mujoco.MjModel, geom: int) -> str:
    return m.body(m.body_rootid[m.geom_bodyid[geom]]).name.split("_")[0]


@pytest.mark.hurodes
def test_two_g1_and_arm_compile_no_contacts_simulate(g1_hrdf_dir, tmp_path):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        g1 = HRDF.from_dir(g1_hrdf_dir)
    comp = MJCFGeneratorComposite(
        {"a": _gen(g1), "b": _gen(g1), "arm": _gen("arm6")},
        placements={"b": Placement((1.5, 0.0, 0.0), yaw=math.pi), "arm": (0.0, 1.5, 0.0)},
    )
    out = tmp_path / "scene.xml"
    comp.export(out)
    m = mujoco.MjModel.from_xml_path(str(out))
    g1_meshes = len(list((g1_hrdf_dir / "meshes").iterdir()))
    assert g1_meshes > 30 and m.nmesh == g1_meshes  # the two G1s share their mesh assets
    assert sum(1 for i in range(m.ngeom) if m.geom(i).name == "floor") == 1
    d = mujoco.MjData(m)
    mujoco.mj_forward(m, d)
    pairs = {
        (_robot_of(m, c.geom1), _robot_of(m, c.geom2))
        for c in d.contact[: d.ncon]
        if m.geom_bodyid[c.geom1] and m.geom_bodyid[c.geom2]
    }
    assert all(a == b for a, b in pairs), pairs
    np.testing.assert_allclose(d.xpos[m.body("b_pelvis").id][:2], [1.5, 0.0], atol=1e-12)
    while d.time < 1.0:
        mujoco.mj_step(m, d)
    assert np.isfinite(d.qpos).all() and np.isfinite(d.qvel).all()


def test_placement_moves_and_turns_the_robot():
    comp = MJCFGeneratorComposite(
        {"a": _gen("mini_humanoid"), "b": _gen("mini_humanoid")},
        placements={"b": Placement((2.0, 1.0, 0.0), yaw=math.pi / 2)},
    )
    m = comp.to_model()
    d = mujoco.MjData(m)
    mujoco.mj_forward(m, d)
    pa = d.xpos[m.body("a_pelvis").id]
    pb = d.xpos[m.body("b_pelvis").id]
    np.testing.assert_allclose(pb - pa, [2.0, 1.0, 0.0], atol=1e-12)
    # b's left hand (at +y of a) is at -x of b after a quarter turn
    la = d.site_xpos[m.site("a_left_hand").id] - pa
    lb = d.site_xpos[m.site("b_left_hand").id] - pb
    np.testing.assert_allclose(lb, [-la[1], la[0], la[2]], atol=1e-12)


def test_attach_at_site_welds_robot():
    comp = MJCFGeneratorComposite(
        {"h": _gen("mini_humanoid"), "arm": _gen("arm6")},
        placements={"arm": Placement(parent="h", frame="back_mount")},
    )
    m = comp.to_model()
    d = mujoco.MjData(m)
    mujoco.mj_forward(m, d)
    assert m.body(m.body_parentid[m.body("arm_base_link").id]).name == "h_torso"
    np.testing.assert_allclose(
        d.xpos[m.body("arm_base_link").id], d.site_xpos[m.site("h_back_mount").id], atol=1e-12
    )
    assert m.nq == 27 + 6


def test_attach_unknown_frame_is_clear_error():
    comp = MJCFGeneratorComposite(
        {"h": _gen("mini_humanoid"), "arm": _gen("arm6")},
        placements={"arm": Placement(parent="h", frame="nowhere")},
    )
    with pytest.raises(GeneratorError, match="robot 'h' has no site or body named 'nowhere'"):
        comp.export()


def test_name_clash_without_prefixes_errors_before_writing(tmp_path):
    comp = MJCFGeneratorComposite({"a": _gen("arm6"), "b": _gen("arm6")})
    out = tmp_path / "scene.xml"
    with pytest.raises(GeneratorError, match=r"names used by more than one element.*base_link"):
        comp.export(out, use_keys_as_prefix=False)
    assert not out.exists()
    comp.export(out)  # with prefixes it works
    assert mujoco.MjModel.from_xml_path(str(out)).nu == 12


def test_distinct_robots_compose_without_prefixes():
    comp = MJCFGeneratorComposite(
        {"h": _gen("mini_humanoid"), "arm": _gen("arm6")}, {"arm": (1, 0, 0)}
    )
    m = comp.to_model(use_keys_as_prefix=False)
    assert m.body("pelvis").id > 0 and m.body("base_link").id > 0


def test_keyframes_merged_with_placement(synth_urdf_safe):
    home_q = [0.0, 0.0, 1.0, 1.0, 0.0, 0.0, 0.0, 0.3, -0.2, 0.05, 0.4]
    h = dataclasses.replace(
        synth_urdf_safe,
        mjcf_extra=f'<mujoco><keyframe><key name="home" qpos="{" ".join(map(str, home_q))}"/></keyframe></mujoco>',
    )
    comp = MJCFGeneratorComposite(
        {"s": _gen(h), "arm": _gen("arm6")},
        placements={"s": Placement((1.0, 2.0, 0.0), yaw=math.pi / 2)},
    )
    m = comp.to_model()
    assert m.nkey == 1 and m.key("home").id == 0
    d = mujoco.MjData(m)
    mujoco.mj_resetDataKeyframe(m, d, 0)
    q = d.qpos
    root = m.joint("s_root").qposadr[0]
    np.testing.assert_allclose(q[root : root + 3], [1.0, 2.0, 1.0], atol=1e-12)
    np.testing.assert_allclose(
        q[root + 3 : root + 7], [math.cos(math.pi / 4), 0, 0, math.sin(math.pi / 4)], atol=1e-12
    )
    assert q[m.joint("s_j1a").qposadr[0]] == 0.3
    assert q[m.joint("s_j3").qposadr[0]] == 0.4
    assert all(q[m.joint(f"arm_{j}").qposadr[0]] == 0.0 for j in ("elbow_joint", "wrist_1_joint"))


def test_composite_loaded_and_lifecycle():
    a, b = MJCFHumanoidGenerator(), MJCFHumanoidGenerator.from_robot_name("arm6")
    comp = MJCFGeneratorComposite({"a": a, "b": b})
    assert not comp.loaded
    with pytest.raises(GeneratorError, match=r"\['a'\] not loaded"):
        comp.load()
    with pytest.raises(GeneratorError, match="nothing is loaded"):
        comp.export()
    a.load(HRDF.from_robot_name("mini_humanoid"))
    assert comp.loaded
    s1 = comp.export()
    comp.destroy()
    assert comp.export() == s1
    comp.clean()
    assert not a.loaded and not b.loaded and not comp.loaded


def test_rejects_non_mjcf_generator():
    with pytest.raises(GeneratorError, match="expected an MJCF generator"):
        MJCFGeneratorComposite({"u": URDFHumanoidGenerator.from_robot_name("arm6")})


@pytest.mark.parametrize(
    ("composite", "robot", "other"),
    [
        (MJCFGeneratorComposite, MJCFHumanoidGenerator, URDFHumanoidGenerator),
        (URDFGeneratorComposite, URDFHumanoidGenerator, MJCFHumanoidGenerator),
    ],
)
def test_both_composites_check_members_alike(composite, robot, other):
    """MJCF and URDF composites share one check of their robots and placements."""
    gen = robot.from_robot_name("arm6")
    with pytest.raises(GeneratorError, match=rf"{composite.__name__}: no generators given"):
        composite({})
    with pytest.raises(GeneratorError, match=rf"generator 'u' is a {other.__name__}"):
        composite({"u": other.from_robot_name("arm6")})
    with pytest.raises(GeneratorError, match=r"unknown robot 'b'; robots: \['a'\]"):
        composite({"a": gen}, placements={"b": (0, 0, 0)})
    with pytest.raises(GeneratorError, match=r"attached to unknown robot 'z'; robots: \['a'\]"):
        composite({"a": gen}, placements={"a": Placement(parent="z", frame="f")})
    with pytest.raises(GeneratorError, match=r"placement of 'a': expected \(x, y, z\[, yaw\]\)"):
        composite({"a": gen}, placements={"a": (1, 2)})
    comp = composite([gen, gen], placements={"generator1": (1.0, 2.0, 3.0, 0.5)})
    assert list(comp.generators) == ["generator0", "generator1"]
    assert comp.placements["generator1"] == Placement((1.0, 2.0, 3.0), 0.5)


def test_placement_validation():
    with pytest.raises(GeneratorError, match="3 finite numbers"):
        Placement((0.0, float("nan"), 0.0))
    with pytest.raises(GeneratorError, match="give both"):
        Placement(parent="a")
    assert Placement.parse("1,2,3,0.5") == Placement((1, 2, 3), 0.5)
    with pytest.raises(GeneratorError, match="expected x,y,z"):
        Placement.parse("1,2")


def test_copy_meshes_composite(g1_hrdf_dir, tmp_path):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        g1 = HRDF.from_dir(g1_hrdf_dir)
    out = tmp_path / "pkg" / "scene.xml"
    MJCFGeneratorComposite({"a": _gen(g1), "b": _gen("arm6")}, {"b": (1, 0, 0)}).export(
        out, copy_meshes=True
    )
    g1_meshes = len(list((g1_hrdf_dir / "meshes").iterdir()))
    assert len(list((tmp_path / "pkg" / "meshes" / "g1_29").glob("*.stl"))) == g1_meshes
    assert mujoco.MjModel.from_xml_path(str(out)).nmesh == g1_meshes


def test_urdf_composite_loads_in_mujoco_and_yourdfpy(tmp_path):
    yourdfpy = pytest.importorskip("yourdfpy")
    comp = URDFGeneratorComposite(
        {
            "h": URDFHumanoidGenerator.from_robot_name("mini_humanoid"),
            "a1": URDFHumanoidGenerator.from_robot_name("arm6"),
            "a2": URDFHumanoidGenerator.from_robot_name("arm6"),
        },
        placements={"a1": Placement(parent="h", frame="back_mount"), "a2": (1.0, 0.0, 0.0, 1.0)},
    )
    out = tmp_path / "scene.urdf"
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ConversionWarning)
        comp.export(out, add_mujoco_tag=True)
    m = mujoco.MjModel.from_xml_path(str(out))
    assert m.nq == 27 + 6 + 6
    d = mujoco.MjData(m)
    mujoco.mj_forward(m, d)
    np.testing.assert_allclose(
        d.xpos[m.body("a1_base_link").id], d.xpos[m.body("h_back_mount").id], atol=1e-12
    )
    np.testing.assert_allclose(d.xpos[m.body("a2_base_link").id], [1.0, 0.0, 0.0], atol=1e-12)
    urdf = yourdfpy.URDF.load(str(out), load_meshes=False)
    assert "a2_wrist_3_link" in urdf.link_map and "h_pelvis" in urdf.link_map
    # the mass matches the MJCF composite of the same robots
    mj = MJCFGeneratorComposite(
        {"h": _gen("mini_humanoid"), "a1": _gen("arm6"), "a2": _gen("arm6")}
    ).to_model()
    assert m.body_mass.sum() == pytest.approx(mj.body_mass.sum(), abs=1e-6)


def test_placement_full_orientation():
    q = (math.cos(0.3), math.sin(0.3), 0.0, 0.0)  # 0.6 rad about x
    comp = MJCFGeneratorComposite(
        {"arm": _gen("arm6")}, placements={"arm": Placement((0, 0, 1), orientation=q)}
    )
    m = comp.to_model()
    d = mujoco.MjData(m)
    mujoco.mj_forward(m, d)
    np.testing.assert_allclose(d.xquat[m.body("arm_base_link").id], q, atol=1e-12)
    with pytest.raises(GeneratorError, match="not both"):
        Placement(yaw=0.1, orientation=q)


def test_nested_composite_and_outer_prefix():
    inner = MJCFGeneratorComposite({"a": _gen("arm6"), "b": _gen("arm6")}, {"b": (0.5, 0, 0)})
    outer = MJCFGeneratorComposite({"pair": inner, "h": _gen("mini_humanoid")}, {"pair": (0, 2, 0)})
    m = outer.to_model(prefix="s")
    d = mujoco.MjData(m)
    mujoco.mj_forward(m, d)
    np.testing.assert_allclose(d.xpos[m.body("s_pair_b_base_link").id], [0.5, 2.0, 0.0], atol=1e-12)
    assert m.body("s_h_pelvis").id > 0


def test_different_simulator_settings_warn(synth_urdf_safe):
    with pytest.warns(ConversionWarning, match=r"robots \['s'\] have simulator settings"):
        MJCFGeneratorComposite({"arm": _gen("arm6"), "s": _gen(synth_urdf_safe)}).export()


@pytest.mark.parametrize(
    ("key", "first", "second"),
    [("option", ("impratio", 10.0), ("impratio", 3.0)), ("flag", ("contact", "disable"), None)],
)
def test_scene_names_robots_whose_other_option_values_differ(key, first, second) -> None:
    # A scene has one <option>: it takes the first robot's, and a robot whose option
    # attributes or flags differ is named, never dropped silently.
    a, b = HRDF.from_robot_name("arm6"), HRDF.from_robot_name("arm6")
    getattr(a.meta.simulator_config, key)[first[0]] = first[1]
    if second is not None:
        getattr(b.meta.simulator_config, key)[second[0]] = second[1]
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        scene = MJCFGeneratorComposite(
            {"a": MJCFHumanoidGenerator.from_hrdf(a), "b": MJCFHumanoidGenerator.from_hrdf(b)},
            placements={"b": Placement((1.0, 0.0, 0.0), 0.0)},
        )
        model = scene.to_model()
    named = [str(w.message) for w in caught if "simulator settings different" in str(w.message)]
    assert len(named) == 1 and "['b']" in named[0]
    if key == "option":
        assert model.opt.impratio == 10.0
    else:
        assert model.opt.disableflags & mujoco.mjtDisableBit.mjDSBL_CONTACT
