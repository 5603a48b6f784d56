"""Fuzzed HRDF folders (issue 11): a fixed seed and a time budget, so CI runs the same
cases in the same order (fewer on a slow machine).

Each case copies a valid robot and applies one to three random mutations: a CSV cell
replaced by a hostile value (markup, paths, NaN, huge numbers, long text), a
``meta.yaml`` value replaced by a value of another type, a file truncated or replaced by
random bytes, a file replaced by a symbolic link out of the folder, a hostile mesh file
(empty, truncated, ASCII, random bytes, a NaN vertex, flat, too many faces) or a hostile
``extra.xml`` (unknown names, a keyframe of the wrong size, entities, a wrong root).
Whatever the input:

- ``validate_dir`` returns its problems, ``HRDF.from_dir`` raises only ``HRDFError``;
- a folder that validates loads, exports to MJCF and URDF, and its MJCF compiles in
  MuJoCo;
- a robot that loads has every mesh inside its folder;
- the MJCF and URDF generators and ``save`` raise only robotwright errors, and a failed
  ``save`` leaves nothing behind.
"""

from __future__ import annotations

import csv
import io
import random
import shutil
import time
import warnings
from pathlib import Path

import numpy as np
import pytest
import trimesh
import yaml

from robotwright.errors import HRDFError, RobotwrightError
from robotwright.generators import MJCFHumanoidGenerator, URDFHumanoidGenerator
from robotwright.generators.compiles import validate_dir
from robotwright.hrdf import HRDF
from robotwright.hrdf.assets import BUNDLED_ROBOTS_DIR

SEED = 20_240_611
MAX_CASES = 400
BUDGET_S = 8.0

CELLS = [
    "", "nan", "inf", "-inf", "-1", "0", "1e400", "1e-320", "abc", "x" * 300, "é",
    '<body name="INJECTED"/>', 'gyro site="a"/><x', "../../outside/secret", "/etc/passwd",
    "meshes/../../outside/secret.stl", "1,2", '"', "true", "999999999999999999999",
    "site", "body", "joint", "framepos", "hinge", "box", "0.5", "1", "2", "0.001",
]  # fmt: skip
META_VALUES = ["abc", [1], {"a": 1}, None, True, -1, 1e308, "", [[[]]], 0, "plane", "RK4"]
EXTRAS = [
    "<mujoco><contact><exclude body1='base_link' body2='nobody'/></contact></mujoco>",
    "<mujoco><keyframe><key name='k' qpos='0 0'/></keyframe></mujoco>",
    "<mujoco><equality><joint joint1='shoulder_pan_joint' joint2='nojoint'/></equality></mujoco>",
    "<mujoco><tendon><fixed name='t'><joint joint='nojoint' coef='1'/></fixed></tendon></mujoco>",
    "<mujoco><sensor><jointpos name='s' joint='nojoint'/></sensor></mujoco>",
    "<mujoco><sensor><bogus name='s'/></sensor></mujoco>",
    '<!DOCTYPE m [<!ENTITY e "x">]><mujoco><keyframe><key name="&e;"/></keyframe></mujoco>',
    "<robot><link name='a'/></robot>",
    "<mujoco><keyframe><key name='k' time='nan'/></keyframe></mujoco>",
    "<mujoco><contact><pair geom1='x' geom2='y'/></contact></mujoco>",
    "<mujoco><actuator><motor joint='shoulder_pan_joint' gear='1e400'/></actuator></mujoco>",
]


