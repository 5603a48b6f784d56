"""Things at scale (issue 19): deep trees copy without recursion, and many name clashes
resolve to exactly the names the naming rule specifies (checked against a direct
transcription of the rule in the Things module doc)."""

from __future__ import annotations

import random

import mujoco
import pytest

from robotwright.things import Body, Hinge, Motor, Site, Sphere, World


def _chain(depth: int) -> Body:
    root = Body("b0", pos=[0, 0, 0.01])
    node = root
    for i in range(1, depth + 1):
        child = Body(f"b{i}" if i % 3 else "link", pos=[0, 0, 0.01 * (i % 5)])
        Sphere(f"g{i}", parent=child, radius=0.001 * (1 + i % 7))
        node.attach(child)
        node = child
    return root


def _shape(root: Body) -> list[tuple]:
    """Every Thing below ``root`` in MJCF order: class, user name, depth, key attributes."""
    out = []
    stack = [(root, 0)]
    while stack:
        node, depth = stack.pop()
        size = getattr(node, "size", None)
        out.append(
            (
                type(node).__name__,
                node._name,
                depth,
                tuple(getattr(node, "pos", ())),
                None if size is None else tuple(size),
            )
        )
        stack.extend((c, depth + 1) for c in reversed(node.children))
    return out


@pytest.mark.parametrize("depth", [999, 1000, 2000, 5000])
def test_deep_chains_copy(depth):
    root = _chain(depth)
    copy = root.copy()
    assert _shape(copy) == _shape(root)
    originals = {t.ID for t in root.walk()}
    assert not originals & {t.ID for t in copy.walk()}  # nothing shared
    # the deepest body of the copy is a new Thing whose parent chain is the copy's
    leaf = next(t for t in copy.walk() if isinstance(t, Body) and not t.bodies)
    assert leaf.root is copy and len(leaf.path) == depth + 1


def test_copy_keeps_overrides_and_internal_references():
    limb = Body("limb", pos=[1, 0, 0])
    joint = Hinge("hip", parent=limb)
    Motor("m", parent=joint)
    site = Site("tip", parent=limb)
    from robotwright.things import JointPos

    JointPos("q", parent=joint)
    copy = limb.copy(pos=[0, 2, 0])
    assert list(copy.pos) == [0, 2, 0] and list(limb.pos) == [1, 0, 0]
    new_joint = copy.joints[0]
    assert new_joint is not joint and new_joint.children[0].parent is new_joint
    assert [type(t).__name__ for t in copy.walk()] == [type(t).__name__ for t in limb.walk()]
    assert site.parent is limb


def _reference_names(root) -> dict[int, str]:
    """The naming rule of robotwright.things.base, transcribed literally: depth-first in
    child order, the first Thing keeps its name, each later one becomes ``name_k`` with
    the smallest k >= 1 no Thing of its namespace requests or already got.

    The search for k starts where the last search for the same name ended: names are only
    ever added to ``taken``, so no smaller k can have become free (and 5,000 copies of one
    name then cost 5,000 steps, not 12.5 million)."""
    wanted = [(t, t._name) for t in root.walk() if t._NAMESPACE and t._name]
    requested = {(t._NAMESPACE, n) for t, n in wanted}
    taken: set[tuple[str, str]] = set()
    searched_to: dict[tuple[str, str], int] = {}
    out = {}
    for thing, base in wanted:
        ns, final = thing._NAMESPACE, base
        if (ns, base) in taken:
            k = searched_to.get((ns, base), 1)
            while (ns, f"{base}_{k}") in taken or (ns, f"{base}_{k}") in requested:
                k += 1
            searched_to[(ns, base)] = k
            final = f"{base}_{k}"
        taken.add((ns, final))
        out[thing.ID] = final
    return out


@pytest.mark.parametrize("seed", range(12))
def test_random_clashes_resolve_as_the_rule_says(seed):
    rng = random.Random(seed)
    bases = ["pad", "pad_1", "pad_2", "link", "link_3", "x", "x_1_1", "x_1"]
    world = World()
    for _ in range(rng.randrange(50, 400)):
        body = Body(rng.choice(bases))
        for _ in range(rng.randrange(0, 3)):
            Sphere(rng.choice(bases), parent=body, radius=0.01)
        parent = rng.choice([world, *world.find_all(Body)[-5:]])
        parent.attach(body)
    expected = _reference_names(world)
    got = {t.ID: t.name for t in world.walk() if t.ID in expected}
    assert got == expected
    for ns in ("body", "geom"):
        names = [
            n
            for t, n in ((t, got[t.ID]) for t in world.walk() if t.ID in got)
            if ns == t._NAMESPACE
        ]
        assert len(names) == len(set(names))


@pytest.mark.parametrize("copies", [2, 100, 5000])
def test_many_copies_of_one_limb_get_distinct_names_and_compile(copies):
    limb = Body("link", pos=[0, 0, 0.1])
    joint = Hinge("j", parent=limb)
    Motor("m", parent=joint)
    Sphere("g", parent=limb, radius=0.01, mass=0.1)
    world = World()
    for _ in range(copies):
        world.attach(limb.copy())
    bodies = [b.name for b in world.find_all(Body)]
    assert bodies == ["link"] + [f"link_{k}" for k in range(1, copies)]
    assert _reference_names(world) == {
        t.ID: t.name for t in world.walk() if t._NAMESPACE and t._name
    }
    model = world.model
    assert model.nbody == copies + 1 and model.nu == copies
    last = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, f"j_{copies - 1}")
    assert model.actuator_trnid[copies - 1, 0] == last


def test_clash_with_requested_suffixes_is_skipped_at_scale():
    world = World()
    for k in range(1, 2000, 2):  # odd suffixes are requested by name
        world.attach(Body(f"leg_{k}"))
    plain = [Body("leg") for _ in range(1002)]
    world.attach(*plain)
    names = [b.name for b in plain]
    assert names[0] == "leg"
    assert names[1:] == [f"leg_{k}" for k in range(2, 2001, 2)] + ["leg_2001"]


def test_many_mesh_assets_of_one_name_get_distinct_names():
    from robotwright.things import MeshAsset

    world = World()
    assets = [MeshAsset("shell", vertex=[0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1]) for _ in range(3000)]
    world.assets.extend(assets)
    xml = world.to_xml_string()
    assert xml.count('<mesh name="shell"') == 1 and 'name="shell_2999"' in xml
    assert 'name="shell_3000"' not in xml
