"""The proof simulates: two compiled models stepped side by side with contacts, with
zero and with a fixed pseudo-random control, their joint positions compared."""

from __future__ import annotations

from pathlib import Path

import mujoco
import numpy as np
import trimesh

from robotwright.proof.compare import _rollouts
from robotwright.proof.convert import convert
from robotwright.proof.rollout import ROLLOUT_TOL, rollout_differences

_ARM = """<mujoco model="arm">
  <asset><mesh name="part" file="part.stl"{hull}/></asset>
  <worldbody>
    <geom name="floor" type="plane" size="2 2 0.1"/>
    <body name="base">
      <geom name="shell" type="mesh" mesh="part" mass="1"/>
      <body name="upper" pos="0 0 0.3">
        <joint name="shoulder" axis="0 1 0" damping="0.1"/>
        <geom type="capsule" fromto="0 0 0 0.15 0 0" size="0.02" mass="0.5"/>
        <body name="lower" pos="0.15 0 0">
          <joint name="elbow" axis="0 1 0" damping="0.1"/>
          <geom name="tip" type="capsule" fromto="0 0 0 -0.15 0 -0.26" size="0.02" mass="0.5"/>
        </body>
      </body>
    </body>
  </worldbody>
  <actuator>
    <motor name="m_shoulder" joint="shoulder" ctrlrange="-2 2" ctrllimited="true"/>
    <motor name="m_elbow" joint="elbow"/>
  </actuator>
</mujoco>"""


def _tree_urdf(n: int, branching: int) -> str:
    """tests/parsers' URDF of ``n`` box links (link i on link (i-1)//branching)."""
    import sys

    sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "parsers"))
    from test_roundtrip_scale import tree_urdf

    return tree_urdf(n, branching=branching)


def _model(folder: Path, hull: str = "") -> mujoco.MjModel:
    if not (folder / "part.stl").exists():
        m = trimesh.creation.icosphere(subdivisions=3, radius=0.1)
        m.vertices *= [1.0, 0.7, 0.5]
        m.vertices += np.random.default_rng(1).normal(0, 0.003, m.vertices.shape)
        m.export(folder / "part.stl")
    xml = _ARM.format(hull=hull)
    path = folder / ("arm_capped.xml" if hull else "arm.xml")
    path.write_text(xml)
    return mujoco.MjModel.from_xml_path(str(path))


def test_the_same_model_rolls_out_the_same(tmp_path) -> None:
    a, b = _model(tmp_path), _model(tmp_path)
    assert _rollouts(a, b) == []


def test_a_changed_collision_hull_is_a_simulation_difference(tmp_path) -> None:
    """The arm's tip rests on its base's mesh, a hull of 8 vertices or the full one:
    every array of bodies and joints agrees, the contacts do not. The floor (scene, not
    written by a conversion) is left out of both."""
    full, capped = _model(tmp_path), _model(tmp_path, ' maxhullvert="8"')
    found = _rollouts(full, capped)
    assert [d.field for d in found] == [
        "simulation, zero control, 200 steps",
        "simulation, pseudo-random control, 200 steps",
    ]
    assert "joint 'shoulder'" in found[0].result or "joint 'elbow'" in found[0].result
    size = float(found[0].result.split("by up to ")[1].split()[0])
    assert size > ROLLOUT_TOL


def test_the_controls_reach_the_matched_actuators(tmp_path) -> None:
    """Actuators matched in another order get the same control: a result whose motors
    are listed the other way round rolls out the same; one whose motor is stronger does
    not (under the pseudo-random control only)."""
    a = _model(tmp_path)
    spec = mujoco.MjSpec.from_file(str(tmp_path / "arm.xml"))
    swapped = spec.copy()
    for act in list(swapped.actuators):
        swapped.delete(act)
    for name, joint in (("m_elbow", "elbow"), ("m_shoulder", "shoulder")):
        act = swapped.add_actuator(name=name, target=joint, trntype=mujoco.mjtTrn.mjTRN_JOINT)
        if name == "m_shoulder":
            act.ctrllimited, act.ctrlrange = True, [-2, 2]
    b = swapped.compile()
    amap = {0: 1, 1: 0}
    qmap = {i: i for i in range(a.nq)}
    assert rollout_differences(a, b, qmap, amap) == []
    stronger = spec.copy()
    stronger.actuators[0].gear[0] = 1.5
    found = rollout_differences(a, stronger.compile(), qmap, {0: 0, 1: 1})
    assert [d.field for d in found] == ["simulation, pseudo-random control, 200 steps"]


