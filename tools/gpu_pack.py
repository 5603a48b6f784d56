"""Carry benchmarks/gpu_suite.py's packages to a GPU machine that cannot download.

The GPU machine has Python 3.12 with torch, numpy, scipy, tensorboard, onnx and the like,
but no MuJoCo, warp or mjlab, and no network; one call carries at most 64 MiB together
with the working tree, and a machine left idle for 30 s is given back, so the calls must
be few and follow each other at once. Here (with network):

    python tools/gpu_pack.py pack .gpu

downloads the x86-64 CPython 3.12 wheels of the mjlab environment, unpacks those the
machine lacks into one folder, leaves out what the suite never loads (warp's CPU
compiler, wandb's and imageio-ffmpeg's programs), adds the Go2 of example-robot-data and
robotwright's entry points (mjlab finds the tasks through them), compresses the whole
with xz and cuts it into ``.gpu/call-K`` folders, each small enough for one call beside
this working tree (about 119 MB in three calls; packing takes about 11 minutes on 2
cores). ``.gpu/calls.txt`` lists the calls: each carries its folder and copies it to
``/tmp/gpu`` (the machine keeps ``/tmp`` while it is warm); the last then runs, there,

    python3 tools/gpu_pack.py unpack /tmp/gpu /tmp/site
    python3 tools/gpu_pack.py run /tmp/site -- --envs 4096 --out $OUT/gpu_suite.json

``unpack`` joins the pieces, checks the archive's SHA-256 and unpacks it; ``run`` starts
the suite with that folder on ``PYTHONPATH`` and the settings it needs there
(:func:`suite_env`).
"""

from __future__ import annotations

import argparse
import hashlib
import io
import json
import os
import re
import shutil
import subprocess
import sys
import tarfile
import tempfile
import zipfile
from pathlib import Path, PurePosixPath

import tomllib

ROOT = Path(__file__).resolve().parents[1]
#: What the mjlab sections of the suite need (the versions CI's 3.11 stage pins).
REQUIREMENTS = ("mjlab==1.6.0", "mujoco==3.11.0", "mujoco-warp==3.11.0", "trimesh", "pyyaml")
REQUIREMENTS += ("defusedxml", "pycollada", "viser", "matplotlib", "example-robot-data")
#: Distributions the GPU machine's image holds (its torch, and what came with it).
_PRESENT_NAMES = """absl-py annotated-doc anyio attrs certifi charset-normalizer click cloudpickle
    contourpy cuda-bindings cuda-pathfinder cycler etils filelock fonttools fsspec grpcio
    h11 httpcore httpx idna imageio jinja2 kiwisolver markdown markdown-it-py markupsafe
    matplotlib mdurl ml-dtypes mpmath networkx numpy onnx onnx-ir onnxscript packaging
    pillow protobuf psutil pygments python-dateutil pyyaml requests rich scipy setuptools
    six sympy tensorboard tensorboard-data-server torch torchvision tqdm triton
    typing-extensions urllib3 werkzeug wrapt xxhash zipp"""
PRESENT = frozenset(_PRESENT_NAMES.split())
#: Distributions the suite never loads (IPython's completion; torchrunx's multi-GPU
#: launch and its SSH stack).
_NEVER_LOADED_NAMES = "jedi parso torchrunx fabric paramiko invoke cryptography pynacl bcrypt"
NEVER_LOADED = frozenset(_NEVER_LOADED_NAMES.split())
#: Paths inside the site the suite never loads: warp's CPU compiler (kernels run on the
#: GPU), wandb's and imageio-ffmpeg's programs, MuJoCo's native viewer, examples.
LEFT_OUT = (
    "warp/bin/warp-clang.so",
    "warp/examples/",
    "wandb/bin/",
    "imageio_ffmpeg/binaries/",
    "mujoco/experimental/studio/",
)
#: Of these distributions only the files under these prefixes are kept.
KEEP_ONLY = {
    "example-robot-data": ("cmeel.prefix/share/example-robot-data/robots/go2_description/",),
}
PLATFORMS = ("manylinux_2_28_x86_64", "manylinux_2_27_x86_64", "manylinux_2_17_x86_64")
PLATFORMS += ("manylinux2014_x86_64", "manylinux_2_34_x86_64", "manylinux_2_31_x86_64")
PLATFORMS += ("manylinux_2_24_x86_64", "manylinux1_x86_64")
#: What one call may carry [bytes], and what is kept free of it for the working tree's
#: growth between packing and the calls.
CALL_LIMIT = 64 * 2**20
MARGIN = 2 * 2**20
ARCHIVE = "site.tar.xz"