def _hostile_meshes() -> list[bytes]:
    box = trimesh.creation.box(extents=(0.05, 0.05, 0.05))
    good = box.export(file_type="stl")
    nan = box.vertices.copy()
    nan[0, 0] = np.nan
    flat = trimesh.Trimesh([[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0]], [[0, 1, 2], [1, 3, 2]])
    ascii_stl = box.export(file_type="stl_ascii")
    return [
        b"",
        good[: len(good) // 2],
        ascii_stl.encode() if isinstance(ascii_stl, str) else ascii_stl,
        trimesh.Trimesh(nan, box.faces, process=False).export(file_type="stl"),
        flat.export(file_type="stl"),
        trimesh.Trimesh(np.zeros((3, 3)), [[0, 1, 2]], process=False).export(file_type="stl"),
        # a header that announces 200,001 faces (MuJoCo's limit is 200,000), data to match
        good[:80] + (200_001).to_bytes(4, "little") + good[84:134] * 200_001,
    ]


HOSTILE_MESHES = _hostile_meshes()
MESH_HEADER = (
    "contact_type,contact_affinity,static_friction,dynamic_friction,restitution,"
    "pos0,pos1,pos2,quat0,quat1,quat2,quat3,rgba0,rgba1,rgba2,rgba3,body_name,name,file"
)


@pytest.fixture(scope="module")
def sources(tmp_path_factory) -> list[Path]:
    """mini_humanoid, and arm6 with a mesh row (``file`` column) and a secret outside."""
    root = tmp_path_factory.mktemp("fuzz_sources")
    arm = root / "arm"
    shutil.copytree(BUNDLED_ROBOTS_DIR / "arm6", arm)
    (arm / "meshes").mkdir()
    box = trimesh.creation.box(extents=(0.05, 0.05, 0.05))
    box.export(str(arm / "meshes" / "part.stl"), file_type="stl")
    (root / "outside").mkdir()
    box.export(str(root / "outside" / "secret.stl"), file_type="stl")
    row = "1,1,1.0,1.0,,0,0,0,1,0,0,0,0.5,0.5,0.5,1,base_link,part,meshes/part.stl"
    (arm / "mesh.csv").write_text(f"{MESH_HEADER}\n{row}\n")
    return [BUNDLED_ROBOTS_DIR / "mini_humanoid", arm]


def _mutate(folder: Path, rng: random.Random) -> str:
    pick = rng.random()
    if pick < 0.08:
        (folder / "extra.xml").write_text(text := rng.choice(EXTRAS))
        return f"extra.xml = {text!r}"
    mesh = folder / "meshes" / "part.stl"
    if pick < 0.16 and mesh.is_file() and not mesh.is_symlink():
        data = rng.choice(HOSTILE_MESHES)
        mesh.write_bytes(data)
        return f"meshes/part.stl = hostile mesh of {len(data)} bytes"
    files = sorted(p for p in folder.iterdir() if p.is_file())
    target = rng.choice(files)
    roll = rng.random()
    text = target.read_text(errors="replace")
    if target.suffix == ".csv" and roll < 0.7:
        rows = list(csv.reader(io.StringIO(text)))
        r = rng.randrange(1, len(rows)) if len(rows) > 1 else 0
        if not rows[r]:
            return "empty row kept"
        c = rng.randrange(len(rows[r]))
        rows[r][c] = rng.choice(CELLS)
        out = io.StringIO()
        csv.writer(out, lineterminator="\n").writerows(rows)
        target.write_text(out.getvalue())
        return f"{target.name} row {r} column {c} = {rows[r][c]!r}"
    if target.name == "meta.yaml" and roll < 0.8:
        try:
            meta = yaml.safe_load(text)
        except yaml.YAMLError:
            return "meta kept"
        paths: list[list] = []

        def walk(node, path) -> None:
            items = node.items() if isinstance(node, dict) else enumerate(node)
            for k, v in items:
                paths.append([*path, k])
                if isinstance(v, (dict, list)):
                    walk(v, [*path, k])

        if not isinstance(meta, (dict, list)):
            return "meta kept"
        walk(meta, [])
        if not paths:
            return "meta kept"
        path, value = rng.choice(paths), rng.choice(META_VALUES)
        node = meta
        for k in path[:-1]:
            node = node[k]
        node[path[-1]] = value
        target.write_text(yaml.safe_dump(meta))
        return f"meta.yaml {path} = {value!r}"
    data = target.read_bytes()
    if roll < 0.85:
        cut = rng.randrange(len(data) + 1)
        target.write_bytes(data[:cut])
        return f"{target.name} truncated at {cut}"
    if roll < 0.95:
        target.write_bytes(bytes(rng.randrange(256) for _ in range(rng.randrange(1, 200))))
        return f"{target.name} random bytes"
    target.unlink()
    target.symlink_to(folder.parent / "outside" / "secret.stl")
    return f"{target.name} is a link out"


def _check_case(folder: Path, out: Path) -> None:
    problems = validate_dir(folder)  # returns problems, raises nothing
    valid = not any(p.severity == "error" for p in problems)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # HRDF and conversion warnings are fine here
        try:
            hrdf = HRDF.from_dir(folder)
        except HRDFError:
            assert not valid, "validate found no error, loading refused the folder"
            return
        if valid:  # validates => exports and compiles
            model = MJCFHumanoidGenerator.from_hrdf(hrdf).to_model()
            assert model.nbody == len(hrdf.bodies) + 1
            assert URDFHumanoidGenerator.from_hrdf(hrdf).generate() is not None
        inside = folder.resolve()
        assert all(hrdf.mesh_source(m).is_relative_to(inside) for m in hrdf.meshes)
        for gen in (MJCFHumanoidGenerator, URDFHumanoidGenerator):
            try:
                g = gen.from_hrdf(hrdf)
                g.generate()
                assert g.xml_str
            except RobotwrightError:
                pass
        try:
            hrdf.save(out)
        except RobotwrightError:
            assert not out.exists()


def test_fuzzed_folders_fail_cleanly(sources, tmp_path) -> None:
    rng = random.Random(SEED)
    start = time.monotonic()
    cases = 0
    while cases < MAX_CASES and time.monotonic() - start < BUDGET_S:
        case = tmp_path / f"case{cases}"
        folder = case / "robot"
        shutil.copytree(rng.choice(sources), folder)
        shutil.copytree(sources[1].parent / "outside", case / "outside")
        what = [_mutate(folder, rng) for _ in range(rng.choice((1, 1, 1, 2, 3)))]
        try:
            _check_case(folder, case / "saved")
        except Exception as exc:  # report the mutation that broke it
            raise AssertionError(f"case {cases} (seed {SEED}): {what}: {exc!r}") from exc
        shutil.rmtree(case)
        cases += 1
    assert cases >= 50, f"only {cases} cases in the {BUDGET_S} s budget"
