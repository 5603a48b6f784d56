"""Fuzz of the conversion proof (issue 20): seeded random robots (random trees, unnamed
objects, random attribute values including infinities and tiny numbers) compared with
themselves written in another order must show no difference, and with one value changed
must show exactly that value."""

from __future__ import annotations

import random

import mujoco
import pytest

from robotwright.parsers import proof

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