def normalize(name: str) -> str:
    """A distribution's name as registries compare it (``Foo_Bar`` -> ``foo-bar``)."""
    return re.sub(r"[-_.]+", "-", name).lower()


def distribution(wheel_name: str) -> str:
    """The normalized distribution name of a wheel file (``Foo_Bar-1.0-...`` -> ``foo-bar``)."""
    return normalize(wheel_name.split("-", 1)[0])


def _site_path(member: str, data_dir: str) -> str | None:
    """Where a wheel member goes in the site folder, or ``None`` when it is not kept
    (scripts, headers, data of ``.data/``, byte code)."""
    if member.endswith("/") or "/__pycache__/" in f"/{member}":
        return None
    if member.startswith(data_dir + "/"):
        scheme, _, rest = member[len(data_dir) + 1 :].partition("/")
        return rest if scheme in ("purelib", "platlib") and rest else None
    return member


def unpack_wheel(wheel: Path, site: Path) -> int:
    """Unpack ``wheel`` into ``site`` as pip would place its library files, less
    :data:`LEFT_OUT` and, for :data:`KEEP_ONLY`'s distributions, all but the prefixes
    named; returns the number of files written.

    Raises:
        SystemExit: a member's path leaves the site folder.
    """
    dist = distribution(wheel.name)
    keep = KEEP_ONLY.get(dist)
    data_dir = "-".join(wheel.name.split("-", 2)[:2]) + ".data"
    written = 0
    with zipfile.ZipFile(wheel) as archive:
        for info in archive.infolist():
            path = _site_path(info.filename, data_dir)
            if path is None or path.startswith(LEFT_OUT):
                continue
            if keep is not None and not path.startswith(keep) and ".dist-info/" not in path:
                continue
            pure = PurePosixPath(path)
            if pure.is_absolute() or ".." in pure.parts:
                raise SystemExit(f"{wheel.name}: member {info.filename!r} leaves the folder")
            target = site.joinpath(*pure.parts)
            target.parent.mkdir(parents=True, exist_ok=True)
            target.write_bytes(archive.read(info))
            if info.external_attr >> 16 & 0o111:
                target.chmod(0o755)
            written += 1
    return written


def write_entry_points(site: Path, pyproject: Path = ROOT / "pyproject.toml") -> Path:
    """A ``robotwright-<version>.dist-info`` in ``site`` with the entry points
    ``pyproject`` declares, so that mjlab finds robotwright's tasks while robotwright
    itself is imported from ``src/``; returns the folder."""
    project = tomllib.loads(pyproject.read_text())["project"]
    info = site / f"{project['name']}-{project['version']}.dist-info"
    info.mkdir(parents=True, exist_ok=True)
    meta = f"Metadata-Version: 2.1\nName: {project['name']}\nVersion: {project['version']}\n"
    (info / "METADATA").write_text(meta)
    groups = dict(project.get("entry-points", {}))
    for table, group in (("scripts", "console_scripts"), ("gui-scripts", "gui_scripts")):
        if table in project:
            groups[group] = project[table]
    lines = [
        f"[{g}]\n" + "".join(f"{k} = {v}\n" for k, v in eps.items()) for g, eps in groups.items()
    ]
    (info / "entry_points.txt").write_text("\n".join(lines))
    return info