def test_unmatched_models_are_not_rolled_out(tmp_path) -> None:
    a = _model(tmp_path)
    assert rollout_differences(a, a, {0: 0}, {0: 0, 1: 1}) == []  # a coordinate unmatched


def test_convert_reports_a_dropped_hull_cap_in_simulation(tmp_path) -> None:
    _model(tmp_path, ' maxhullvert="8"')
    out = convert(tmp_path / "arm_capped.xml", tmp_path / "out.xml", simulate=True)
    notes = [m for m in out if "proof:" in m]
    assert any("collision hull" in n for n in notes)
    assert any("simulation, zero control" in n for n in notes)
    # The simulation is on by default; simulate=False compares the compiled models only.
    default = convert(tmp_path / "arm_capped.xml", tmp_path / "default.xml")
    assert any("simulation, zero control" in m for m in default)
    plain = convert(tmp_path / "arm_capped.xml", tmp_path / "plain.xml", simulate=False)
    assert not [m for m in plain if "simulation," in m]


def test_the_command_line_simulates_unless_told_not_to(tmp_path, capsys) -> None:
    from robotwright.cli import main

    _model(tmp_path, ' maxhullvert="8"')
    src, out = tmp_path / "arm_capped.xml", tmp_path / "cli.xml"
    assert main(["convert", str(src), "-o", str(out), "-v"]) == 0
    assert "proof: simulation, zero control, 200 steps differs" in capsys.readouterr().err
    assert main(["convert", str(src), "-o", str(tmp_path / "n.xml"), "--no-simulate", "-v"]) == 0
    assert "proof: simulation" not in capsys.readouterr().err


def test_roundtrip_reports_the_simulation_as_a_row(tmp_path, capsys) -> None:
    from robotwright.cli import main
    from robotwright.proof.roundtrip.run import SIMULATION_CHECK, roundtrip

    _model(tmp_path)
    _model(tmp_path, ' maxhullvert="8"')
    same = {r.check: r for r in roundtrip(tmp_path / "arm.xml", configs=5, simulate=True).rows}
    assert same[SIMULATION_CHECK].ok and same[SIMULATION_CHECK].compared == 1
    # The source's hull is capped at 8 vertices and our MJCF's is not: the static rows
    # compare bodies, joints and geoms alike; the simulation row sees the contacts.
    report = roundtrip(tmp_path / "arm_capped.xml", configs=5, simulate=True)
    row = {r.check: r for r in report.rows}[SIMULATION_CHECK]
    assert not row.ok and "differing from step" in row.value and not report.ok
    assert SIMULATION_CHECK in {r.check for r in roundtrip(tmp_path / "arm.xml").rows}
    left_out = roundtrip(tmp_path / "arm.xml", simulate=False).rows
    assert SIMULATION_CHECK not in {r.check for r in left_out}
    capsys.readouterr()
    assert main(["roundtrip", str(tmp_path / "arm_capped.xml")]) == 1
    assert "MJCF: simulation" in capsys.readouterr().out
    assert main(["roundtrip", str(tmp_path / "arm_capped.xml"), "--no-simulate"]) == 0


def test_round_off_alone_is_no_simulation_difference(tmp_path) -> None:
    """robosuite's ARX5 arm converts with every array equal but for 3e-15 in geom poses
    (mesh centres rounded); under the pseudo-random control those last digits grow into
    a 0.2 rad difference, which a start moved by 1e-12 does not show. The source's
    round-off twin (the source with the output's round-off-equal arrays) moves exactly
    as the output: no difference. A real change (a gear) stays a difference."""
    import pytest

    import robotwright.proof.rollout as rollout
    from robotwright.hrdf.model import HRDF
    from robotwright.proof.compare import _matched
    from robotwright.proof.roundtrip.run import our_mjcf_model

    assets = (
        Path(__file__).resolve().parents[2] / ".testdata/robosuite-models/robosuite_models/assets"
    )
    src = assets / "robots" / "arx5" / "robot.xml"
    if not src.is_file():
        pytest.skip("robosuite-models data not fetched (run python tools/fetch_test_data.py)")
    messages = convert(src, tmp_path / "arx5", asset_roots=(assets,), simulate=True)
    assert not [m for m in messages if "simulation," in m], messages
    source = mujoco.MjModel.from_xml_path(str(src))
    ours = our_mjcf_model(HRDF.from_dir(tmp_path / "arx5"))
    twin, taken = rollout.round_off_twin(source, ours)
    assert taken >= 1
    assert np.abs(twin.geom_pos - ours.geom_pos).max() == 0.0
    assert 0 < np.abs(source.geom_pos - ours.geom_pos).max() < 1e-13
    _, _, maps, cols = _matched(source, ours, None)
    qmap, amap = cols["qpos"], maps["actuator"]
    # Without the twin the round-off is a difference (what made the rollout opt-in).
    real_twin = rollout.round_off_twin
    try:
        rollout.round_off_twin = lambda s, r: (s, 0)
        blamed = rollout.rollout_differences(source, ours, qmap, amap)
    finally:
        rollout.round_off_twin = real_twin
    # (MuJoCo 4.0's contacts carry those last digits that far; 3.11's do not)
    if int(mujoco.__version__.split(".")[0]) >= 4:
        assert [d.field for d in blamed] == ["simulation, pseudo-random control, 200 steps"]
    assert [d.field for d in blamed] in ([], ["simulation, pseudo-random control, 200 steps"])
    assert rollout.rollout_differences(source, ours, qmap, amap) == []
    spec = mujoco.MjSpec.from_file(str(src))
    spec.actuators[0].gear[0] = 2.0
    geared = spec.compile()
    found = rollout.rollout_differences(geared, ours, qmap, amap)
    assert "simulation, pseudo-random control, 200 steps" in [d.field for d in found]


