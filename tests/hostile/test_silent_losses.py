"""Fuzz of the losses the physics corpora showed (issue 20): seeded random actuators
(every gain, bias and dynamics type, servo-shaped gains, declared inputs on MuJoCo 4)
convert to the source's compiled actuator fields with no unreported difference; seeded
random robots with ball joints (rotated frames, anchors off the body origin, cone
limits, other joints in the same body) round-trip through our URDF with the forward
kinematics of the source; actuator inputs MuJoCo refuses are an error naming the file,
exit 2, nothing written."""

from __future__ import annotations

import logging
import random
import subprocess
import sys
import warnings
from pathlib import Path

import mujoco
import numpy as np
import pytest

from robotwright.hrdf.model import HRDF
from robotwright.proof.convert import convert
from robotwright.proof.roundtrip.run import our_mjcf_model, roundtrip


@pytest.fixture(autouse=True)
def _quiet_parsers():
    """Parser log lines off while a test runs (restored after)."""
    logger = logging.getLogger("robotwright.parsers")
    old = logger.level
    logger.setLevel(logging.ERROR)
    yield
    logger.setLevel(old)


#: A declared control input (``<general input="pos">``, ``mjtCtrlInput``): MuJoCo 4 only;
#: MuJoCo 3.11's ``input`` takes an so3 actuator's chart and refuses these keywords.
HAS_INPUT = hasattr(mujoco, "mjtCtrlInput")
ACTUATOR_SEEDS = range(40)
BALL_SEEDS = range(20)


def _num(rng: random.Random) -> str:
    return rng.choice(["0", "1", "-1", "2.5", "1e-9", "-300", "1e6", "0.125"])


def _actuator(rng: random.Random, k: int, joint: str) -> str:
    """One random actuator MuJoCo compiles: a servo's gains half of the time."""
    attrs = {"name": f"a{k}", "joint": joint}
    if rng.random() < 0.5:  # servo-shaped: gain = -bias[1] (position) or -bias[2] (velocity)
        kp = rng.choice(["3", "100", "0.5"])
        if rng.random() < 0.5:
            attrs.update(gainprm=kp, biasprm=f"0 -{kp} {rng.choice(['0', '-2'])}")
        else:
            attrs.update(gainprm=kp, biasprm=f"0 0 -{kp}")
        attrs["biastype"] = "affine"
        gain = "fixed"
    else:
        gain = rng.choice(["fixed", "affine", "user"])
        attrs["gaintype"] = gain
        attrs["biastype"] = rng.choice(["none", "affine", "user"])
        attrs["gainprm"] = " ".join(_num(rng) for _ in range(3))
        attrs["biasprm"] = " ".join(_num(rng) for _ in range(3))
    dyn = rng.choice(["none", "none", "integrator", "filter", "filterexact", "user"])
    if dyn != "none":
        attrs["dyntype"] = dyn
        attrs["dynprm"] = rng.choice(["0.1", "1", "0.02"])
    if HAS_INPUT and gain != "user" and rng.random() < 0.5:
        attrs["input"] = rng.choice(["pos", "vel", "pressure"])
    if rng.random() < 0.5:
        attrs.update(ctrllimited="true", ctrlrange=rng.choice(["-1 1", "0 255", "-3 0.5"]))
    if rng.random() < 0.3:
        attrs.update(forcelimited="true", forcerange="-12 12")
    if rng.random() < 0.3:
        attrs["gear"] = rng.choice(["2", "-1", "0.5"])
    return "<general " + " ".join(f'{k}="{v}"' for k, v in attrs.items()) + "/>"


def _actuated_robot(seed: int) -> str:
    rng = random.Random(seed)
    n = rng.randint(1, 4)
    chain = (
        "".join(
            f'<body name="l{i}" pos="0 0 -0.2"><joint name="j{i}" axis="0 1 0" range="-1 1"/>'
            f'<geom type="capsule" fromto="0 0 0 0 0 -0.2" size="0.02" mass="0.3"/>'
            for i in range(n)
        )
        + "</body>" * n
    )
    acts = "".join(_actuator(rng, k, f"j{rng.randrange(n)}") for k in range(rng.randint(1, 5)))
    return (
        '<mujoco model="fuzz"><worldbody><body name="base" pos="0 0 1">'
        f'<geom type="box" size="0.1 0.1 0.1" mass="2"/>{chain}</body></worldbody>'
        f"<actuator>{acts}</actuator></mujoco>"
    )


def _actuator_fields(model: mujoco.MjModel) -> list[str]:
    out = []
    for name in dir(model):
        if not name.startswith("actuator_") or name.endswith(("adr", "num", "acc0", "length0")):
            continue
        value = getattr(model, name)
        if isinstance(value, np.ndarray) and value.shape[:1] == (model.nu,):
            out.append(name)
    return out


