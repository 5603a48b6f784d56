"""A URDF visual and collision of one shape read back as one drawn, colliding geom."""

from __future__ import annotations

from pathlib import Path

import mujoco
import numpy as np
import pytest
import trimesh

from robotwright.parsers import urdf_to_hrdf
from robotwright.parsers.reference import urdf_mujoco_view, view_from_model
from robotwright.proof.roundtrip.run import compare_views, our_mjcf_model, roundtrip

INERTIAL = (
    '<inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" '
    'iyz="0"/></inertial>'
)
RED = '<material name="red"><color rgba="1 0 0 1"/></material>'


def _urdf(tmp_path: Path, base: str, child: str = "", joint: str = "fixed") -> Path:
    """A two-link robot: ``base`` and ``child`` are the links' geometry elements."""
    path = tmp_path / "r.urdf"
    path.write_text(
        f'<robot name="r">{RED}<link name="base">{INERTIAL}{base}</link>'
        f'<link name="tip">{INERTIAL}{child}</link>'
        f'<joint name="j" type="{joint}"><parent link="base"/><child link="tip"/>'
        '<origin xyz="0 0 0.3" rpy="0.1 0.2 0.3"/><axis xyz="0 0 1"/>'
        '<limit lower="-1" upper="1" effort="1" velocity="1"/></joint></robot>'
    )
    return path


def _el(tag: str, shape: str, origin: str = "", name: str | None = None, mat: str = "") -> str:
    n = f' name="{name}"' if name else ""
    o = f"<origin {origin}/>" if origin else ""
    return f"<{tag}{n}>{o}<geometry>{shape}</geometry>{mat}</{tag}>"


BOX = '<box size="0.1 0.2 0.3"/>'
AT = 'xyz="0 0 0.05" rpy="0.3 0 0"'


def _geoms(path: Path, **options):
    hrdf = urdf_to_hrdf(path, **options)
    return hrdf, [*hrdf.meshes, *hrdf.simple_geoms]


def test_same_geometry_and_origin_is_one_drawn_colliding_geom(tmp_path: Path) -> None:
    path = _urdf(
        tmp_path,
        _el("visual", BOX, AT, mat='<material name="red"/>') + _el("collision", BOX, AT, "shell"),
        joint="revolute",
    )
    hrdf, geoms = _geoms(path)
    (g,) = geoms
    assert (g.group, g.contact_type, g.contact_affinity) == (0, 1, 1)
    assert g.rgba == (1.0, 0.0, 0.0, 1.0) and g.geom_name == "shell"
    assert g.type == "box" and g.size == (0.05, 0.1, 0.15)
    # Compiled: the geom MuJoCo's own import makes of the collision, and drawn.
    model = our_mjcf_model(hrdf)
    assert model.ngeom == 1 and model.geom("shell").group[0] == 0
    rows = compare_views(
        urdf_mujoco_view(path), view_from_model(model), configs=5, collision_only=True
    )
    assert all(r.ok for r in rows), rows


@pytest.mark.parametrize(
    ("visual", "collision"),
    [
        (_el("visual", BOX, AT), _el("collision", BOX, 'xyz="0 0 0.05" rpy="0.3 0 1e-9"')),
        (_el("visual", BOX, AT), _el("collision", '<box size="0.1 0.2 0.30001"/>', AT)),
        (_el("visual", BOX, AT), _el("collision", '<sphere radius="0.1"/>', AT)),
        (_el("visual", BOX, AT, "a"), _el("collision", BOX, AT, "b")),
    ],
    ids=["origin", "size", "shape", "names"],
)
def test_different_origin_geometry_or_names_stay_apart(
    tmp_path: Path, visual: str, collision: str
) -> None:
    _, geoms = _geoms(_urdf(tmp_path, visual + collision))
    assert sorted((g.group, g.contact_type) for g in geoms) == [(2, 0), (3, 1)]


