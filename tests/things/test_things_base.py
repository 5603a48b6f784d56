"""BaseThing: registries, IDs, tree links, copying, naming, validation."""

from __future__ import annotations

import mujoco
import numpy as np
import pytest

from robotwright.things import (
    REGISTRY,
    Ball,
    BaseThing,
    Body,
    Box,
    Camera,
    Capsule,
    Free,
    Gyro,
    Hinge,
    JointPos,
    Motor,
    Position,
    Site,
    Slide,
    Sphere,
    ThingAttributeError,
    World,
)
from robotwright.things.attrs import Real, Text


# ---------------------------------------------------------------- registries
def test_registries_aggregate_along_the_class_hierarchy():
    assert {"pos", "quat", "size", "rgba", "type"} <= set(Sphere._MUJOCO_ATTR)
    assert {"type"} == Sphere._DERIVED_ATTR
    assert "type" not in Sphere._BLUEPRINT_ATTR  # fixed by the class, not an init arg
    assert "name" in Sphere._BLUEPRINT_ATTR  # inherited from BaseThing
    # _DEL_MUJOCO_ATTR removes inherited attributes
    assert "axis" in Hinge._MUJOCO_ATTR and "axis" not in Ball._MUJOCO_ATTR
    assert "range" not in Free._MUJOCO_ATTR and "align" in Free._MUJOCO_ATTR
    assert Position._DEFAULT_VALS["kp"] == 1.0 and "kp" not in Motor._MUJOCO_ATTR
    # references are never deep-copied
    assert "material" in Sphere._NO_COPY_VALS and "target" in Camera._NO_COPY_VALS


def test_new_subclass_needs_only_new_declarations():
    class FittedSphere(Sphere):
        """A sphere with MJCF's ``fitscale`` and a Python-only shared ``label``."""

        _NEW_MUJOCO_ATTR = {"fitscale": Real(nonneg=True)}
        _NEW_BLUEPRINTS_ATTR = {"fitscale": Real(nonneg=True), "label": Text()}
        _NEW_DEFAULT_VALS = {"fitscale": 1.0}
        _NEW_NO_COPY_VALS = {"label"}
        _DEL_MUJOCO_ATTR = {"fluidcoef"}

    assert "fitscale" in FittedSphere._MUJOCO_ATTR and "fluidcoef" not in FittedSphere._MUJOCO_ATTR
    assert "fluidcoef" in Sphere._MUJOCO_ATTR  # the parent is untouched
    assert FittedSphere._DEFAULT_VALS["fitscale"] == 1.0 and FittedSphere.type == "sphere"
    label = ["shared"]
    geom = FittedSphere("g", radius=0.1, label=label)
    assert geom.fitscale == 1.0
    world = World()
    world.attach(Body("b").attach(geom))
    assert "fitscale" not in world.to_xml_string()  # equal to its default: omitted
    geom.fitscale = 2.0
    assert 'fitscale="2"' in world.to_xml_string()
    assert world.model.ngeom == 1
    clone = geom.copy()
    assert clone.fitscale == 2.0 and clone.label is label  # _NO_COPY_VALS: shared
    with pytest.raises(ThingAttributeError, match=r"FittedSphere 'g' .*\.fitscale"):
        geom.fitscale = -1.0


def test_ids_are_unique_and_registered():
    things = [Body(), Sphere(), Hinge(), Body()]
    ids = [t.ID for t in things]
    assert len(set(ids)) == len(ids)
    assert all(REGISTRY.get(t.ID) is t for t in things)


def test_seed_signature_name_parent_kwargs():
    parent = Body("torso")
    geom = Box("box", parent, size=[0.1, 0.2, 0.3])
    assert geom.parent is parent and geom.name == "box"
    assert np.array_equal(geom.size, [0.1, 0.2, 0.3])
    with pytest.raises(TypeError, match="sizee"):
        Box(sizee=[1, 1, 1])


# ---------------------------------------------------------------- tree
def test_parent_root_path_follow_reparenting_and_detaching():
    a, b, c = Body("a"), Body("b"), Body("c")
    g = Sphere("g", radius=0.1)
    a.attach(b)
    b.attach(g)
    assert g.root is a and g.path == [g, b, a] and b.children == (g,)
    c.attach(g)  # re-parent: removed from b
    assert g.parent is c and g.root is c and b.children == () and g.path == [g, c]
    c.parent = a  # parent setter attaches
    assert g.root is a and g.path == [g, c, a]
    c.detach()
    assert c.parent is None and c.root is c and g.root is c and a.children == (b,)
    g.parent = None
    assert g.root is g and g.path == [g] and c.children == ()


def test_attach_rejects_cycles_and_wrong_kinds():
    a, b = Body("a"), Body("b")
    a.attach(b)
    with pytest.raises(ThingAttributeError, match="cycle"):
        b.attach(a)
    with pytest.raises(ThingAttributeError, match="cannot be attached"):
        Sphere().attach(Body())
    with pytest.raises(ThingAttributeError, match="Motor cannot be attached to a Body"):
        Body().attach(Motor())
    with pytest.raises(ThingAttributeError, match="measures or drives a site"):
        Hinge().attach(Gyro())


