"""Mesh staging: OBJ files split into several objects, which MuJoCo reads in part."""

from __future__ import annotations

from pathlib import Path

import mujoco
import numpy as np
import pytest
import trimesh

from robotwright.errors import ConversionError
from robotwright.parsers import mjcf_to_hrdf_with_warnings, urdf_to_hrdf_with_warnings
from robotwright.parsers.meshes import obj_object_faces
from robotwright.proof.roundtrip.run import our_mjcf_model

TET_V = "v 0 0 0\nv 0.1 0 0\nv 0 0.1 0\nv 0 0 0.1\n"
# One closed, outward-wound tetrahedron whose first face sits in its own object, as
# CAD exports split a part: MuJoCo reads only that face, an open shell of no volume.
SPLIT_TET = TET_V + "o lid\nf 1 3 2\ng rest\nf 1 2 4\nf 1 4 3\nf 2 3 4\n"
WHOLE_TET = TET_V + "o only\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n"

URDF = """<robot name="r">
  <link name="base"><inertial><mass value="1"/>
    <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial>
    <collision><geometry><mesh filename="{mesh}"/></geometry></collision></link>
</robot>
"""


def _robot(tmp_path: Path, obj_text: str) -> Path:
    (tmp_path / "part.obj").write_text(obj_text)
    path = tmp_path / "r.urdf"
    path.write_text(URDF.format(mesh="part.obj"))
    return path


def _mesh_model(file: Path) -> mujoco.MjModel:
    return mujoco.MjModel.from_xml_string(
        f'<mujoco><asset><mesh name="m" file="{file}"/></asset><worldbody><body>'
        '<joint/><geom type="mesh" mesh="m"/></body></worldbody></mujoco>'
    )


TWO_TETS = (
    TET_V + "v 1 0 0\nv 1.1 0 0\nv 1 0.1 0\nv 1 0 0.1\n"
    "o a\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\no b\nf 5 7 6\nf 5 6 8\nf 5 8 7\nf 6 7 8\n"
)


def test_mujoco_reads_only_the_first_object_of_an_obj(tmp_path: Path) -> None:
    """The premise of the repair: MuJoCo keeps the first object's faces only."""
    (tmp_path / "two.obj").write_text(TWO_TETS)
    assert _mesh_model(tmp_path / "two.obj").mesh_facenum[0] == 4
    (tmp_path / "split.obj").write_text(SPLIT_TET)
    with pytest.raises(ValueError, match="volume"):
        _mesh_model(tmp_path / "split.obj")


def test_obj_object_faces_counts_objects_and_groups(tmp_path: Path) -> None:
    (tmp_path / "a.obj").write_text(SPLIT_TET)
    (tmp_path / "b.obj").write_text("g empty\n" + WHOLE_TET)  # a faceless group is no object
    assert obj_object_faces(tmp_path / "a.obj") == (1, 3)
    assert obj_object_faces(tmp_path / "b.obj") == ()


def test_split_obj_without_option_is_linked_and_its_loss_reported(tmp_path: Path) -> None:
    path = _robot(tmp_path, SPLIT_TET)
    hrdf, warnings = urdf_to_hrdf_with_warnings(path, work_dir=tmp_path / "work")
    staged = tmp_path / "work" / hrdf.meshes[0].file
    # The file itself, not a conversion (a hard link, or a copy where the confined
    # reader may not link: Landlock refuses a link that would gain write access).
    assert staged.read_bytes() == (tmp_path / "part.obj").read_bytes()
    text = [str(w) for w in warnings if "part.obj" in str(w)]
    assert len(text) == 1 and "MuJoCo reads the first only (1 of 4 faces)" in text[0]
    with pytest.raises(ValueError, match="volume"):
        our_mjcf_model(hrdf)


def test_join_obj_objects_keeps_every_triangle_and_compiles(tmp_path: Path) -> None:
    path = _robot(tmp_path, SPLIT_TET)
    hrdf, warnings = urdf_to_hrdf_with_warnings(
        path, work_dir=tmp_path / "work", join_obj_objects=True
    )
    staged = tmp_path / "work" / hrdf.meshes[0].file
    assert staged.suffix == ".stl"
    text = [str(w) for w in warnings if "part.obj" in str(w)]
    assert len(text) == 1 and "2 objects (faces [1, 3])" in text[0] and "joined" in text[0]
    source = trimesh.load(str(tmp_path / "part.obj"), force="mesh", process=False)
    joined = trimesh.load(str(staged), force="mesh", process=False)
    # Same triangles, corner for corner and in the same winding; STL holds float32, as
    # MuJoCo's own mesh vertices do.
    np.testing.assert_array_equal(joined.triangles, source.triangles.astype(np.float32))
    assert joined.volume == pytest.approx(0.1**3 / 6, rel=1e-6)
    model = our_mjcf_model(hrdf)
    assert model.mesh_facenum[0] == 4
    with pytest.raises(ConversionError, match=r"part\.obj.*2 objects"):
        urdf_to_hrdf_with_warnings(
            path, work_dir=tmp_path / "strict", join_obj_objects=True, strict=True
        )