def tree_size(root: Path = ROOT) -> int:
    """Bytes of what a device call sends of the checkout: tracked files and untracked
    ones git does not ignore."""
    listed = subprocess.run(
        ["git", "ls-files", "-z", "--cached", "--others", "--exclude-standard"],
        cwd=root,
        capture_output=True,
        check=True,
    ).stdout.split(b"\0")
    paths = (root / os.fsdecode(p) for p in listed if p)
    return sum(p.stat().st_size for p in paths if p.is_file())


def _xz_tar(folder: Path) -> bytes:
    """``folder`` as a tar archive compressed with xz: by the ``xz`` program on every core
    where there is one (Python's own xz runs on one core: several minutes for the
    500 MB the suite needs), else by Python."""
    size = sum(p.stat().st_size for p in folder.rglob("*") if p.is_file())
    print(f"compressing {size / 1e6:.0f} MB with xz (minutes) ...", flush=True)
    program = shutil.which("xz")
    if program is None:
        buffer = io.BytesIO()
        with tarfile.open(fileobj=buffer, mode="w:xz", preset=6) as tar:
            tar.add(folder, arcname=".")
        return buffer.getvalue()
    with tempfile.TemporaryFile() as plain:
        with tarfile.open(fileobj=plain, mode="w") as tar:
            tar.add(folder, arcname=".")
        plain.seek(0)
        return subprocess.run(
            [program, "-6", "-T0", "-c"], stdin=plain, capture_output=True, check=True
        ).stdout


def archive_and_cut(site: Path, out: Path, capacity: int) -> list[Path]:
    """Compress ``site`` (tar, xz) and cut it into ``out/call-K`` folders of at most
    ``capacity`` bytes; the last also holds ``manifest.json`` (size and SHA-256 of the
    whole archive). Returns the call folders in order."""
    if capacity <= 0:
        raise SystemExit("the working tree alone fills a device call: nothing can be carried")
    data = _xz_tar(site)
    for stale in out.glob("call-*"):  # an earlier packing's calls
        shutil.rmtree(stale)
    calls = []
    for k, start in enumerate(range(0, len(data), capacity), start=1):
        folder = out / f"call-{k}"
        folder.mkdir(parents=True, exist_ok=True)
        (folder / f"{ARCHIVE}.part{k:02d}").write_bytes(data[start : start + capacity])
        calls.append(folder)
    manifest = {"archive": ARCHIVE, "size": len(data), "sha256": hashlib.sha256(data).hexdigest()}
    (calls[-1] / "manifest.json").write_text(json.dumps(manifest))
    return calls


def unpack(gathered: Path, site: Path) -> None:
    """Join the pieces gathered in one folder, check them against the manifest and
    unpack the archive into ``site``.

    Raises:
        SystemExit: a piece is missing or damaged.
    """
    manifest = json.loads((gathered / "manifest.json").read_text())
    parts = sorted(gathered.glob(f"{manifest['archive']}.part*"))
    data = b"".join(p.read_bytes() for p in parts)
    if len(data) != manifest["size"] or hashlib.sha256(data).hexdigest() != manifest["sha256"]:
        raise SystemExit(f"unpack: {len(parts)} pieces found, missing or damaged")
    site.mkdir(parents=True, exist_ok=True)
    with tarfile.open(fileobj=io.BytesIO(data), mode="r:xz") as tar:
        tar.extractall(site, filter="data")


