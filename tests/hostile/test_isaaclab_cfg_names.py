"""Names from a robot file go into the generated Isaac Lab module as data, never as code.

``robotwright isaaclab-cfg`` writes a Python module that users import; a robot whose
joint and robot names are crafted to break out of a string literal or a regular
expression must give a module whose only statements are the expected imports and
assignments, whose strings are the names exactly, and whose joint expressions match
exactly those joints.
"""

from __future__ import annotations

import ast
import dataclasses
import re

import mujoco
import pytest

from robotwright.generators.isaaclab_cfg import articulation_cfg_source
from robotwright.sources import load_robot

HOSTILE = [
    "j'); import os; os.system('echo pwned'); ('",
    'k"""\nimport shutil\n"""',
    "a.*|.*",
    "back\\slash\\'",
]


def _model(names: list[str], lower: float = -1.0) -> mujoco.MjModel:
    spec = mujoco.MjSpec()
    body = spec.worldbody.add_body(name="base")
    body.add_geom(size=[0.1, 0, 0])
    for i, name in enumerate(names):
        link = body.add_body(name=f"link{i}", pos=[0, 0, -0.2 * (i + 1)])
        link.add_joint(name=name, type=mujoco.mjtJoint.mjJNT_HINGE, range=[lower, 1])
        link.add_geom(size=[0.05, 0, 0])
    return spec.compile()


#: Names with no double quote or backslash: the docstring stays a triple-quoted block.
PLAIN_PATH = ["x\nimport os\nos.system('y')", "z'''"]


@pytest.mark.parametrize(
    ("robot_name", "names"),
    [(HOSTILE[0], HOSTILE), (HOSTILE[1], HOSTILE), ("robot", PLAIN_PATH)],
)
def test_hostile_names_stay_data_in_the_generated_module(robot_name, names):
    robot = load_robot("arm6")
    actuators = [
        dataclasses.replace(a, joint=names[i % len(names)])
        for i, a in enumerate(robot.actuators[:4])
    ]
    hrdf = dataclasses.replace(robot, name=robot_name, actuators=actuators)
    # Ranges that exclude the reference position: the clamped joints are listed too.
    text, clamped = articulation_cfg_source(hrdf, _model(names, lower=0.5), "robot.usd")
    assert len(clamped) == len(names)
    assert text.startswith('"""') == (names is PLAIN_PATH)  # both docstring forms
    tree = ast.parse(text)
    # The names are in the docstring as text, whole (newlines and quotes included).
    doc = ast.get_docstring(tree, clean=False)
    assert repr(robot_name) in doc and all(name in doc for name in names)
    kinds = [type(node).__name__ for node in tree.body]
    assert kinds == ["Expr", "ImportFrom", "Import", "ImportFrom", "ImportFrom", "Assign", "Assign"]
    # Every call in the module is one of the expected constructors.
    called = {ast.unparse(node.func) for node in ast.walk(tree) if isinstance(node, ast.Call)}
    assert called <= {
        "str",
        "Path(__file__).with_name",
        "Path",
        "ArticulationCfg",
        "sim_utils.UsdFileCfg",
        "ArticulationCfg.InitialStateCfg",
        "ImplicitActuatorCfg",
    }, called
    # Joint positions: one key per joint, each a regular expression matching exactly it.
    keys = [
        ast.literal_eval(k)
        for node in ast.walk(tree)
        if isinstance(node, ast.Dict)
        for k in node.keys
        if isinstance(k, ast.Constant)
        and isinstance(k.value, str)
        and not k.value.startswith("group_")
    ]
    assert len(keys) == len(names)
    for key, name in zip(keys, names):
        assert re.fullmatch(key, name)
        assert [n for n in names if re.fullmatch(key, n)] == [name]
    # Actuator groups name exactly the actuated joints.
    exprs = [
        ast.literal_eval(e)
        for node in ast.walk(tree)
        if isinstance(node, ast.keyword) and node.arg == "joint_names_expr"
        for e in node.value.elts
    ]
    assert sorted(exprs) == sorted(re.escape(a.joint) for a in actuators)
