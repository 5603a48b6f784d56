"""Modified DH forward kinematics against hand-computed numbers, and against MuJoCo."""

from __future__ import annotations

import math
import random

import mujoco
import numpy as np
import pytest

from robotwright.grammar import derive
from robotwright.grammar.build import build, trans
from robotwright.grammar.design import Design
from robotwright.grammar.dh import DHRow, fk, fk_frames
from robotwright.grammar.loader import default_grammar


def test_planar_two_link_hand_computed():
    rows = [DHRow(0.0, 0.0, 0.0), DHRow(0.5, 0.0, 0.0)]
    tool = trans(x=0.3)
    T = fk(rows, [math.pi / 6, math.pi / 3], tool)
    # x = 0.5 cos(30 deg) + 0.3 cos(90 deg), y = 0.5 sin(30 deg) + 0.3 sin(90 deg)
    np.testing.assert_allclose(T[:3, 3], [0.4330127018922193, 0.55, 0.0], atol=1e-12)
    T = fk(rows, [math.pi / 2, -math.pi / 2], tool)
    np.testing.assert_allclose(T[:3, 3], [0.3, 0.5, 0.0], atol=1e-12)
    np.testing.assert_allclose(T[:3, :3], np.eye(3), atol=1e-12)


def test_spatial_hand_computed():
    # yaw joint raised 0.1, then a pitch joint (alpha = 90 deg), then a 0.4 m link.
    rows = [DHRow(0.0, 0.0, 0.1), DHRow(0.0, math.pi / 2, 0.0), DHRow(0.4, 0.0, 0.0)]
    T = fk(rows, [math.pi / 2, 0.0, 0.0])
    np.testing.assert_allclose(T[:3, 3], [0.0, 0.4, 0.1], atol=1e-12)
    np.testing.assert_allclose(T[:3, 0], [0.0, 1.0, 0.0], atol=1e-12)  # x3
    np.testing.assert_allclose(T[:3, 2], [1.0, 0.0, 0.0], atol=1e-12)  # z3 = pitch axis
    T = fk(rows, [math.pi / 2, math.pi / 2, 0.0])
    np.testing.assert_allclose(T[:3, 3], [0.0, 0.0, 0.5], atol=1e-12)


def test_slide_row_and_batch():
    rows = [DHRow(0.0, 0.0, 0.2, type="slide"), DHRow(0.3, -math.pi / 2, 0.0)]
    np.testing.assert_allclose(fk(rows, [0.1, 0.0])[:3, 3], [0.3, 0.0, 0.3], atol=1e-12)
    Q = np.random.default_rng(0).uniform(-1, 1, (7, 2))
    batch = fk(rows, Q)
    for i in range(7):
        np.testing.assert_allclose(batch[i], fk(rows, Q[i]), atol=1e-12)
    assert fk_frames(rows, Q).shape == (7, 2, 4, 4)
    with pytest.raises(ValueError, match="expected"):
        fk(rows, [0.0])
    with pytest.raises(ValueError, match="type"):
        DHRow(0, 0, 0, type="ball")


def test_one_pose_and_a_batch_give_the_same_frames_on_random_tables():
    # One pose takes its own path (Python floats); the batched one is the reference.
    rng = np.random.default_rng(3)
    for _ in range(20):
        n = int(rng.integers(1, 7))
        rows = [
            DHRow(*rng.uniform(-1, 1, 4), type="slide" if rng.random() < 0.3 else "hinge")
            for _ in range(n)
        ]
        q = rng.uniform(-2, 2, n)
        one = fk_frames(rows, q)
        assert one.shape == (n, 4, 4)
        np.testing.assert_allclose(one, fk_frames(rows, q[None])[0], atol=1e-12)
        np.testing.assert_allclose(fk(rows, q), fk(rows, q[None])[0], atol=1e-12)


def _design(text: str) -> Design:
    return Design.from_text("# grammar=srl\n" + text)


# Two vertical revolute joints: a planar arm 0.25 m + 0.15 m + gripper (palm 0.024 +
# finger 0.06), on a base 0.02 thick; joint frame raised by housing/2 + 2 mm = 0.027.
PLANAR = _design(
    "r1 @0: B=base(diameter=0.08, thickness=0.02) P=pinned()\n"
    "r2 @0: C=revolute(limit=1.5708) L=link(diameter=0.04, length=0.25, rotation=0.0)\n"
    "r3 @3: C=revolute(limit=2.618) L=link(diameter=0.04, length=0.15, rotation=0.0)\n"
    "r4 @5: E=gripper(finger_length=0.06)\n"
)
# Same, but the second joint axis is turned 90 deg about the first link: it pitches.
SPATIAL = _design(
    "r1 @0: B=base(diameter=0.08, thickness=0.02) P=pinned()\n"
    f"r2 @0: C=revolute(limit=1.5708) L=link(diameter=0.04, length=0.25, rotation={math.pi / 2!r})\n"
    "r3 @3: C=revolute(limit=2.618) L=link(diameter=0.04, length=0.15, rotation=0.0)\n"
    "r4 @5: E=tool(length=0.08)\n"
)


