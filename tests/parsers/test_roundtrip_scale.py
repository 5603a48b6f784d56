"""Round trip of large robots and of massless links (issue 11, "Scale"): geoms matched
per body (not all pairs), forward kinematics compared in arrays, inertia compared on
every body, massless ones included. Speed itself is measured in
``benchmarks/roundtrip_scale.py``; these tests check that the faster matching still
matches right and still fails when it should."""

from __future__ import annotations

from pathlib import Path

import mujoco
import numpy as np
import pytest

from robotwright.parsers.reference import quat_angle, view_from_model
from robotwright.proof.roundtrip.run import compare_geoms, compare_views, rotation_angles, roundtrip


def tree_urdf(n: int, *, branching: int = 4) -> str:
    """A URDF tree of ``n`` links (link i hangs from link (i-1)//branching), each with an
    unnamed box collision geom and visual, on revolute joints."""
    out = ['<robot name="tree">']
    for i in range(n):
        out.append(
            f'<link name="l{i}"><inertial><origin xyz="0 0 0.05"/><mass value="0.1"/>'
            '<inertia ixx="1e-4" iyy="2e-4" izz="1.5e-4" ixy="0" ixz="0" iyz="0"/></inertial>'
            '<visual><origin xyz="0 0 0.05"/><geometry><box size="0.02 0.02 0.1"/></geometry>'
            '</visual><collision><origin xyz="0 0.01 0.05" rpy="0.1 0 0"/><geometry>'
            '<box size="0.02 0.02 0.1"/></geometry></collision></link>'
        )
        if i:
            out.append(
                f'<joint name="j{i}" type="revolute"><parent link="l{(i - 1) // branching}"/>'
                f'<child link="l{i}"/><origin xyz="0 0 0.1" rpy="0 0 {0.1 * (i % 7)}"/>'
                '<axis xyz="0 1 0"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>'
            )
    out.append("</robot>")
    return "\n".join(out)


def test_a_tree_of_many_links_round_trips(tmp_path: Path) -> None:
    path = tmp_path / "tree.urdf"
    path.write_text(tree_urdf(600))
    report = roundtrip(path, configs=5)
    assert report.ok, report.table()
    rows = {r.check: r for r in report.rows}
    assert rows["MJCF: collision geoms (type, size, pose at q0)"].value.startswith("600/600")


def test_a_chain_too_deep_for_mjcf_is_answered_before_the_reference(tmp_path: Path) -> None:
    """A chain of 600 links: MuJoCo imports the URDF, but MJCF cannot nest it. The answer
    names the body too deep, and no reference was loaded for it (MuJoCo's import of a
    deeper chain takes far longer than this answer)."""
    path = tmp_path / "chain.urdf"
    path.write_text(tree_urdf(600, branching=1))
    report = roundtrip(path, configs=2)
    assert not report.ok
    assert report.error is not None and report.error.startswith("our MJCF is not written")
    assert "'l496' is nested 497 bodies deep" in report.error
    assert report.reference == "" and not report.rows


def test_the_round_trip_legs_agree_with_one_at_a_time(tmp_path: Path) -> None:
    """The three MuJoCo imports run at once; each leg's table equals the one computed
    alone (the source's view, our MJCF's, our URDF's)."""
    from robotwright.proof.roundtrip.run import (
        TOL_URDF,
        our_mjcf_model,
        our_urdf_view,
        parse_source,
        reference_view,
    )

    path = tmp_path / "tree.urdf"
    path.write_text(tree_urdf(40, branching=3))
    report = roundtrip(path, configs=3, simulate=False)  # the static legs only
    hrdf = parse_source(path).hrdf
    ref, ours = reference_view(path), view_from_model(our_mjcf_model(hrdf))
    alone = [
        ("MJCF: " + r.check, r.value, r.ok)
        for r in compare_views(
            ref, ours, configs=3, collision_only=True, source_has_actuators=False
        )
    ]
    alone += [
        ("URDF: " + r.check, r.value, r.ok)
        for r in compare_views(
            ref, our_urdf_view(hrdf), tol=TOL_URDF, configs=3, full=False, inertials_ref=ours
        )
    ]
    assert [(r.check, r.value, r.ok) for r in report.rows] == alone
    assert report.ok and report.reference == "mujoco"


