"""Fuzz of the conversion proof (issue 20): seeded random robots (random trees, unnamed
objects, random attribute values including infinities and tiny numbers) compared with
themselves written in another order must show no difference, and with one value changed
must show exactly that value."""

from __future__ import annotations

import random

import mujoco
import pytest

from robotwright.proof import compare as proof

SEEDS = range(24)


def _robot(seed: int, shuffle: bool, change: tuple[int, str] | None = None) -> str:
    rng = random.Random(seed)
    n = rng.randint(2, 12)
    bodies = []
    for i in range(n):
        parent = -1 if i == 0 else rng.randrange(i)
        named = rng.random() < 0.6 or i == 0
        attrs = {
            "damping": rng.choice(["0", "1e-300", "3.5", "1e9"]),
            "stiffness": rng.choice(["0", "2", "7e-12"]),
            "range": rng.choice(["-1 1", "-0.5 2"]),
        }
        if change is not None and change[0] == i:
            attrs[change[1]] = "0.123456"
        bodies.append((i, parent, named, attrs, rng.choice(["sphere", "box", "capsule"])))
    children: dict[int, list] = {}
    for b in bodies:
        children.setdefault(b[1], []).append(b)
    order = random.Random(seed + 1000)

    def emit(b) -> str:
        i, _, named, attrs, gtype = b
        name = f' name="b{i}"' if named else ""
        jname = f' name="j{i}"' if named else ""
        a = " ".join(f'{k}="{v}"' for k, v in attrs.items())
        size = {"sphere": "0.05", "box": "0.05 0.04 0.03", "capsule": "0.02 0.05"}[gtype]
        kids = list(children.get(i, []))
        # Only named children are reordered (unnamed ones are matched by order).
        if shuffle:
            named_kids = [k for k in kids if k[2]]
            order.shuffle(named_kids)
            it = iter(named_kids)
            kids = [next(it) if k[2] else k for k in kids]
        inner = "".join(emit(k) for k in kids)
        joint = f"<joint{jname} {a}/>" if i else "<freejoint/>"
        return (
            f'<body{name} pos="0 0 0.1">{joint}<geom type="{gtype}" size="{size}" '
            f'mass="0.5"/>{inner}</body>'
        )

    return f"<mujoco><worldbody>{emit(bodies[0])}</worldbody></mujoco>"


@pytest.mark.parametrize("seed", SEEDS)
def test_reordered_random_robot_has_no_difference(seed: int) -> None:
    a = mujoco.MjModel.from_xml_string(_robot(seed, shuffle=False))
    b = mujoco.MjModel.from_xml_string(_robot(seed, shuffle=True))
    assert proof.compare_models(a, b) == []


@pytest.mark.parametrize("seed", SEEDS)
@pytest.mark.parametrize("attr", ["damping", "stiffness"])
def test_one_changed_value_is_found(seed: int, attr: str) -> None:
    rng = random.Random(seed * 7)
    src = _robot(seed, shuffle=False)
    n = src.count("<body")
    target = rng.randrange(1, n) if n > 1 else 0
    a = mujoco.MjModel.from_xml_string(src)
    b = mujoco.MjModel.from_xml_string(_robot(seed, shuffle=True, change=(target, attr)))
    field = {"damping": "dof_damping", "stiffness": "jnt_stiffness"}[attr]
    diffs = proof.compare_models(a, b)
    # 0.123456 is none of the values the robots are made of: the value always changed.
    assert [d.field for d in diffs] == [field], diffs
    assert "0.123456" in diffs[0].result


# -- URDF sources and outputs ---------------------------------------------------------------
def _tensor(rng: random.Random) -> tuple[float, ...]:
    """A random physical inertia tensor (ixx iyy izz ixy ixz iyz): random principal
    moments (A + B >= C) turned by a random rotation."""
    import numpy as np

    a, b = rng.uniform(0.01, 0.1), rng.uniform(0.01, 0.1)
    c = rng.uniform(abs(a - b) + 1e-3, a + b - 1e-3)
    q = np.array([rng.gauss(0, 1) for _ in range(4)])
    q /= np.linalg.norm(q)
    m = np.zeros(9)
    mujoco.mju_quat2Mat(m, q)
    r = m.reshape(3, 3)
    t = r @ np.diag([a, b, c]) @ r.T
    return tuple(float(x) for x in (t[0, 0], t[1, 1], t[2, 2], t[0, 1], t[0, 2], t[1, 2]))


