"""The proof compares the convex hull MuJoCo collides each mesh geom with: a conversion
that keeps every array but changes a hull (a dropped ``maxhullvert``, a moved vertex)
changes the contacts, and the proof says so, naming the geom."""

from __future__ import annotations

from pathlib import Path

import mujoco
import numpy as np
import pytest
import trimesh

from robotwright.proof.compare import compare_models
from robotwright.proof.convert import convert


def _robot(folder: Path, name: str, mesh_attrs: str = "", contype: int = 1) -> Path:
    """One free body with one collision mesh (an uneven ellipsoid of 642 vertices)."""
    if not (folder / "part.stl").exists():
        m = trimesh.creation.icosphere(subdivisions=3, radius=0.05)
        m.vertices *= [1.0, 0.6, 0.4]
        m.vertices += np.random.default_rng(0).normal(0, 0.002, m.vertices.shape)
        m.export(folder / "part.stl")
    path = folder / f"{name}.xml"
    path.write_text(
        f'<mujoco model="{name}"><asset><mesh name="part" file="part.stl"{mesh_attrs}/></asset>'
        '<worldbody><body name="b" pos="0 0 0.3"><freejoint name="root"/>'
        f'<geom name="shell" type="mesh" mesh="part" mass="1" contype="{contype}"/>'
        "</body></worldbody></mujoco>"
    )
    return path


def _hull_notes(messages: list[str]) -> list[str]:
    return [m for m in messages if "collision hull" in m]


def test_a_dropped_maxhullvert_is_a_hull_difference(tmp_path) -> None:
    src = _robot(tmp_path, "capped", ' maxhullvert="12"')
    notes = _hull_notes(convert(src, tmp_path / "out.xml"))
    assert len(notes) == 1 and "'shell'" in notes[0]
    assert "12 vertices" in notes[0]  # the source's hull; the output's has more


def test_a_kept_hull_is_no_difference(tmp_path) -> None:
    assert _hull_notes(convert(_robot(tmp_path, "plain"), tmp_path / "plain_out.xml")) == []
    # a mirrored mesh (negative scale) keeps its scale: the same hull
    mirrored = _robot(tmp_path, "mirrored", ' scale="1 -1 1"')
    assert _hull_notes(convert(mirrored, tmp_path / "mirrored_out.xml")) == []


def test_a_moved_hull_is_reported_with_its_distance(tmp_path) -> None:
    source = mujoco.MjModel.from_xml_path(str(_robot(tmp_path, "a")))
    mesh = trimesh.load(tmp_path / "part.stl")
    mesh.vertices *= 1.01  # every vertex 1 % farther out: the same hull, larger
    (tmp_path / "moved").mkdir()
    mesh.export(tmp_path / "moved" / "part.stl")
    moved = mujoco.MjModel.from_xml_path(str(_robot(tmp_path / "moved", "a")))
    found = [d for d in compare_models(source, moved) if d.field == "collision hull"]
    assert len(found) == 1 and "shell" in found[0].obj
    distance = float(found[0].result.split(" m from it")[0].split()[-1])
    farthest_out = 0.01 * float(np.linalg.norm(mesh.vertices / 1.01, axis=1).max())
    assert distance == pytest.approx(farthest_out, rel=0.01)


def test_a_geom_that_never_collides_has_no_hull_compared(tmp_path) -> None:
    src = _robot(tmp_path, "drawn", ' maxhullvert="12"', contype=0)
    text = src.read_text().replace('contype="0"', 'contype="0" conaffinity="0"')
    src.write_text(text)
    assert _hull_notes(convert(src, tmp_path / "drawn_out.xml")) == []


def test_talos_mirrored_collision_meshes_keep_their_hulls_and_their_contacts(tmp_path) -> None:
    """Issue 40, items 1 and 3, on a real robot's meshes: talos' 13 arm and leg collision
    meshes (example-robot-data), each mirrored (``scale="1 -1 1"``) on a free body, the
    bodies piled so that they touch from the first step. The rows keep the negative
    scale, so every hull MuJoCo collides with is the source's, polygons included (a
    mirrored copy of the file gave ``arm_6`` 198 polygons for 200), and the proof's
    simulation (200 steps, contacts on) finds the same motion."""
    from robotwright.catalog import find_entry

    entry = find_entry("talos")
    if entry is None:
        pytest.skip("talos comes from example-robot-data (not installed)")
    meshes = Path(entry.path).resolve().parents[1] / "meshes"
    files = sorted([*meshes.glob("arm/arm_*_collision.STL"), *meshes.glob("v2/*_collision.stl")])
    assert len(files) == 13
    assets, bodies = [], []
    for i, f in enumerate(files):
        (tmp_path / f.name).write_bytes(f.read_bytes())
        assets.append(f'<mesh name="m{i}" file="{f.name}" scale="1 -1 1"/>')
        bodies.append(
            f'<body name="part{i}" pos="{0.03 * (i % 4)} {0.03 * (i // 4)} {0.5 + 0.02 * i}">'
            f'<freejoint name="free{i}"/><geom name="g{i}" type="mesh" mesh="m{i}"/></body>'
        )
    src = tmp_path / "mirrored_talos_parts.xml"
    src.write_text(
        f"<mujoco><asset>{''.join(assets)}</asset><worldbody>{''.join(bodies)}</worldbody></mujoco>"
    )
    messages = convert(src, tmp_path / "out", simulate=True)
    assert not any("mirror" in m for m in messages), messages
    from robotwright.hrdf.model import HRDF
    from robotwright.proof.roundtrip.run import our_mjcf_model

    hrdf = HRDF.from_dir(tmp_path / "out")
    assert sorted(m.scale for m in hrdf.meshes) == [(1.0, -1.0, 1.0)] * 13
    source = mujoco.MjModel.from_xml_path(str(src))
    ours = our_mjcf_model(hrdf)

    def hull(model: mujoco.MjModel, geom: str) -> tuple[int, int, int]:
        mesh = model.geom(geom).dataid[0]
        adr = model.mesh_graphadr[mesh]
        return (
            int(model.mesh_graph[adr]),
            int(model.mesh_graph[adr + 1]),
            int(model.mesh_polynum[mesh]),
        )

    assert [hull(ours, f"g{i}") for i in range(13)] == [hull(source, f"g{i}") for i in range(13)]
    assert [m for m in messages if "proof:" in m] == []
    data = mujoco.MjData(source)
    mujoco.mj_forward(source, data)
    assert data.ncon > 0  # the pile touches from the start
