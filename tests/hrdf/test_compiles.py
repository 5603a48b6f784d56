"""``validate`` ends with a compile (issue 11, "loaded means it compiles"): hostile mesh
contents and ``extra.xml`` that names what does not exist are problems located in the
robot's files, and a folder that validates exports and compiles."""

from __future__ import annotations

import shutil
from pathlib import Path

import numpy as np
import pytest
import trimesh

from robotwright.cli import main
from robotwright.generators import MJCFHumanoidGenerator
from robotwright.generators.compiles import check_compiles, validate_dir
from robotwright.hrdf import HRDF
from robotwright.hrdf.assets import BUNDLED_ROBOTS_DIR

MESH_HEADER = (
    "contact_type,contact_affinity,static_friction,dynamic_friction,restitution,"
    "pos0,pos1,pos2,quat0,quat1,quat2,quat3,rgba0,rgba1,rgba2,rgba3,body_name,name"
)
MESH_ROW = "1,1,1.0,1.0,,0,0,0,1,0,0,0,0.5,0.5,0.5,1,base_link,{name}"


def _box() -> trimesh.Trimesh:
    return trimesh.creation.box(extents=(0.05, 0.05, 0.05))


def _bad_meshes() -> dict[str, tuple[bytes, str]]:
    """name -> (STL bytes, words MuJoCo's reason must contain)."""
    good = _box().export(file_type="stl")
    nan = _box().vertices.copy()
    nan[3, 1] = np.nan
    ascii_stl = _box().export(file_type="stl_ascii")
    flat = trimesh.Trimesh([[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0]], [[0, 1, 2], [1, 3, 2]])
    return {
        "empty": (b"", "empty"),
        "truncated": (good[: len(good) // 2 + 7], "wrong size"),
        "ascii": (ascii_stl.encode() if isinstance(ascii_stl, str) else ascii_stl, "ASCII"),
        "nan": (
            trimesh.Trimesh(nan, _box().faces, process=False).export(file_type="stl"),
            "not finite",
        ),
        "flat": (flat.export(file_type="stl"), "coplanar"),
        "too_many_faces": (
            good[:80] + (200_001).to_bytes(4, "little") + good[84:134] * 200_001,
            "200000",
        ),
    }


@pytest.fixture
def arm(tmp_path: Path) -> Path:
    dest = tmp_path / "arm"
    shutil.copytree(BUNDLED_ROBOTS_DIR / "arm6", dest)
    return dest


def _errors(folder: Path) -> list:
    return [p for p in validate_dir(folder) if p.severity == "error"]


@pytest.mark.parametrize("robot", ["arm6", "mini_humanoid"])
def test_bundled_robots_validate_with_the_compile(robot: str) -> None:
    assert _errors(BUNDLED_ROBOTS_DIR / robot) == []


def test_every_hostile_mesh_is_a_located_problem(arm: Path) -> None:
    bad = _bad_meshes()
    rows = [MESH_ROW.format(name="good")] + [MESH_ROW.format(name=n) for n in bad]
    (arm / "mesh.csv").write_text("\n".join([MESH_HEADER, *rows]) + "\n")
    (arm / "meshes").mkdir()
    _box().export(str(arm / "meshes" / "good.stl"), file_type="stl")
    for name, (data, _) in bad.items():
        (arm / "meshes" / f"{name}.stl").write_bytes(data)
    # The table checks alone pass: the files are there, inside the folder.
    assert [p for p in validate_dir(arm, compile_model=False) if p.severity == "error"] == []
    errors = _errors(arm)
    assert [(p.file, p.row, p.column) for p in errors] == [
        ("mesh.csv", i, "name") for i in range(1, len(rows))
    ]
    for p, (name, (_, reason)) in zip(errors, bad.items(), strict=True):
        assert f"meshes/{name}.stl" in p.message and reason in p.message, p.message


def test_valid_mesh_with_scale_compiles(arm: Path) -> None:
    header = MESH_HEADER + ",scale0,scale1,scale2"
    (arm / "mesh.csv").write_text(f"{header}\n{MESH_ROW.format(name='part')},2,2,2\n")
    (arm / "meshes").mkdir()
    _box().export(str(arm / "meshes" / "part.stl"), file_type="stl")
    assert _errors(arm) == []
    model = MJCFHumanoidGenerator.from_hrdf(HRDF.from_dir(arm)).to_model()
    assert model.nmesh == 1
    # the mesh scale reaches MuJoCo: a 0.05 m cube scaled 2x is 0.1 m wide
    np.testing.assert_allclose(np.ptp(model.mesh_vert, axis=0), [0.1, 0.1, 0.1], rtol=1e-6)


def test_negative_mesh_scale_mirrors_and_out_of_range_scales_are_located(arm: Path) -> None:
    header = MESH_HEADER + ",scale0,scale1,scale2"
    (arm / "meshes").mkdir()
    mesh = _box()
    mesh.apply_translation((0.1, 0.2, 0.3))
    mesh.export(str(arm / "meshes" / "part.stl"), file_type="stl")
    (arm / "mesh.csv").write_text(f"{header}\n{MESH_ROW.format(name='part')},1,-2,1\n")
    assert _errors(arm) == []
    model = MJCFHumanoidGenerator.from_hrdf(HRDF.from_dir(arm)).to_model()
    # mirrored on y and stretched: the mesh's centre goes to y = -0.4 in the geom frame
    np.testing.assert_allclose(model.mesh_scale[0], [1, -2, 1])
    assert model.geom_pos[model.geom_dataid.tolist().index(0)][1] < 0
    for bad in ("0,1,1", "1,1,2000000", "1,-1e-9,1"):
        (arm / "mesh.csv").write_text(f"{header}\n{MESH_ROW.format(name='part')},{bad}\n")
        errors = _errors(arm)
        assert [(p.file, p.row, p.column) for p in errors] == [("mesh.csv", 0, "scale0")], bad
        assert "between 1e-06 and 1e+06" in errors[0].message


@pytest.mark.parametrize(
    ("extra", "words"),
    [
        ("<sensor><jointpos name='s' joint='nojoint'/></sensor>", "nojoint"),
        ("<tendon><fixed name='t'><joint joint='nojoint' coef='1'/></fixed></tendon>", "nojoint"),
        ("<contact><exclude body1='base_link' body2='nobody'/></contact>", "nobody"),
        # MuJoCo words the refusal its own way: the error names the element.
        ("<sensor><bogus name='s'/></sensor>", "bogus"),
    ],
)
def test_extra_xml_naming_what_is_not_there_is_located(arm: Path, extra: str, words: str) -> None:
    (arm / "extra.xml").write_text(f"<mujoco>{extra}</mujoco>")
    errors = _errors(arm)
    assert len(errors) == 1
    assert errors[0].file == "extra.xml"
    assert errors[0].element is not None and errors[0].element.startswith("<")
    assert words in f"{errors[0].element} {errors[0].message}"


def test_site_of_size_zero_is_a_table_problem(arm: Path) -> None:
    text = (arm / "site.csv").read_text().splitlines()
    header = text[0].split(",")
    row = text[1].split(",")
    row[header.index("size0")] = "0"
    (arm / "site.csv").write_text("\n".join([text[0], ",".join(row), *text[2:]]) + "\n")
    errors = _errors(arm)
    assert [(p.file, p.row, p.column) for p in errors] == [("site.csv", 0, "size0")]


def test_check_compiles_is_empty_for_a_model_that_compiles() -> None:
    hrdf = HRDF.from_dir(BUNDLED_ROBOTS_DIR / "mini_humanoid")
    assert check_compiles(hrdf) == []


def test_validate_command_reports_the_compile_problem(arm: Path, capsys) -> None:
    (arm / "extra.xml").write_text(
        "<mujoco><sensor><jointpos name='s' joint='x'/></sensor></mujoco>"
    )
    assert main(["validate", str(arm)]) == 1
    out = capsys.readouterr().out
    assert "error: extra.xml: <jointpos" in out