def _urdf(seed: int) -> str:
    rng = random.Random(seed)
    n = rng.randint(2, 9)
    links, joints = [], []
    for i in range(n):
        ixx, iyy, izz, ixy, ixz, iyz = _tensor(rng)
        rpy = " ".join(f"{rng.uniform(-3, 3)!r}" for _ in range(3))
        xyz = " ".join(f"{rng.uniform(-0.1, 0.1)!r}" for _ in range(3))
        geoms = []
        for _ in range(rng.randint(0, 3)):
            shape = rng.choice(['<box size="0.1 0.05 0.02"/>', '<sphere radius="0.03"/>',
                                '<cylinder radius="0.02" length="0.1"/>'])  # fmt: skip
            pos = " ".join(f"{rng.uniform(-0.1, 0.1)!r}" for _ in range(3))
            geoms.append(
                f'<collision><origin xyz="{pos}"/><geometry>{shape}</geometry></collision>'
            )
        links.append(
            f'<link name="l{i}"><inertial><origin xyz="{xyz}" rpy="{rpy}"/>'
            f'<mass value="{rng.uniform(0.1, 2)!r}"/><inertia ixx="{ixx!r}" iyy="{iyy!r}" '
            f'izz="{izz!r}" ixy="{ixy!r}" ixz="{ixz!r}" iyz="{iyz!r}"/></inertial>'
            + "".join(geoms)
            + "</link>"
        )
        if i:
            kind = rng.choice(["revolute", "prismatic", "continuous"])
            limit = (
                '<limit lower="-1" upper="1" effort="3" velocity="2"/>'
                if kind != "continuous"
                else ""
            )
            axis = rng.choice(["1 0 0", "0 1 0", "0 0 1", "0.6 0.8 0"])
            damping = f'<dynamics damping="{rng.uniform(0, 1)!r}"/>' if rng.random() < 0.5 else ""
            joints.append(
                f'<joint name="j{i}" type="{kind}"><parent link="l{rng.randrange(i)}"/>'
                f'<child link="l{i}"/><origin xyz="0 0 0.2" rpy="0 0 {rng.uniform(-1, 1)!r}"/>'
                f'<axis xyz="{axis}"/>{limit}{damping}</joint>'
            )
    return f'<robot name="r{seed}">{"".join(links)}{"".join(joints)}</robot>'


URDF_SEEDS = range(12)


@pytest.mark.parametrize("seed", URDF_SEEDS)
@pytest.mark.parametrize("out", ["folder", "out.xml", "out.urdf"])
def test_random_urdf_converts_with_no_false_alarm(tmp_path, seed: int, out: str) -> None:
    from robotwright.proof.convert import convert

    src = tmp_path / "r.urdf"
    src.write_text(_urdf(seed))
    assert proof.source_model(src, "urdf", {}) is not None  # MuJoCo imports it
    messages = convert(src, tmp_path / out)
    assert not [m for m in messages if "proof:" in m], messages


@pytest.mark.parametrize("seed", URDF_SEEDS)
def test_random_urdf_changed_mass_is_found(tmp_path, monkeypatch, seed: int) -> None:
    import dataclasses

    from robotwright.hrdf.model import HRDF
    from robotwright.proof.convert import convert

    target = f"l{random.Random(seed * 3).randrange(random.Random(seed).randint(2, 9))}"
    real = HRDF.save

    def save(self, path, **kw):
        bodies = [
            dataclasses.replace(b, mass=b.mass * 1.001) if b.name == target else b
            for b in self.bodies
        ]
        return real(dataclasses.replace(self, bodies=bodies), path, **kw)

    monkeypatch.setattr(HRDF, "save", save)
    src = tmp_path / "r.urdf"
    src.write_text(_urdf(seed))
    lost = [m for m in convert(src, tmp_path / "out") if "proof:" in m]
    # each static note names the body; the simulation (URDF sources are stepped beside
    # MuJoCo's import) may show the motion that follows, named by its joint
    static = [m for m in lost if "proof: simulation," not in m]
    assert static and all(f"'{target}'" in m for m in static), lost
    assert any("body_mass" in m for m in static), lost


@pytest.mark.parametrize("seed", range(30))
def test_inertia_in_any_axis_order_is_one_tensor(seed: int) -> None:
    import numpy as np

    rng = random.Random(seed)
    moments = [rng.uniform(0.01, 0.1) for _ in range(2)]
    moments.append(rng.uniform(abs(moments[0] - moments[1]) + 1e-3, sum(moments) - 1e-3))
    perm = rng.sample(range(3), 3)

    def xml(diag, quat) -> str:
        d = " ".join(repr(float(x)) for x in diag)
        q = " ".join(repr(float(x)) for x in quat)
        return (
            '<mujoco><worldbody><body name="b"><freejoint/><inertial pos="0 0 0" mass="1" '
            f'diaginertia="{d}" quat="{q}"/></body></worldbody></mujoco>'
        )

    # The same tensor: axes permuted (and signed) by a rotation matrix whose columns are
    # the original axes in the new order.
    r = np.zeros((3, 3))
    for new, old in enumerate(perm):
        r[old, new] = rng.choice([-1.0, 1.0])
    if np.linalg.det(r) < 0:
        r[:, 0] = -r[:, 0]
    q = np.zeros(4)
    mujoco.mju_mat2Quat(q, r.flatten())
    a = mujoco.MjModel.from_xml_string(xml(moments, [1, 0, 0, 0]))
    b = mujoco.MjModel.from_xml_string(xml([moments[i] for i in perm], q))
    assert proof.compare_models(a, b) == []
    # Another rotation of the same moments is another tensor (unless they are equal).
    turn = [np.cos(0.3), 0, 0, np.sin(0.3)]
    c = mujoco.MjModel.from_xml_string(xml(moments, turn))
    assert [d.field for d in proof.compare_models(a, c)] == ["body_inertia"]
