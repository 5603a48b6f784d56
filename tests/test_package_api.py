"""``import robotwright`` gives every subpackage as an attribute, imported on first use."""

from __future__ import annotations

import os
import subprocess
import sys

import pytest

_HEAVY = ("mujoco", "numpy", "trimesh", "viser", "PIL")


def _run(code: str) -> subprocess.CompletedProcess:
    """``code`` in a fresh interpreter without MUJOCO_GL: where it is set, import
    robotwright imports MuJoCo at once, by design (robotwright._mujoco_gl); importing
    mjlab, as other tests do, sets it to egl in this process."""
    env = {k: v for k, v in os.environ.items() if k != "MUJOCO_GL"}
    return subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, timeout=300, env=env
    )


def test_import_robotwright_imports_no_heavy_dependency() -> None:
    done = _run(
        f"import sys, robotwright\nprint(sorted(m for m in {_HEAVY!r} if m in sys.modules))"
    )
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == "[]"


@pytest.mark.parametrize(
    ("attribute", "function"),
    [("view", "show"), ("render", "render"), ("hrdf", "HRDF"), ("sensors", "LidarSensor")],
)
def test_subpackages_are_attributes_after_import(attribute: str, function: str) -> None:
    """``robotwright.view.show(...)`` and ``robotwright.render.render(...)``, as the
    README writes them, work after a plain ``import robotwright``."""
    done = _run(
        "import robotwright\n"
        f"f = getattr(robotwright.{attribute}, {function!r})\n"
        "print(callable(f))"
    )
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == "True"


def test_render_after_import_draws_a_picture(tmp_path) -> None:
    out = tmp_path / "arm.png"
    done = _run(f"import robotwright\nrobotwright.render.render('arm6', {str(out)!r})")
    assert done.returncode == 0, done.stderr
    assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_unknown_attribute_is_an_attribute_error() -> None:
    import robotwright

    with pytest.raises(AttributeError):
        robotwright.no_such_part  # noqa: B018
    assert hasattr(robotwright, "view") and "view" in dir(robotwright)


def test_the_readers_face_keeps_the_proofs_old_names_without_importing_them() -> None:
    """``robotwright.parsers.convert``, ``.prove`` and ``.roundtrip`` (names of the proof
    layer since it left the readers) are the proof's own functions; importing the
    readers' package imports neither the proof nor a writer."""
    done = _run(
        "import sys\n"
        "import robotwright.parsers as readers\n"
        "before = sorted(m for m in sys.modules if m.startswith(('robotwright.proof',"
        " 'robotwright.generators')))\n"
        "import robotwright.proof as proof\n"
        "same = [getattr(readers, n) is getattr(proof, n) and callable(getattr(proof, n))"
        " for n in ('convert', 'prove', 'roundtrip')]\n"
        "print(before, same)"
    )
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == "[] [True, True, True]"


@pytest.mark.parametrize(
    ("module", "names"),
    [
        ("robotwright.parsers.mjcf", ("MJCFOptions", "parse_mjcf", "parse_mjcf_spec")),
        ("robotwright.parsers.urdf", ("URDFOptions", "parse_urdf")),
        ("robotwright.parsers.xacro", ("expand_xacro", "is_xacro", "xacro_as_urdf")),
        ("robotwright.parsers.usd", ("USDOptions", "parse_usd", "prepare_confined_read")),
        ("robotwright.proof.roundtrip", ("RoundTripReport", "our_mjcf_model", "roundtrip")),
    ],
)
def test_each_format_package_names_its_entry_points(module: str, names: tuple) -> None:
    """``from robotwright.parsers.mjcf import parse_mjcf`` (the import path of the
    modules these packages replaced) works through each package's face."""
    import importlib

    package = importlib.import_module(module)
    assert set(names) <= set(package.__all__)
    assert all(callable(getattr(package, n)) for n in names)