def _model(bodies: list[list[tuple[str, str]]]) -> mujoco.MjModel:
    """Bodies on hinges, each with unnamed box geoms given as (pos, size) strings."""
    xml = ["<mujoco><worldbody><body name='root'><freejoint/><geom size='0.1'/>"]
    for i, geoms in enumerate(bodies):
        xml.append(
            f"<body name='b{i}' pos='{i} 0 0'><joint name='j{i}' axis='0 1 0'/>"
            "<inertial pos='0 0 0' mass='1' diaginertia='0.1 0.1 0.1'/>"
        )
        xml += [f"<geom type='box' pos='{p}' size='{s}'/>" for p, s in geoms]
        xml.append("</body>")
    xml.append("</body></worldbody></mujoco>")
    return mujoco.MjModel.from_xml_string("".join(xml))


def _geoms_row(ref: list, ours: list):
    return compare_geoms(
        view_from_model(_model(ref)), view_from_model(_model(ours)), 1e-9, collision_only=False
    )


def test_geoms_match_per_body_in_any_order() -> None:
    ref = [[("0 0 0", "0.1 0.1 0.1"), ("0 0 1", "0.1 0.1 0.1")], [("0 1 0", "0.2 0.1 0.1")]]
    ours = [[("0 0 1", "0.1 0.1 0.1"), ("0 0 0", "0.1 0.1 0.1")], [("0 1 0", "0.2 0.1 0.1")]]
    assert _geoms_row(ref, ours).ok


def test_geoms_moved_to_another_body_match_by_pose() -> None:
    # Body 1's geom carried by body 0 at the same world pose (as a merged link would be).
    ref = [[("0 0 0", "0.1 0.1 0.1")], [("0 1 0", "0.2 0.1 0.1")]]
    ours = [[("0 0 0", "0.1 0.1 0.1"), ("1 1 0", "0.2 0.1 0.1")], []]
    assert _geoms_row(ref, ours).ok


@pytest.mark.parametrize(
    "ours",
    [
        [[("0 0 0", "0.1 0.1 0.1")], [("0 1 0", "0.2 0.1 0.3")]],  # a size changed
        [[("0 0 0", "0.1 0.1 0.1")], [("0 1 1e-6", "0.2 0.1 0.1")]],  # moved 1e-6 m
        [[("0 0 0", "0.1 0.1 0.1")], []],  # a geom lost
    ],
)
def test_geom_differences_fail(ours: list) -> None:
    ref = [[("0 0 0", "0.1 0.1 0.1")], [("0 1 0", "0.2 0.1 0.1")]]
    assert not _geoms_row(ref, ours).ok


def test_rotation_angles_agree_with_quat_angle() -> None:
    rng = np.random.default_rng(5)
    quats = rng.normal(size=(40, 4))
    quats /= np.linalg.norm(quats, axis=1, keepdims=True)
    mats = np.empty((40, 9))
    for q, m in zip(quats, mats, strict=True):
        mujoco.mju_quat2Mat(m, q)
    r1, r2 = mats[:20].reshape(-1, 3, 3), mats[20:].reshape(-1, 3, 3)
    expected = [quat_angle(a, b) for a, b in zip(r1, r2, strict=True)]
    np.testing.assert_allclose(rotation_angles(r1, r2), expected, atol=1e-12)
    assert rotation_angles(r1, r1).max() < 1e-7


def _massless_model(inertia: str | None) -> mujoco.MjModel:
    """A body on a hinge and a welded child with mass 0 and the given inertia (or none)."""
    child = (
        f"<inertial pos='0 0 0' mass='0' diaginertia='{inertia}'/>"
        if inertia
        else "<inertial pos='0 0 0' mass='0' diaginertia='0 0 0'/>"
    )
    return mujoco.MjModel.from_xml_string(
        "<mujoco><worldbody><body name='a'><joint name='j' axis='0 0 1'/>"
        "<inertial pos='0 0 0' mass='1' diaginertia='0.1 0.1 0.1'/>"
        f"<body name='tip' pos='0 0 1'>{child}</body></body></worldbody></mujoco>"
    )


def _inertia_row(ref: mujoco.MjModel, ours: mujoco.MjModel):
    rows = compare_views(view_from_model(ref), view_from_model(ours), configs=2)
    return {r.check: r for r in rows}["inertia tensors max rel.err"]


def test_inertia_of_a_massless_link_is_compared() -> None:
    # pybullet's franka panda_link8: mass 0 and non-zero inertia. Zeroing it must fail.
    ref = _massless_model("0.3 0.3 0.3")
    assert not _inertia_row(ref, _massless_model(None)).ok
    assert _inertia_row(ref, _massless_model("0.3 0.3 0.3")).ok
    assert _inertia_row(_massless_model(None), _massless_model(None)).ok


