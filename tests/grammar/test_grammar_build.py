"""Building designs: the seed's traversal, HRDF contents, masses, MJCF/URDF export, mount."""

from __future__ import annotations

import math
import random

import mujoco
import numpy as np
import pytest

from robotwright.errors import GrammarError
from robotwright.grammar import demo_limb, derive, mount_on
from robotwright.grammar.build import build, build_hrdf
from robotwright.grammar.design import Design
from robotwright.grammar.loader import default_grammar
from robotwright.hrdf import HRDF
from robotwright.hrdf.validate import check_model

from .helpers import default_data, load_variant, one_choice_library

pytestmark = pytest.mark.filterwarnings("ignore::robotwright.errors.ConversionWarning")

DESIGN = Design.from_text(
    "# grammar=srl\n"
    "r1 @0: B=base(diameter=0.12, thickness=0.04) P=pinned()\n"
    "r2 @0: C=universal(limit=1.5708) L=link(diameter=0.04, length=0.25, rotation=0.0)\n"
    "r3 @3: C=prismatic(stroke=0.1) L=link(diameter=0.04, length=0.15, rotation=1.5708)\n"
    "r4 @5: E=gripper(finger_length=0.06)\n"
)


def test_seed_traversal_defers_joints_to_the_next_link():
    limb = build(default_grammar(), DESIGN)
    assert [b.name for b in limb.bodies] == ["base", "link1", "link2", "gripper1"]
    assert [(j.name, j.body, j.type) for j in limb.joints] == [
        ("joint1", "link1", "hinge"),
        ("joint2", "link1", "hinge"),  # the universal connector's 2 DoFs: one body
        ("joint3", "link2", "slide"),
    ]
    # link1's frame is the universal's second DoF frame (twisted 90 deg about x), so
    # the first axis (base z) reads +y there and the second axis is the frame's z.
    np.testing.assert_allclose(limb.joints[0].axis, [0, 1, 0], atol=1e-5)
    np.testing.assert_allclose(limb.joints[1].axis, [0, 0, 1], atol=1e-12)
    assert limb.joints[2].range == (0.0, 0.1)
    assert [r.alpha for r in limb.branches[0].rows] == [0.0, 1.5708, 0.0]
    assert [r.a for r in limb.branches[0].rows] == [0.0, 0.0, 0.25]


def test_hrdf_is_valid_and_masses_follow_densities():
    hrdf = build_hrdf(default_grammar(), DESIGN)
    assert [p for p in check_model(hrdf, check_files=False) if p.severity == "error"] == []
    assert not hrdf.floating_base and hrdf.dof == 3 and len(hrdf.actuators) == 3
    base = hrdf.body("base")
    assert base.mass == pytest.approx(2700 * math.pi * 0.06**2 * 0.04, rel=1e-9)
    link1 = hrdf.body("link1")
    housing = 1500 * math.pi * 0.03**2 * 0.06  # universal housing, one per DoF
    assert link1.mass == pytest.approx(1200 * math.pi * 0.02**2 * 0.25 + 2 * housing, rel=1e-9)
    assert hrdf.meta.extra["grammar"]["design_hash"] == DESIGN.hash()


def test_hrdf_folder_round_trip(tmp_path):
    hrdf = build_hrdf(default_grammar(), DESIGN)
    with pytest.warns(UserWarning, match="'grammar': unknown key, kept verbatim"):
        again = HRDF.from_dir(hrdf.save(tmp_path / "srl"))
    assert again.meta.extra["grammar"]["design_hash"] == DESIGN.hash()
    assert [b.name for b in again.bodies] == [b.name for b in hrdf.bodies]
    assert [b.mass for b in again.bodies] == pytest.approx([b.mass for b in hrdf.bodies])
    assert [j.range for j in again.joints] == [j.range for j in hrdf.joints]


def test_every_sampled_design_exports_mjcf_and_urdf_that_compile(tmp_path):
    gen = pytest.importorskip("robotwright.generators")
    if not hasattr(gen, "URDFHumanoidGenerator"):
        pytest.skip("URDF generator not available")
    g = default_grammar()
    rng = random.Random(2)
    for k in range(6):
        hrdf = build_hrdf(g, derive.sample(g, 4, rng))
        gen.MJCFHumanoidGenerator.from_hrdf(hrdf).export(tmp_path / f"{k}.xml")
        gen.URDFHumanoidGenerator.from_hrdf(hrdf).export(
            tmp_path / f"{k}.urdf", add_mujoco_tag=True
        )
        m = mujoco.MjModel.from_xml_path(str(tmp_path / f"{k}.xml"))
        u = mujoco.MjModel.from_xml_path(str(tmp_path / f"{k}.urdf"))
        assert m.nq == u.nq == hrdf.dof
        assert m.body_mass.sum() == pytest.approx(hrdf.total_mass, rel=1e-9)
        assert u.body_mass.sum() == pytest.approx(hrdf.total_mass, rel=1e-6)
        np.testing.assert_allclose(
            np.sort(m.jnt_range, axis=0), np.sort(u.jnt_range, axis=0), atol=1e-9
        )


