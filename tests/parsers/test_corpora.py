"""Every robot file of four public corpora that MuJoCo compiles on its own round-trips
exactly through HRDF, or is an expected failure whose reason names a fault of the source.

Corpora (unpacked as data by tools/fetch_test_data.py): robosuite-models and robosuite
(MJCF robots, grippers, bases, arenas, objects; robosuite's pybullet URDFs),
gymnasium's MuJoCo assets, and pybullet_data (URDFs and old MJCFs, without its 1,000
generated ``random_urdfs``). Each file is compiled by MuJoCo first: a file MuJoCo itself
refuses is out of scope and skipped with MuJoCo's reason. The rest goes through
:func:`robotwright.proof.roundtrip.run.roundtrip` (our MJCF to 1e-9: masses, inertias,
joints, 20 random configurations, actuators with gear/ctrlrange, tendons, equalities,
sensors, keyframes; our URDF to 1e-6) plus a check of every body's mass, centre of mass
and inertia tensor, massless bodies included, and the proof ``robotwright convert`` runs
(:func:`robotwright.proof.compare.prove`: no compiled field differs unless a note says
so), all on one parse of the file. A world holding several top-level bodies
(an arm and its target) is converted with the largest one as the robot.

The counts per corpus are in docs/parsers.md and the README.
"""

from __future__ import annotations

from pathlib import Path

import mujoco
import numpy as np
import pytest

from robotwright.parsers.reference import compile_urdf, urdf_for_mujoco
from robotwright.proof.compare import prove
from robotwright.proof.roundtrip.run import roundtrip

pytestmark = [pytest.mark.realdata, pytest.mark.usefixtures("quiet_parsers")]


TESTDATA = Path(__file__).resolve().parents[2] / ".testdata"
#: corpus -> folder holding its files (paths in the ids are relative to it).
CORPORA = {
    "robosuite-models": TESTDATA / "robosuite-models" / "robosuite_models" / "assets",
    "robosuite": TESTDATA / "robosuite" / "robosuite" / "models" / "assets",
    "gymnasium": TESTDATA / "gymnasium" / "gymnasium" / "envs" / "mujoco" / "assets",
    "pybullet": TESTDATA / "pybullet" / "pybullet_data",
}
CONFIGS = 20

#: "corpus/relative path" -> the fault of the source that keeps it from round-tripping.
EXPECTED_FAILURES: dict[str, str] = {
    "pybullet/differential/diff_ring.urdf": "mesh paths are relative to pybullet_data (its "
    "search path), not to the URDF's folder: differential/differential/*.stl do not exist",
}


def _files(corpus: str) -> list[Path]:
    root = CORPORA[corpus]
    return sorted(p for p in root.rglob("*") if p.suffix in (".xml", ".urdf") and p.is_file())


def _params() -> list:
    out = []
    for corpus, root in CORPORA.items():
        if not root.is_dir():
            out.append(
                pytest.param(
                    corpus,
                    None,
                    marks=pytest.mark.skip(
                        reason=f"{corpus} corpus absent (python tools/fetch_test_data.py): {root}"
                    ),
                    id=corpus,
                )
            )
            continue
        for path in _files(corpus):
            key = f"{corpus}/{path.relative_to(root).as_posix()}"
            marks = []
            if key in EXPECTED_FAILURES:
                marks.append(pytest.mark.xfail(reason=EXPECTED_FAILURES[key], strict=True))
            out.append(pytest.param(corpus, path.relative_to(root).as_posix(), marks=marks, id=key))
    return out


def _source_model(path: Path) -> mujoco.MjModel:
    """The source as MuJoCo compiles it on its own; skips when MuJoCo refuses it."""
    try:
        if path.suffix == ".urdf":
            return compile_urdf(urdf_for_mujoco(path))
        return mujoco.MjModel.from_xml_path(str(path))
    except Exception as exc:  # noqa: BLE001 - any refusal puts the file out of scope
        pytest.skip(f"MuJoCo does not compile the source: {str(exc).splitlines()[0][:160]}")


def _robot_root(model: mujoco.MjModel) -> str | None:
    """The top-level body with the largest subtree when the world holds several."""
    top = [i for i in range(1, model.nbody) if model.body_parentid[i] == 0]
    if len(top) < 2:
        return None
    size = {i: int(np.sum(model.body_rootid == i)) for i in top}
    return model.body(max(top, key=lambda i: (size[i], -i))).name


@pytest.mark.corpus
@pytest.mark.parametrize(("corpus", "rel"), _params())
def test_corpus_file_roundtrips(
    corpus: str, rel: str, tmp_path: Path, body_differences, layout_package
) -> None:
    root = CORPORA[corpus]
    path = root / rel
    source = _source_model(path)
    if source.nbody < 2:
        pytest.skip("the file holds no body: nothing to convert")
    options: dict = {"asset_roots": (root,)}
    if layout_package(path):
        options["package_map"] = layout_package(path)
    robot = _robot_root(source) if path.suffix == ".xml" else None
    if robot is not None:
        options["root_body"] = robot
    work = tmp_path / "parse"  # the parse's staged meshes stay for the proof
    report = roundtrip(path, configs=CONFIGS, reference="mujoco", work_dir=work, **options)
    assert report.ok, report.table()
    assert report.parse is not None and report.mjcf_model is not None
    bad = body_differences(source, report.mjcf_model, robot)
    assert not bad, bad
    # The proof of the conversion (what `robotwright convert` runs): no difference in any
    # compared MjModel field that no note reports, on the same parse.
    kind = "urdf" if path.suffix == ".urdf" else "mjcf"
    found = prove(path, kind, report.parse.hrdf, "hrdf", report.warnings, options=options)
    assert not found, [str(p) for p in found]


def test_expected_failures_exist() -> None:
    missing = []
    for key in EXPECTED_FAILURES:
        corpus, rel = key.split("/", 1)
        if CORPORA[corpus].is_dir() and not (CORPORA[corpus] / rel).is_file():
            missing.append(key)
    assert not missing