def suite_env(site: Path, base: dict[str, str] | None = None) -> dict[str, str]:
    """The environment the suite runs in on the GPU machine: robotwright from ``src/``
    and the carried packages first on the path; MuJoCo's OpenGL off (mjlab asks for EGL,
    which the machine's image lacks); imageio-ffmpeg pointed at a program since its own
    was left out (the suite writes no video); the Go2 found under ``cmeel.prefix``."""
    env = dict(os.environ if base is None else base)
    env["PYTHONPATH"] = os.pathsep.join([str(ROOT / "src"), str(site)])
    env["MUJOCO_GL"] = "disable"
    env["IMAGEIO_FFMPEG_EXE"] = "/bin/false"
    env["AMENT_PREFIX_PATH"] = str(site / "cmeel.prefix")
    env["PYTHONUNBUFFERED"] = "1"
    return env


def _carried(dist: str) -> bool:
    return dist not in PRESENT and dist not in NEVER_LOADED and not dist.startswith("nvidia-")


def pack(out: Path) -> list[Path]:
    """Resolve, download, unpack, prune and cut (the module docstring); returns the call
    folders. Only the wheels carried are downloaded into ``out`` (resolving may fetch
    torch into pip's cache to read its requirements; it is not kept)."""
    wheels, site = out / "wheels", out / "site"
    out.mkdir(parents=True, exist_ok=True)
    target = ["--only-binary=:all:", "--python-version", "3.12", "--implementation", "cp"]
    target += [arg for p in PLATFORMS for arg in ("--platform", p)]
    pip = [sys.executable, "-m", "pip"]
    report = out / "resolved.json"
    resolve = [*pip, "install", "--dry-run", "--ignore-installed", "--report", str(report)]
    resolve += ["--target", str(out / "unused"), *target, *REQUIREMENTS]
    subprocess.run(resolve, check=True)
    pins = [
        f"{item['metadata']['name']}=={item['metadata']['version']}"
        for item in json.loads(report.read_text())["install"]
        if _carried(normalize(item["metadata"]["name"]))
    ]
    subprocess.run(
        [*pip, "download", "--no-deps", "--dest", str(wheels), *target, *pins], check=True
    )
    for wheel in sorted(wheels.glob("*.whl")):  # only the carried ones were downloaded
        print(f"{unpack_wheel(wheel, site):6d} files  {wheel.name}")
    write_entry_points(site)
    calls = archive_and_cut(site, out, CALL_LIMIT - tree_size() - MARGIN)
    for folder in (wheels, site, out / "unused"):  # 900 MB of intermediates
        shutil.rmtree(folder, ignore_errors=True)
    lines = []
    for k, call in enumerate(calls, start=1):
        rel = os.path.relpath(call, ROOT)
        lines.append(f"call {k}: carry {rel}; run: mkdir -p /tmp/gpu && cp {rel}/* /tmp/gpu/")
    lines.append(
        "and in the last call after it: python3 tools/gpu_pack.py unpack /tmp/gpu /tmp/site && "
        "python3 tools/gpu_pack.py run /tmp/site -- --envs 4096 --out $OUT/gpu_suite.json"
    )
    (out / "calls.txt").write_text("\n".join(lines) + "\n")
    print((out / "calls.txt").read_text(), end="")
    return calls


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    sub = ap.add_subparsers(dest="action", required=True)
    sub.add_parser("pack", help="here: download and cut into call folders").add_argument(
        "folder", type=Path
    )
    p = sub.add_parser("unpack", help="there: join the gathered pieces and unpack them")
    p.add_argument("gathered", type=Path)
    p.add_argument("site", type=Path)
    p = sub.add_parser("run", help="there: the suite with the unpacked packages")
    p.add_argument("site", type=Path)
    p.add_argument("suite_args", nargs=argparse.REMAINDER)
    args = ap.parse_args(argv)
    if args.action == "pack":
        pack(args.folder.resolve())
    elif args.action == "unpack":
        unpack(args.gathered, args.site)
    else:
        suite = [a for a in args.suite_args if a != "--"]
        cmd = [sys.executable, str(ROOT / "benchmarks" / "gpu_suite.py"), *suite]
        return subprocess.run(cmd, env=suite_env(args.site.resolve())).returncode
    return 0


if __name__ == "__main__":
    sys.exit(main())