def test_single_object_obj_stays_linked_with_the_option(tmp_path: Path) -> None:
    path = _robot(tmp_path, WHOLE_TET)
    hrdf, warnings = urdf_to_hrdf_with_warnings(
        path, work_dir=tmp_path / "work", join_obj_objects=True
    )
    staged = tmp_path / "work" / hrdf.meshes[0].file
    assert staged.read_bytes() == (tmp_path / "part.obj").read_bytes()
    assert not [w for w in warnings if "part.obj" in str(w)]
    assert our_mjcf_model(hrdf).mesh_facenum[0] == 4


def test_convert_and_roundtrip_commands_take_join_obj_objects(tmp_path: Path, capsys) -> None:
    from robotwright.cli import main

    path = _robot(tmp_path, SPLIT_TET)
    # Without the option MuJoCo reads one triangle of the split OBJ and refuses the robot
    # (source and conversion alike): bad input, exit 2.
    assert main(["roundtrip", str(path), "--configs", "2"]) == 2
    assert main(["roundtrip", str(path), "--configs", "2", "--join-obj-objects"]) == 0
    out = tmp_path / "out.xml"
    assert main(["convert", str(path), "-o", str(out), "--join-obj-objects", "-v"]) == 0
    captured = capsys.readouterr()  # conversion notes go to stderr
    assert "joined into one STL" in captured.out + captured.err
    assert mujoco.MjModel.from_xml_path(str(out)).mesh_facenum[0] == 4


def test_mjcf_source_with_split_obj_reported_and_joined_by_option(tmp_path: Path) -> None:
    (tmp_path / "two.obj").write_text(TWO_TETS)
    path = tmp_path / "m.xml"
    path.write_text(
        '<mujoco><asset><mesh name="two" file="two.obj"/></asset><worldbody>'
        '<body name="b"><joint/><geom type="mesh" mesh="two"/></body></worldbody></mujoco>'
    )
    hrdf, warnings = mjcf_to_hrdf_with_warnings(path, work_dir=tmp_path / "a")
    assert any("reads the first only (4 of 8 faces)" in str(w) for w in warnings)
    assert our_mjcf_model(hrdf).mesh_facenum[0] == 4  # as MuJoCo reads the source
    hrdf, warnings = mjcf_to_hrdf_with_warnings(
        path, work_dir=tmp_path / "b", join_obj_objects=True
    )
    assert any("two.obj': 2 objects (faces [4, 4])" in str(w) for w in warnings)
    assert our_mjcf_model(hrdf).mesh_facenum[0] == 8


def test_staging_folder_lives_as_long_as_a_robot_holds_it(probe: Path, tmp_path: Path) -> None:
    """Without work_dir the meshes are staged in a temporary folder that the parsed
    robot holds: copies made with dataclasses.replace keep it, and it is removed once no
    robot holds it (it used to stay in /tmp forever)."""
    import gc
    from dataclasses import replace

    from robotwright.generators import MJCFHumanoidGenerator

    hrdf = mjcf_to_hrdf_with_warnings(probe).hrdf
    folder = hrdf.root_dir
    assert folder is not None and (folder / hrdf.meshes[0].file).is_file()
    copy = replace(hrdf, name="copy")
    del hrdf
    gc.collect()
    assert folder.is_dir()
    # An export outside the staging folder copies the meshes, so it outlives it.
    out = tmp_path / "out" / "probe.xml"
    MJCFHumanoidGenerator.from_hrdf(copy).export(out)
    del copy
    gc.collect()
    assert not folder.exists()
    assert mujoco.MjModel.from_xml_path(str(out)).nmesh == 1


def test_work_dir_is_kept(probe: Path, tmp_path: Path) -> None:
    import gc

    hrdf = mjcf_to_hrdf_with_warnings(probe, work_dir=tmp_path / "stage").hrdf
    assert hrdf.temp_assets is None
    del hrdf
    gc.collect()
    assert any((tmp_path / "stage" / "meshes").iterdir())