_BODY = """<mujoco><worldbody><body name="b" pos="0 0 1"><freejoint/>
  <geom type="box" size="0.1 0.2 0.3" contype="0" conaffinity="0"/>
  <inertial pos="0 0 0" mass="2" {inertia}/></body></worldbody></mujoco>"""


def test_an_inertia_in_other_principal_axes_is_the_same_body() -> None:
    """One tensor, written once as its principal moments in MuJoCo's order and once in
    another order with the axes turned to match: the round-off twin takes the result's
    axes (with the body's bounding volumes, built in them); a tensor 1 % larger stays
    the source's."""
    from robotwright.proof.rollout import round_off_twin

    full = mujoco.MjModel.from_xml_string(
        _BODY.format(inertia='fullinertia="0.4 0.35 0.3 0.01 0.02 0.03"')
    )
    moments, quat = full.body_inertia[1], full.body_iquat[1]
    # the same axes listed y, z, x: turn the frame so that its x is the old y, and so on
    turn = np.zeros(4)
    mujoco.mju_mat2Quat(turn, np.array([[0, 0, 1], [1, 0, 0], [0, 1, 0]], float).reshape(-1))
    turned = np.zeros(4)
    mujoco.mju_mulQuat(turned, quat, turn)
    other = mujoco.MjModel.from_xml_string(
        _BODY.format(
            inertia=f'diaginertia="{moments[1]:.17g} {moments[2]:.17g} {moments[0]:.17g}" '
            f'quat="{" ".join(f"{v:.17g}" for v in turned)}"'
        )
    )
    assert not np.allclose(other.body_inertia[1], full.body_inertia[1])
    twin, taken = round_off_twin(full, other)
    assert taken >= 1
    assert np.array_equal(twin.body_iquat[1], other.body_iquat[1])
    assert np.array_equal(twin.body_inertia[1], other.body_inertia[1])
    larger = mujoco.MjModel.from_xml_string(
        _BODY.format(inertia='fullinertia="0.404 0.3535 0.303 0.0101 0.0202 0.0303"')
    )
    kept, _ = round_off_twin(full, larger)
    assert np.array_equal(kept.body_inertia[1], full.body_inertia[1])


def test_a_urdf_source_is_simulated_against_mujocos_import(tmp_path) -> None:
    """A URDF source is stepped beside MuJoCo's import of it (visual geoms left out of
    ours as that import leaves them). Unitree's A1 with its fixed links merged: MuJoCo's
    ``fusestatic`` and our merge give each merged body's tensor in other principal axes,
    and on MuJoCo 4.0 a leg-to-leg mesh contact at zero depth then comes and goes
    with the last digits: the twin that takes those axes moves as ours does."""
    import pytest

    from robotwright.catalog import find_entry
    from robotwright.proof.roundtrip.run import SIMULATION_CHECK, roundtrip

    entry = find_entry("a1")
    if entry is None or Path(entry.path).suffix != ".urdf":
        pytest.skip("a1 comes from example-robot-data (not installed)")
    report = roundtrip(Path(entry.path), configs=3, urdf=False, fixed_joints="merge")
    row = {r.check: r for r in report.rows}[SIMULATION_CHECK]
    assert row.ok and row.compared == 1, row
    assert report.simulated_model.ngeom < report.mjcf_model.ngeom  # no visual geoms
    # the proof of convert simulates it too: no note
    messages = convert(Path(entry.path), tmp_path / "a1", fixed_joints="merge", simulate=True)
    assert not [m for m in messages if "simulation," in m], messages
    # and a sitting robot is not a URDF's (its massless links have no match): no row
    sites = roundtrip(Path(entry.path), configs=3, urdf=False, fixed_joints="site")
    assert SIMULATION_CHECK not in {r.check for r in sites.rows}