def _site_pos(hrdf, q, site):
    from robotwright.generators import MJCFHumanoidGenerator

    model = MJCFHumanoidGenerator.from_hrdf(hrdf).to_model()
    data = mujoco.MjData(model)
    data.qpos[:] = q
    mujoco.mj_kinematics(model, data)
    return data.site(site).xpos.copy()


@pytest.mark.filterwarnings("ignore::robotwright.errors.ConversionWarning")
@pytest.mark.parametrize(
    ("design", "q", "expected"),
    [
        (PLANAR, [math.pi / 2, -math.pi / 2], [0.15 + 0.084, 0.25, 0.047]),
        (PLANAR, [0.0, 0.0], [0.25 + 0.15 + 0.084, 0.0, 0.047]),
        (SPATIAL, [0.0, math.pi / 2], [0.25, 0.0, 0.047 + 0.15 + 0.08]),
    ],
)
def test_built_designs_hand_computed_dh_and_mujoco(design, q, expected):
    g = default_grammar()
    limb = build(g, design)
    (branch,) = limb.branches
    np.testing.assert_allclose(branch.tool_pose(np.array(q))[:3, 3], expected, atol=1e-4)
    np.testing.assert_allclose(_site_pos(limb.to_hrdf(), q, branch.site), expected, atol=1e-4)


@pytest.mark.filterwarnings("ignore::robotwright.errors.ConversionWarning")
def test_dh_equals_mujoco_fk_of_exported_mjcf_on_random_designs(tmp_path):
    from robotwright.generators import MJCFHumanoidGenerator

    g = default_grammar()
    rng = random.Random(11)
    nrng = np.random.default_rng(11)
    for k in range(15):
        limb = build(g, derive.sample(g, 4, rng))
        path = tmp_path / f"limb{k}.xml"
        MJCFHumanoidGenerator.from_hrdf(limb.to_hrdf()).export(path)
        model = mujoco.MjModel.from_xml_path(str(path))
        data = mujoco.MjData(model)
        lo, hi = limb.joint_ranges().T
        names = [j.name for j in limb.joints]
        for _ in range(5):
            q = nrng.uniform(lo, hi)
            for n, v in zip(names, q):
                data.joint(n).qpos[0] = v
            mujoco.mj_kinematics(model, data)
            for br in limb.branches:
                T = br.tool_pose(q[[names.index(n) for n in br.joints]])
                site = data.site(br.site)
                np.testing.assert_allclose(T[:3, 3], site.xpos, atol=1e-9)
                np.testing.assert_allclose(T[:3, :3], site.xmat.reshape(3, 3), atol=1e-9)


@pytest.mark.filterwarnings("ignore::robotwright.errors.ConversionWarning")
def test_printed_dh_table_alone_gives_mujocos_forward_kinematics(tmp_path, capsys):
    """``grammar show`` prints every number exactly, frame 0 and the tool offset too:
    the table read back from the text gives MuJoCo's site poses to 1e-12."""
    from robotwright.cli import main
    from robotwright.generators import MJCFHumanoidGenerator
    from robotwright.grammar.export import export_design

    g = default_grammar()
    rng, nrng = random.Random(5), np.random.default_rng(5)
    for k in range(4):
        design = derive.sample(g, 4, rng)
        folder = tmp_path / f"d{k}"
        export_design(g, design, folder, picture=False)
        assert main(["grammar", "show", str(folder)]) == 0
        text = capsys.readouterr().out.splitlines()
        limb = build(g, design)
        path = tmp_path / f"limb{k}.xml"
        MJCFHumanoidGenerator.from_hrdf(limb.to_hrdf()).export(path)
        model = mujoco.MjModel.from_xml_path(str(path))
        data = mujoco.MjData(model)
        names = [j.name for j in limb.joints]
        lo, hi = limb.joint_ranges().T
        for b, br in enumerate(limb.branches):
            at = next(i for i, line in enumerate(text) if line.startswith(f"branch {b} ->"))
            base = np.array([[float(v) for v in text[at + 2 + r].split()] for r in range(4)])
            rows = []
            for line in text[at + 6 : at + 6 + len(br.rows)]:
                name, kind, *cells = line.split()
                vals = dict(c.split("=") for c in cells)
                rows.append(
                    DHRow(
                        name=name,
                        type=kind,
                        a=float(vals["a"]),
                        alpha=float(vals["alpha"]),
                        d=float(vals["d"]),
                        theta=float(vals["theta"]),
                    )
                )
            t0 = at + 7 + len(br.rows)
            tool = np.array([[float(v) for v in text[t0 + r].split()] for r in range(4)])
            for _ in range(5):
                q = nrng.uniform(lo, hi)
                for n, v in zip(names, q):
                    data.joint(n).qpos[0] = v
                mujoco.mj_kinematics(model, data)
                T = base @ fk(rows, q[[names.index(n) for n in br.joints]], tool)
                site = data.site(br.site)
                np.testing.assert_allclose(T[:3, 3], site.xpos, atol=1e-12)
                np.testing.assert_allclose(T[:3, :3], site.xmat.reshape(3, 3), atol=1e-12)