def test_branching_design_has_one_branch_per_open_end(tmp_path):
    g, _ = default_data()
    g["rules"]["r5"] = {"lhs": "-L", "rhs": "-L -> C -> L*", "branching": True}
    grammar = load_variant(tmp_path, g, one_choice_library())
    designs = list(derive.enumerate_designs(grammar, 2))
    sizes = sorted(len(build(grammar, d).branches) for d in designs)
    assert sizes == [1, 1, 1, 2]  # only "close with E, then branch" has two ends
    for d in designs:
        limb = build(grammar, d)
        site_names = {s.name for s in limb.sites}
        assert all(br.site in site_names for br in limb.branches)


def test_mount_on_humanoid_site_places_the_base_there():
    from robotwright.generators import MJCFHumanoidGenerator

    robot = HRDF.from_robot_name("mini_humanoid")
    limb = demo_limb(0)
    half = math.sqrt(0.5)
    both = mount_on(robot, limb, "back_mount", quat=(half, 0.0, -half, 0.0))
    assert [p for p in check_model(both, check_files=False) if p.severity == "error"] == []
    assert len(both.bodies) == len(robot.bodies) + len(limb.bodies)
    assert both.dof == robot.dof + limb.dof
    assert both.total_mass == pytest.approx(robot.total_mass + limb.total_mass)
    model = MJCFHumanoidGenerator.from_hrdf(both).to_model()
    data = mujoco.MjData(model)
    mujoco.mj_kinematics(model, data)
    site = data.site("back_mount")
    base = data.body("srl_base")
    np.testing.assert_allclose(base.xpos, site.xpos, atol=1e-9)
    # the limb's z axis (base normal) points backwards, along the site's -x
    np.testing.assert_allclose(
        base.xmat.reshape(3, 3)[:, 2], -site.xmat.reshape(3, 3)[:, 0], atol=1e-6
    )


def test_mount_errors_name_the_problem():
    robot = HRDF.from_robot_name("mini_humanoid")
    limb = demo_limb(0)
    with pytest.raises(GrammarError, match="no body or site named 'tail'"):
        mount_on(robot, limb, "tail")
    once = mount_on(robot, limb, "torso")
    with pytest.raises(GrammarError, match="choose another prefix"):
        mount_on(once, limb, "torso")
    twice = mount_on(once, limb, "chest", prefix="srl2_")
    assert twice.dof == robot.dof + 2 * limb.dof


def test_demo_limb_is_deterministic():
    assert (
        demo_limb(3).meta.extra["grammar"]["design_hash"]
        == demo_limb(3).meta.extra["grammar"]["design_hash"]
    )
    assert (
        demo_limb(3).meta.extra["grammar"]["design_hash"]
        != demo_limb(4).meta.extra["grammar"]["design_hash"]
    )


def test_composite_mount_matches_hrdf_mount():
    from robotwright.generators import MJCFHumanoidGenerator
    from robotwright.grammar.mount import mount_scene

    robot = HRDF.from_robot_name("mini_humanoid")
    limb = demo_limb(1)
    half = math.sqrt(0.5)
    quat = (half, 0.0, -half, 0.0)
    merged = MJCFHumanoidGenerator.from_hrdf(
        mount_on(robot, limb, "back_mount", quat=quat)
    ).to_model()
    scene = mount_scene(robot, limb, "back_mount", quat=quat).to_model()
    assert scene.nq == merged.nq and scene.nu == merged.nu
    assert scene.body_mass.sum() == pytest.approx(merged.body_mass.sum(), rel=1e-9)
    dm, ds = mujoco.MjData(merged), mujoco.MjData(scene)
    mujoco.mj_kinematics(merged, dm)
    mujoco.mj_kinematics(scene, ds)
    for site in limb.sites:
        np.testing.assert_allclose(
            ds.site(f"srl_{site.name}").xpos, dm.site(f"srl_{site.name}").xpos, atol=1e-6
        )


def test_all_one_link_designs_compile_as_mjcf_and_urdf():
    from xml.etree.ElementTree import tostring

    from robotwright.generators import MJCFHumanoidGenerator, URDFHumanoidGenerator

    g = default_grammar()
    designs = list(derive.enumerate_designs(g, 1))
    assert len(designs) == 192
    for d in designs:
        hrdf = build_hrdf(g, d)
        mjcf = MJCFHumanoidGenerator.from_hrdf(hrdf).generate(add_scene=False)
        urdf = URDFHumanoidGenerator.from_hrdf(hrdf).generate(add_mujoco_tag=True)
        m = mujoco.MjModel.from_xml_string(tostring(mjcf, encoding="unicode"))
        u = mujoco.MjModel.from_xml_string(tostring(urdf, encoding="unicode"))
        assert m.nq == u.nq == hrdf.dof
        assert m.body_mass.sum() == pytest.approx(hrdf.total_mass, rel=1e-9)
        assert u.body_mass.sum() == pytest.approx(hrdf.total_mass, rel=1e-6)