def test_a_free_base_asked_for_is_in_the_roundtrip_reference_too() -> None:
    """``--floating-base`` on a URDF: the round trip's reference (MuJoCo's import) gets
    the same free joint, as ``convert``'s proof does; the joints then match one to one
    and the robot, free, is simulated beside ours (before: ``joints 12/13``, FAIL)."""
    import pytest

    from robotwright.catalog import find_entry
    from robotwright.proof.roundtrip.run import SIMULATION_CHECK, roundtrip

    entry = find_entry("go2")
    if entry is None or Path(entry.path).suffix != ".urdf":
        pytest.skip("go2 comes from example-robot-data (not installed)")
    report = roundtrip(Path(entry.path), configs=3, floating_base=True)
    rows = {r.check: r for r in report.rows}
    assert report.ok, report.table()
    assert rows["MJCF: joints (ref/ours)"].value == "13/13"
    assert rows[SIMULATION_CHECK].compared == 1 and rows[SIMULATION_CHECK].ok
    assert report.simulated_reference.jnt_type[0] == mujoco.mjtJoint.mjJNT_FREE


def _overlapping_tree(folder: Path) -> Path:
    """A 100-link tree (branching 4) whose box links overlap at rest: thousands of
    contacts, more than MuJoCo's arena holds (MuJoCo 4 stops stepping it)."""
    path = folder / "tree.urdf"
    path.write_text(_tree_urdf(100, branching=4), encoding="utf-8")
    return path


def test_a_source_overlapping_at_rest_is_not_simulated_and_says_why(tmp_path, capsys) -> None:
    """The proof's simulation is a note, not a crash or minutes of stepping, where the
    source has more contacts at rest than MAX_ROLLOUT_CONTACTS (the command's exit 0)."""
    from robotwright.cli import main
    from robotwright.proof.rollout import MAX_ROLLOUT_CONTACTS
    from robotwright.proof.roundtrip.run import SIMULATION_CHECK, roundtrip

    source = _overlapping_tree(tmp_path)
    model = mujoco.MjModel.from_xml_path(str(source))
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    assert data.ncon > MAX_ROLLOUT_CONTACTS
    messages = convert(source, tmp_path / "hrdf", simulate=True)
    skipped = [m for m in messages if "simulation not compared" in m]
    assert len(skipped) == 1 and f"{data.ncon} contacts" in skipped[0], messages
    assert main(["convert", str(source), "-o", str(tmp_path / "cli"), "-v"]) == 0
    assert "proof: simulation not compared" in capsys.readouterr().err
    report = roundtrip(source, configs=2, urdf=False)
    row = {r.check: r for r in report.rows}[SIMULATION_CHECK]
    assert row.compared == 0 and "not simulated" in row.value and "contacts" in row.value


def test_mujoco_stopping_the_source_or_the_output_is_told_apart(tmp_path) -> None:
    """MuJoCo's own error while stepping: the source's makes the simulation a note
    (RolloutNotMade), the output's alone a difference naming the step."""
    import pytest

    import robotwright.proof.rollout as rollout

    a, b = _model(tmp_path), _model(tmp_path)
    real_step, real_alone = mujoco.mj_step, rollout._robot_alone
    copies: list = []  # the source's and the output's copies, world geoms made inert
    fails = {"which": 1}  # 0: the source, 1: the output

    def alone(model):
        copies.append(real_alone(model))
        return copies[-1]

    def step(m, d):
        if m is copies[fails["which"]] and d.time > 0.05:
            raise mujoco.FatalError("mj_stackAlloc: out of memory\nsecond line")
        real_step(m, d)

    qpos, act = {0: 0, 1: 1}, {0: 0, 1: 1}
    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(rollout, "_robot_alone", alone)
        patch.setattr(mujoco, "mj_step", step)
        found = rollout.rollout_differences(a, b, qpos, act)
        assert len(found) == 2 and all("stops stepping the output" in d.result for d in found)
        assert "mj_stackAlloc: out of memory" in found[0].result
        assert "second line" not in found[0].result
        copies.clear()
        fails["which"] = 0
        with pytest.raises(rollout.RolloutNotMade, match="stops stepping the source at step"):
            rollout.rollout_differences(a, b, qpos, act)