def test_unnamed_side_takes_the_other_name_and_pairs_are_one_to_one(tmp_path: Path) -> None:
    base = (
        _el("visual", BOX, AT, mat='<material name="red"/>')
        + _el("visual", BOX, AT, "second")
        + _el("collision", BOX, AT, "col")
    )
    child = _el("visual", '<sphere radius="0.2"/>', name="ball") + _el(
        "collision", '<sphere radius="0.2"/>'
    )
    _, geoms = _geoms(_urdf(tmp_path, base, child))
    got = sorted((g.body, g.geom_name, g.group, g.contact_type, g.rgba[0]) for g in geoms)
    assert got == [
        ("base", "col", 0, 1, 1.0),  # the first visual (red) pairs with the collision
        ("base", "second", 2, 0, 0.5),  # the second stays a visual
        ("tip", "ball", 0, 1, 0.5),
    ]


def test_mesh_pairs_need_the_same_file_and_scale(tmp_path: Path) -> None:
    (tmp_path / "meshes").mkdir()
    trimesh.creation.box(extents=(0.1, 0.2, 0.3)).export(tmp_path / "meshes" / "part.stl")
    mesh = '<mesh filename="meshes/part.stl" scale="1 1 2"/>'
    other = '<mesh filename="meshes/part.stl" scale="1 1 3"/>'
    base = _el("visual", mesh) + _el("collision", mesh)
    child = _el("visual", mesh) + _el("collision", other)
    hrdf, geoms = _geoms(_urdf(tmp_path, base, child, joint="revolute"))
    kinds = sorted((g.body, g.group, g.scale) for g in hrdf.meshes)
    assert kinds == [
        ("base", 0, (1.0, 1.0, 2.0)),
        ("tip", 2, (1.0, 1.0, 2.0)),
        ("tip", 3, (1.0, 1.0, 3.0)),
    ]
    assert our_mjcf_model(hrdf).ngeom == 3


def test_pair_on_a_merged_fixed_link_keeps_its_pose(tmp_path: Path) -> None:
    """fixed_joints='merge' moves the pair's one geom into the parent with the link's pose:
    MuJoCo's import with fusestatic puts its collision geom at the same place."""
    path = _urdf(tmp_path, "", _el("visual", BOX, AT) + _el("collision", BOX, AT))
    hrdf, geoms = _geoms(path, fixed_joints="merge")
    (g,) = geoms
    assert (g.body, g.group, g.contact_type) == ("base", 0, 1)
    ours = our_mjcf_model(hrdf)
    spec = mujoco.MjSpec.from_file(str(path))
    spec.compiler.fusestatic = True
    ref = spec.compile()
    ref_ids = [i for i in range(ref.ngeom) if ref.geom_contype[i]]
    assert len(ref_ids) == 1
    d1, d2 = mujoco.MjData(ours), mujoco.MjData(ref)
    mujoco.mj_kinematics(ours, d1)
    mujoco.mj_kinematics(ref, d2)
    np.testing.assert_allclose(d1.geom_xpos[0], d2.geom_xpos[ref_ids[0]], atol=1e-12)
    np.testing.assert_allclose(d1.geom_xmat[0], d2.geom_xmat[ref_ids[0]], atol=1e-12)


PB = Path(__file__).resolve().parents[2] / ".testdata" / "pybullet" / "pybullet_data"


@pytest.mark.realdata
def test_pybullet_cartpole_pairs_merge_and_round_trip() -> None:
    """cartpole.urdf: the cart and the pole carry a visual and a collision of one shape
    (one geom each now), the rail a visual only; the round trip stays exact."""
    path = PB / "cartpole.urdf"
    if not path.is_file():
        pytest.skip(f"{path} absent: run tools/fetch_test_data.py")
    _, geoms = _geoms(path)
    assert sorted((g.body, g.group) for g in geoms) == [("cart", 0), ("pole", 0), ("slideBar", 2)]
    report = roundtrip(path, configs=10)
    assert report.ok, report.table()