@pytest.mark.parametrize("full", [True, False])
def test_every_body_inertia_is_compared_on_both_legs(full: bool) -> None:
    """The URDF leg (``full=False``) compares each body's inertia too: a link whose
    inertia was lost (a massless moving link that carries inertia) fails the row."""
    xml = """<mujoco><worldbody><body name="a"><joint type="hinge"/>
      <inertial pos="0 0 0" mass="1" diaginertia="0.1 0.1 0.1"/>
      <body name="b" pos="0 0 0.2"><joint type="hinge"/>
        <inertial pos="0 0 0" mass="{m}" diaginertia="{i} {i} {i}"/></body>
    </body></worldbody></mujoco>"""
    ref = mujoco.MjModel.from_xml_string(xml.format(m=1e-9, i=0.02))
    lost = mujoco.MjModel.from_xml_string(xml.format(m=1e-9, i=1e-12))
    same = compare_views(view_from_model(ref), view_from_model(ref), configs=2, full=full)
    rows = compare_views(view_from_model(ref), view_from_model(lost), configs=2, full=full)
    assert all(r.ok for r in same)
    inertia = next(r for r in rows if r.check == "inertia tensors max rel.err")
    assert not inertia.ok


def test_actuators_made_for_a_urdf_are_checked_against_its_joints(tmp_path: Path) -> None:
    """MuJoCo's URDF import has no actuators; those ``actuators="motor"`` makes are not a
    failure, but each must drive a moving joint of the source, once."""
    from robotwright.proof.roundtrip.compare import _made_actuators_row

    path = tmp_path / "tree.urdf"
    path.write_text(tree_urdf(6))
    report = roundtrip(path, configs=2, actuators="motor")
    row = next(r for r in report.rows if r.check.startswith("MJCF: actuators"))
    assert report.ok and row.ok and row.value == "0/5" and row.compared == 5
    plain = roundtrip(path, configs=2)
    row = next(r for r in plain.rows if r.check.startswith("MJCF: actuators"))
    assert plain.ok and not row.applicable
    # An actuator on a joint the source does not have, or a joint driven twice, fails.
    ref = view_from_model(_motor_model(["j1", "j2"]))
    assert _made_actuators_row(ref, view_from_model(_motor_model(["j1", "j2"], ["j1", "j2"]))).ok
    assert not _made_actuators_row(
        ref, view_from_model(_motor_model(["j1", "j2"], ["j1", "j1"]))
    ).ok
    assert not _made_actuators_row(ref, view_from_model(_motor_model(["j1", "jx"], ["jx"]))).ok


def _motor_model(joints: list[str], motors: tuple[str, ...] | list[str] = ()) -> mujoco.MjModel:
    xml = "<mujoco><worldbody><body name='a'><freejoint/><geom size='0.1'/>"
    xml += "".join(
        f"<body name='b{j}'><joint name='{j}'/><geom size='0.1'/></body>" for j in joints
    )
    xml += "</body></worldbody><actuator>"
    xml += "".join(f"<motor joint='{j}'/>" for j in motors)
    return mujoco.MjModel.from_xml_string(xml + "</actuator></mujoco>")


def test_a_chain_too_deep_for_mjcf_exports_to_urdf_saying_the_proof_is_not_made(
    tmp_path: Path, capsys
) -> None:
    from robotwright.cli import main

    source = tmp_path / "chain.urdf"
    source.write_text(tree_urdf(600, branching=1))
    assert main(["convert", str(source), "-o", str(tmp_path / "hrdf")]) == 0
    capsys.readouterr()
    out = tmp_path / "out.urdf"
    # URDF files are flat: the chain is written; only the proof (through our MJCF,
    # whose nesting MuJoCo's reader limits) cannot be made, and the note says so.
    assert main(["-v", "export", str(tmp_path / "hrdf"), "--format", "urdf", "-o", str(out)]) == 0
    err = capsys.readouterr().err
    assert "proof: not made" in err and "600 bodies deep" in err, err
    text = out.read_text()
    assert all(f'<link name="l{i}"' in text for i in range(600))
    # MJCF cannot hold it: refused, saying what can.
    assert main(["export", str(tmp_path / "hrdf"), "-o", str(tmp_path / "out.xml")]) == 2
    assert "write URDF or HRDF" in capsys.readouterr().err
    assert not (tmp_path / "out.xml").exists()