def _chain(n: int) -> mujoco.MjModel:
    """MuJoCo's import of a chain of ``n`` box links on hinges (a mass matrix of
    n(n-1)/2 entries)."""

    return mujoco.MjModel.from_xml_string(_tree_urdf(n, branching=1))


class _Report:
    """What simulation_row reads of a round trip's report: the source's model (MuJoCo's
    import) and ours."""

    reference = "mujoco"

    def __init__(self, source: mujoco.MjModel, ours: mujoco.MjModel) -> None:
        self.simulated_reference, self.simulated_model = source, ours


def test_a_long_chain_is_stepped_fewer_times_within_the_budget() -> None:
    """A step costs as the mass matrix's entries, a chain's growing as its length
    squared: a robot's 200 steps, a 300-link chain's as many as the budget buys, and a
    chain too long for MIN_ROLLOUT_STEPS is not simulated, saying why."""
    import pytest

    from robotwright.proof.rollout import (
        MIN_ROLLOUT_STEPS,
        ROLLOUT_STEPS,
        ROLLOUT_WORK,
        RolloutNotMade,
        rollout_steps,
    )

    short, long = _chain(100), _chain(300)
    assert short.nM == 99 * 100 // 2 and rollout_steps(short) == ROLLOUT_STEPS
    steps = rollout_steps(long)
    assert MIN_ROLLOUT_STEPS <= steps < ROLLOUT_STEPS
    assert steps * long.nM <= ROLLOUT_WORK < (steps + 1) * long.nM
    too_long = _chain(480)
    assert too_long.nM > ROLLOUT_WORK // MIN_ROLLOUT_STEPS
    with pytest.raises(RolloutNotMade, match=f"{too_long.nM:,} entries"):
        rollout_steps(too_long)


def test_a_long_chain_changed_is_found_in_its_fewer_steps() -> None:
    """The 300-link chain, damped (undamped, it falls chaotically: a start 1e-12 away
    ends 0.1 rad away), with one link's centre of mass moved 2 cm: the shorter
    rollouts still find it, naming their steps; unchanged, the chain moves the same,
    and roundtrip's row says over how many steps."""
    from robotwright.proof.rollout import rollout_steps
    from robotwright.proof.roundtrip.run import simulation_row

    source, result = _chain(300), _chain(300)
    for model in (source, result):
        model.dof_damping[:] = 1.0  # N m s / rad
    steps = rollout_steps(source)
    row = simulation_row(_Report(source, result))  # type: ignore[arg-type]
    assert row.ok and row.compared == 1
    assert row.value == f"the same motion over {steps} steps, fewer for a long chain (within 1e-6)"
    result.body_ipos[150, 0] += 0.02
    found = _rollouts(source, result)
    assert found and found[0].field == f"simulation, zero control, {steps} steps", found


def test_a_chain_too_long_to_step_is_a_note_and_a_row(tmp_path, capsys) -> None:
    """convert of a 480-link chain (within MJCF's depth): the proof compares it without
    the simulation and says so (exit 0); roundtrip's row says why, not 'not comparable'."""
    from robotwright.cli import main
    from robotwright.proof.roundtrip.run import SIMULATION_CHECK, simulation_row

    source = tmp_path / "chain.urdf"
    source.write_text(_tree_urdf(480, branching=1), encoding="utf-8")
    assert main(["convert", str(source), "-o", str(tmp_path / "hrdf"), "-v"]) == 0
    err = capsys.readouterr().err
    assert "proof: simulation not compared: its mass matrix has 114,960 entries" in err, err

    row = simulation_row(_Report(_chain(480), _chain(480)))  # type: ignore[arg-type]
    assert row.check == SIMULATION_CHECK and row.compared == 0 and row.ok
    assert row.value.startswith("not simulated: its mass matrix has 114,960 entries")


def test_contacts_past_mujocos_arena_are_a_reason_not_a_crash_or_minutes() -> None:
    """Trees of overlapping boxes: 300 links fill MuJoCo's arena at rest (MuJoCo 3.x then
    keeps no contact at all, and stepping it took 23 s), 1,000 links stop its collision
    with a FatalError. Both are a reason not to simulate, found before any step."""
    import pytest

    from robotwright.proof.rollout import RolloutNotMade

    for links, reason in ((300, "than MuJoCo's arena holds"), (1000, "MuJoCo cannot hold")):
        model = mujoco.MjModel.from_xml_string(_tree_urdf(links, branching=4))
        qpos = {i: i for i in range(model.nq)}
        with pytest.raises(RolloutNotMade, match=reason):
            rollout_differences(model, model, qpos, {})