@pytest.mark.parametrize("seed", ACTUATOR_SEEDS)
def test_random_actuators_convert_exactly(tmp_path: Path, seed: int) -> None:
    src = tmp_path / "r.xml"
    src.write_text(_actuated_robot(seed))
    source = mujoco.MjModel.from_xml_path(str(src))  # every generated form compiles
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        messages = convert(src, tmp_path / "out")
    assert not [m for m in messages if "proof:" in m], messages
    ours = our_mjcf_model(HRDF.from_dir(tmp_path / "out"))
    assert ours.nu == source.nu
    for f in _actuator_fields(source):
        np.testing.assert_array_equal(getattr(ours, f), getattr(source, f), err_msg=f)


def _ball_robot(seed: int) -> str:
    rng = random.Random(seed)

    def angles() -> str:
        return " ".join(str(rng.randint(-180, 180)) for _ in range(3))

    def body(i: int, depth: int) -> str:
        # MuJoCo takes a ball after the body's other rotations only, 6 dofs at most.
        kinds = [rng.choice(["hinge", "slide"]) for _ in range(rng.randint(0, 2))] + ["ball"]
        if rng.random() < 0.3:
            kinds.append("slide")
        joints = []
        for k, kind in enumerate(kinds):
            pos = rng.choice(["0 0 0", "0.01 0 0", "0 -0.02 0.03"])
            attrs = f'name="j{i}_{k}" type="{kind}" pos="{pos}"'
            if kind == "ball" and rng.random() < 0.5:
                attrs += f' range="0 {rng.randint(5, 170)}"'
            elif kind == "hinge":
                attrs += f' axis="{angles()}" range="-60 60"'
            elif kind == "slide":
                attrs += ' axis="0 0 1" range="-0.1 0.1"'
            joints.append(f"<joint {attrs}/>")
        kids = "".join(
            body(i * 10 + c, depth + 1) for c in range(rng.randint(0, 2) if depth < 2 else 0)
        )
        return (
            f'<body name="b{i}" pos="{rng.uniform(-0.2, 0.2):.3f} 0 -0.15" euler="{angles()}">'
            + "".join(joints)
            + f'<geom type="box" size="0.03 0.02 0.01" pos="0.02 0 0" mass="{rng.uniform(0.1, 1):.3f}"/>'
            + f'<site name="s{i}" pos="0 0.03 0"/>{kids}</body>'
        )

    return (
        '<mujoco model="balls"><compiler angle="degree"/><worldbody>'
        f'<body name="base" pos="0 0 1" euler="{angles()}">'
        f'<geom type="sphere" size="0.05" mass="1"/>{body(1, 0)}</body>'
        "</worldbody></mujoco>"
    )


@pytest.mark.parametrize("seed", BALL_SEEDS)
def test_random_ball_robots_round_trip_through_urdf(tmp_path: Path, seed: int) -> None:
    src = tmp_path / "balls.xml"
    src.write_text(_ball_robot(seed))
    report = roundtrip(src, configs=10, reference="mujoco")
    assert report.ok, report.table()
    fk = [r for r in report.rows if r.check.startswith("URDF: FK")]
    assert len(fk) == 1 and fk[0].applicable, report.table()


#: Refused by MuJoCo 4 (a wrong keyword, a form its gain type cannot take) and by 3.11
#: (whose ``input`` takes an so3 actuator's chart only).
BAD_INPUTS = {
    "unknown-keyword": '<general joint="j" input="sideways"/>',
    "feedforward-on-fixed-gain": '<general joint="j" input="ff"/>',
    "input-on-user-gain": '<general joint="j" gaintype="user" input="pos"/>',
    "two-inputs": '<general joint="j" input="pos vel"/>',
    "control-character": '<general joint="j" input="pos&#27;[31m"/>',
}


@pytest.mark.parametrize("act", BAD_INPUTS.values(), ids=list(BAD_INPUTS))
def test_refused_actuator_input_is_an_error(tmp_path: Path, act: str) -> None:
    src = tmp_path / "bad.xml"
    src.write_text(
        '<mujoco><worldbody><body name="b"><joint name="j"/><geom size="0.1"/></body>'
        f"</worldbody><actuator>{act}</actuator></mujoco>"
    )
    out = tmp_path / "out"
    proc = subprocess.run(
        [sys.executable, "-m", "robotwright", "convert", str(src), "-o", str(out)],
        capture_output=True,
        text=True,
        timeout=600,
    )
    assert proc.returncode == 2, proc.stderr
    assert proc.stderr.startswith("error:") and "bad.xml" in proc.stderr, proc.stderr
    assert "Traceback" not in proc.stderr and "\x1b" not in proc.stderr
    assert not out.exists()