# ---------------------------------------------------------------- copy
def test_copy_is_deep_and_overrides_kwargs():
    limb = Body("limb", pos=[0, 0, 1])
    hinge = Hinge("knee", axis=[0, 1, 0], range=[-1, 1])
    hinge.attach(Motor("knee_motor", gear=[20]))
    geom = Capsule("shin", radius=0.03, half_length=0.2)
    limb.attach(hinge, geom, Camera("eye", mode="targetbody", target=limb))
    clone = limb.copy(pos=[1, 2, 3])
    assert np.array_equal(clone.pos, [1, 2, 3]) and np.array_equal(limb.pos, [0, 0, 1])
    c_hinge, c_geom, c_cam = clone.children
    assert c_hinge is not hinge and c_geom is not geom and c_hinge.parent is clone
    assert c_hinge.axis is not hinge.axis and np.array_equal(c_hinge.axis, hinge.axis)
    assert c_hinge.children[0] is not hinge.children[0]
    assert c_cam.target is clone  # references inside the copied subtree follow the copy
    c_geom.size = [0.05, 0.1]
    assert geom.size[0] == 0.03  # no shared state
    assert c_hinge.ID != hinge.ID


def test_arrays_are_read_only_so_edits_go_through_validation():
    geom = Sphere(radius=0.1)
    with pytest.raises(ValueError):
        geom.pos[0] = 1.0


# ---------------------------------------------------------------- names
def test_name_enumeration_is_deterministic_and_skips_taken_names():
    root = Body("root")
    first, second, third = Sphere("pad"), Sphere("pad"), Sphere("pad_1")
    root.attach(first, second, third)
    # "pad_1" is requested by the third geom, so the second "pad" becomes "pad_2"
    assert [first.name, second.name, third.name] == ["pad", "pad_2", "pad_1"]
    other = Body("pad")  # another namespace (body) does not clash with geoms
    root.attach(other)
    assert other.name == "pad"
    second.detach()
    assert second.name == "pad" and third.name == "pad_1"


def test_attaching_the_same_limb_twice_gives_a_valid_model_with_distinct_names():
    finger = Body("finger", pos=[0.05, 0, 0])
    joint = Hinge("joint", axis=[0, 1, 0], range=[0, 1])
    joint.attach(Position("act", kp=10), JointPos("pos"))
    finger.attach(joint, Box("pad", size=[0.01, 0.01, 0.03]), Site("tip"))
    palm = Body("palm", pos=[0, 0, 0.5])
    palm.attach(Box("palm", size=[0.05, 0.05, 0.01]), finger.copy(), finger.copy(pos=[-0.05, 0, 0]))
    world = World()
    world.attach(palm)
    model = world.model
    left, right = palm.bodies
    assert (left.name, right.name) == ("finger", "finger_1")
    assert (left.joints[0].name, right.joints[0].name) == ("joint", "joint_1")
    for thing, obj in [
        (right, mujoco.mjtObj.mjOBJ_BODY),
        (right.joints[0], mujoco.mjtObj.mjOBJ_JOINT),
    ]:
        assert mujoco.mj_name2id(model, obj, thing.name) >= 0
    assert model.nu == 2 and model.nsensor == 2
    assert mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_ACTUATOR, 1) == "act_1"
    # the second actuator drives the second joint
    assert model.actuator_trnid[1, 0] == mujoco.mj_name2id(
        model, mujoco.mjtObj.mjOBJ_JOINT, "joint_1"
    )


def test_unnamed_target_of_an_actuator_gets_a_class_name():
    body = Body("b")
    slide = Slide(axis=[1, 0, 0])
    slide.attach(Motor())
    body.attach(slide, Sphere(radius=0.1))
    world = World()
    world.attach(body)
    assert slide.name == "slide"
    assert 'joint="slide"' in world.to_xml_string() and world.model.nu == 1


# ---------------------------------------------------------------- validation
@pytest.mark.parametrize(
    ("thing", "attr", "value", "expect"),
    [
        (Sphere("ball"), "size", [-0.1], "non-negative"),
        (Sphere("ball"), "size", "big", "sequence"),
        (Hinge("knee"), "range", [1.0, -1.0], "lower <= upper"),
        (Hinge("knee"), "axis", [0, 0, 0], "non-zero"),
        (Hinge("knee"), "damping", -1.0, "non-negative"),
        (Box("b"), "condim", 2.5, "integer"),
        (Box("b"), "mass", -1.0, ">= 0"),
        (Box("b"), "rgba", [1, 0, 0], "4 numbers"),
        (Motor("m"), "ctrllimited", "yes", "auto, true, false"),
        (Body("torso"), "mocap", 1, "True or False"),
    ],
)
def test_bad_values_raise_errors_naming_thing_and_attribute(thing, attr, value, expect):
    before = getattr(thing, attr)
    with pytest.raises(ThingAttributeError) as info:
        setattr(thing, attr, value)
    message = str(info.value)
    assert f"{type(thing).__name__} '{thing._name}'" in message
    assert f".{attr}:" in message and expect in message
    assert (getattr(thing, attr) == before) is True or np.array_equal(getattr(thing, attr), before)


def test_derived_attributes_are_fixed_by_the_class():
    with pytest.raises(ThingAttributeError, match="fixed by the class Sphere"):
        Sphere().type = "box"


def test_basething_is_usable_directly():
    thing = BaseThing(name="plain")
    assert thing.name == "plain" and thing.parent is None and thing.root is thing
