"""One size cap on every asset file a model reads, and the overwrite rule on every file an
output copies (issue 19, items 3 and 4).

MuJoCo reads the mesh, height field and texture files a model names itself, with no size
limit, and allocates what a model declares. Every reader checks each such file (``stat``;
a PNG's 24-byte header) and the sizes a model declares (``<hfield nrow ncol>``, built-in
textures) against ``--max-mesh-mb`` (512 MB by default) before MuJoCo reads anything: the
refusal is one ``error:`` line naming the file, its size, the limit and the flag, exit 2,
nothing written. The files here are sparse (``os.truncate``): they cost no disk, and are
no valid mesh, so a message of MuJoCo's would mean the cap let them through.

Files copied next to a model file (``meshes/<robot>/``, ``assets/``) replace a file of the
same name only with ``--overwrite``; a file already holding the same bytes is not refused.
"""

from __future__ import annotations

import os
import random
import shutil
import struct
import subprocess
import sys
import zlib
from pathlib import Path

import pytest
import trimesh

from robotwright import mesh_size_limit
from robotwright._assets import check_asset_file
from robotwright.cli import main
from robotwright.errors import InputFileError, RobotwrightError
from robotwright.hrdf.assets import BUNDLED_ROBOTS_DIR

pytestmark = pytest.mark.filterwarnings("ignore::robotwright.errors.ConversionWarning")

MESH_HEADER = (
    "contact_type,contact_affinity,static_friction,dynamic_friction,restitution,"
    "pos0,pos1,pos2,quat0,quat1,quat2,quat3,rgba0,rgba1,rgba2,rgba3,body_name,name"
)
MESH_ROW = "1,1,1.0,1.0,,0,0,0,1,0,0,0,0.5,0.5,0.5,1,base_link,a"
#: A cap small enough that test files stay tiny: 1 MB (10**6 bytes).
CAP = ["--max-mesh-mb", "1"]
OVER = 3 * 10**6  # bytes of a sparse file over CAP


def snapshot(root: Path) -> dict[str, object]:
    """Everything under ``root``: links read, never followed; sizes of sparse files (their
    bytes are all zero), bytes of the others."""
    found: dict[str, object] = {}
    for dirpath, dirs, files in os.walk(root, followlinks=False):
        for name in dirs + files:
            p = Path(dirpath, name)
            rel = str(p.relative_to(root))
            if p.is_symlink():
                found[rel] = ("link", os.readlink(p))
            elif p.is_dir():
                found[rel] = ("dir",)
            elif p.stat().st_size > 10**6:
                found[rel] = ("big", p.stat().st_size)
            elif p.is_file():
                found[rel] = ("file", p.read_bytes())
            else:
                found[rel] = ("other", p.stat().st_mode)
    return found


def _run(argv: list[str], capsys) -> tuple[int, str]:
    capsys.readouterr()
    code = main(argv)
    err = capsys.readouterr().err
    assert "Traceback" not in err
    return code, err


def _refused_for_size(argv: list[str], capsys, root: Path, asset: Path) -> str:
    """``argv`` exits 2 with an error naming ``asset``, the limit and the flag (not
    MuJoCo's words), and nothing under ``root`` changed."""
    before = snapshot(root)
    code, err = _run(argv, capsys)
    assert code == 2, (argv, err)
    assert err.startswith("error: "), err
    _names_the_cap(err, asset)
    assert snapshot(root) == before, argv
    return err


def _names_the_cap(message: str, asset: Path | None, limit: str = "1 MB") -> None:
    if asset is not None:
        assert str(asset) in message, message
    assert f"larger than the {limit} limit" in message or f"more than the {limit} limit" in message
    assert "--max-mesh-mb" in message, message
    assert "MuJoCo" not in message and "not a mesh" not in message, message


def _sparse(path: Path, size: int = OVER) -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_bytes(b"")
    os.truncate(path, size)
    return path


def _obj(path: Path, size: int | None = None) -> Path:
    """A valid OBJ tetrahedron, padded with a comment to exactly ``size`` bytes."""
    text = "v 0 0 0\nv 0.1 0 0\nv 0 0.1 0\nv 0 0 0.1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n"
    if size is not None:
        pad = size - len(text) - 3
        assert pad >= 0
        text += "# " + "x" * pad + "\n"
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(text, encoding="ascii")
    if size is not None:
        assert path.stat().st_size == size
    return path


def _png(path: Path, width: int, height: int, *, data: bool = True) -> Path:
    """A grey PNG; with ``data=False`` only its header (a file that declares the size)."""

    def chunk(kind: bytes, body: bytes) -> bytes:
        return (
            struct.pack(">I", len(body)) + kind + body + struct.pack(">I", zlib.crc32(kind + body))
        )

    head = b"\x89PNG\r\n\x1a\n" + chunk(
        b"IHDR", struct.pack(">IIBBBBB", width, height, 8, 0, 0, 0, 0)
    )
    body = b""
    if data:
        raw = b"".join(b"\0" + bytes([128]) * width for _ in range(height))
        body = chunk(b"IDAT", zlib.compress(raw)) + chunk(b"IEND", b"")
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_bytes(head + body)
    return path


# ------------------------------------------------------------------ sources


@pytest.fixture
def arm(tmp_path: Path) -> Path:
    """The bundled arm (an HRDF folder) with one STL mesh."""
    dest = tmp_path / "src" / "arm"
    shutil.copytree(BUNDLED_ROBOTS_DIR / "arm6", dest)
    (dest / "mesh.csv").write_text(f"{MESH_HEADER}\n{MESH_ROW}\n", encoding="utf-8")
    (dest / "meshes").mkdir()
    trimesh.creation.box(extents=(0.05, 0.05, 0.05)).export(str(dest / "meshes" / "a.stl"))
    return dest


SCENE = """<mujoco model="s">
  <compiler meshdir="{meshdir}"/>
  <asset>{asset}</asset>
  <worldbody>
    <body name="lidar" pos="0 0 1"><geom type="sphere" size="0.05"/></body>
    <body name="thing"><geom type="box" size="0.1 0.1 0.1"/>{geom}</body>
  </worldbody>
</mujoco>
"""

#: MJCF asset families: (asset XML, geom XML, file written (relative), how to write it).
#: The file named is over CAP (sparse, or a PNG header declaring a big image).
MJCF_ASSETS: dict[str, tuple[str, str, str, str]] = {
    "stl mesh": (
        '<mesh name="m" file="a.stl"/>',
        '<geom type="mesh" mesh="m"/>',
        "a.stl",
        "sparse",
    ),
    "obj mesh": (
        '<mesh name="m" file="a.obj"/>',
        '<geom type="mesh" mesh="m"/>',
        "a.obj",
        "sparse",
    ),
    "msh mesh": (
        '<mesh name="m" file="a.msh"/>',
        '<geom type="mesh" mesh="m"/>',
        "a.msh",
        "sparse",
    ),
    "mesh in meshdir": (
        '<mesh name="m" file="b.stl"/>',
        '<geom type="mesh" mesh="m"/>',
        "parts/b.stl",
        "sparse",
    ),
    "hfield binary": (
        '<hfield name="h" file="h.bin" size="1 1 0.1 0.1"/>',
        '<geom type="hfield" hfield="h"/>',
        "h.bin",
        "sparse",
    ),
    "hfield png (size)": (
        '<hfield name="h" file="h.png" size="1 1 0.1 0.1"/>',
        '<geom type="hfield" hfield="h"/>',
        "h.png",
        "sparse",
    ),
    "hfield png (declared)": (
        '<hfield name="h" file="h.png" size="1 1 0.1 0.1"/>',
        '<geom type="hfield" hfield="h"/>',
        "h.png",
        "png header",
    ),
    "texture png (declared)": (
        '<texture name="t" type="2d" file="t.png"/><material name="mt" texture="t"/>',
        '<geom type="sphere" size="0.1" material="mt"/>',
        "t.png",
        "png header",
    ),
    "texture png (size)": (
        '<texture name="t" type="2d" file="t.png"/><material name="mt" texture="t"/>',
        '<geom type="sphere" size="0.1" material="mt"/>',
        "t.png",
        "sparse",
    ),
    "cube texture face": (
        '<texture name="t" type="cube" fileright="r.png" fileleft="r.png" fileup="r.png" '
        'filedown="r.png" filefront="r.png" fileback="r.png"/>',
        "",
        "r.png",
        "png header",
    ),
    "skin": ('<skin name="k" file="k.skn"/>', "", "k.skn", "sparse"),
}


def _mjcf(folder: Path, family: str) -> tuple[Path, Path]:
    """An MJCF scene of ``family`` in ``folder`` and the over-cap file it names."""
    asset, geom, rel, how = MJCF_ASSETS[family]
    meshdir = "parts" if rel.startswith("parts/") else "."
    scene = folder / "scene.xml"
    folder.mkdir(parents=True, exist_ok=True)
    scene.write_text(SCENE.format(meshdir=meshdir, asset=asset, geom=geom), encoding="utf-8")
    target = folder / rel
    if how == "sparse":
        _sparse(target)
    else:
        _png(target, 2000, 2000, data=False)  # 16 MB once decoded: over 1 MB
    return scene, target.resolve()


def _urdf(folder: Path) -> tuple[Path, Path]:
    folder.mkdir(parents=True, exist_ok=True)
    mesh = _sparse(folder / "meshes" / "a.stl")
    urdf = folder / "r.urdf"
    urdf.write_text(
        '<robot name="r"><link name="base"><inertial><mass value="1"/>'
        '<inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>'
        '<visual><geometry><mesh filename="meshes/a.stl"/></geometry></visual>'
        '<collision><geometry><mesh filename="meshes/a.stl"/></geometry></collision>'
        "</link></robot>",
        encoding="utf-8",
    )
    return urdf, mesh.resolve()


# ------------------------------------------------------------------ MJCF readers

#: Commands that read an MJCF file: argv with ``{src}`` and ``{out}``.
MJCF_READERS: dict[str, list[str]] = {
    "convert to hrdf": ["convert", "{src}", "-o", "{out}/robot"],
    "convert to mjcf": ["convert", "{src}", "-o", "{out}/s.xml"],
    "things": ["things", "{src}", "{out}/s.xml"],
    "render": ["render", "{src}", "-o", "{out}/s.png"],
    "lidar": ["lidar", "{src}", "--sensor", "lidar", "--pattern", "grid", "-o", "{out}.npz"],
    "roundtrip": ["roundtrip", "{src}"],
}


def _argv(template: list[str], src: Path, out: Path) -> list[str]:
    return [a.format(src=src, out=out) for a in template] + CAP


@pytest.mark.parametrize("family", sorted(MJCF_ASSETS))
@pytest.mark.parametrize("reader", sorted(MJCF_READERS))
def test_every_mjcf_reader_refuses_an_asset_over_the_cap(
    reader: str, family: str, tmp_path: Path, capsys
) -> None:
    if reader == "convert to hrdf" and family in ("cube texture face", "skin"):
        family = "stl mesh"  # same gate; keeps the matrix from repeating the slowest pair
    scene, asset = _mjcf(tmp_path / "in", family)
    out = tmp_path / "out"
    _refused_for_size(_argv(MJCF_READERS[reader], scene, out), capsys, tmp_path, asset)
    assert not out.exists()


def _view(argv: list[str]) -> subprocess.CompletedProcess:
    # The timeout only guards against a regression that would start serving; not asserted.
    return subprocess.run(
        [sys.executable, "-m", "robotwright", *argv], capture_output=True, text=True, timeout=300
    )


@pytest.mark.parametrize("source", ["mjcf", "hrdf", "urdf"])
def test_view_refuses_an_asset_over_the_cap(source: str, arm: Path, tmp_path: Path) -> None:
    if source == "mjcf":
        path, asset = _mjcf(tmp_path / "in", "stl mesh")
    elif source == "urdf":
        path, asset = _urdf(tmp_path / "u")
    else:
        path, asset = arm, _sparse(arm / "meshes" / "a.stl")
    done = _view(["view", str(path), "--port", "0", *CAP])
    assert done.returncode == 2, done.stderr
    assert done.stderr.startswith("error: "), done.stderr
    _names_the_cap(done.stderr, asset)


def test_include_and_flexcomp_files_are_capped(tmp_path: Path, capsys) -> None:
    """A mesh named in an included file, and a file read while MuJoCo parses the XML."""
    folder = tmp_path / "in"
    mesh = _sparse(folder / "a.stl").resolve()
    (folder / "part.xml").write_text(
        '<mujoco><asset><mesh name="m" file="a.stl"/></asset></mujoco>', encoding="utf-8"
    )
    scene = folder / "scene.xml"
    scene.write_text(
        '<mujoco><include file="part.xml"/><worldbody><geom type="mesh" mesh="m"/>'
        "</worldbody></mujoco>",
        encoding="utf-8",
    )
    _refused_for_size(
        ["convert", str(scene), "-o", str(tmp_path / "o.xml"), *CAP], capsys, tmp_path, mesh
    )
    flex = folder / "flex.xml"
    flex.write_text(
        '<mujoco><worldbody><flexcomp name="f" type="mesh" file="a.stl" dim="2"/>'
        "</worldbody></mujoco>",
        encoding="utf-8",
    )
    _refused_for_size(
        ["render", str(flex), "-o", str(tmp_path / "f.png"), *CAP], capsys, tmp_path, mesh
    )


# ------------------------------------------------------------------ HRDF and URDF readers

HRDF_READERS: dict[str, list[str]] = {
    "info": ["info", "{src}"],
    "export mjcf": ["export", "{src}", "-o", "{out}/a.xml"],
    "export urdf": ["export", "{src}", "-o", "{out}/a.urdf", "--copy-meshes"],
    "compose": ["compose", "{src}", "-o", "{out}/s.xml", "--copy-meshes"],
    "convert": ["convert", "{src}", "-o", "{out}/a.xml"],
    "things": ["things", "{src}", "{out}/a.xml"],
    "render": ["render", "{src}", "-o", "{out}/a.png"],
}


@pytest.mark.parametrize("reader", sorted(HRDF_READERS))
def test_every_hrdf_reader_refuses_a_mesh_over_the_cap(
    reader: str, arm: Path, tmp_path: Path, capsys
) -> None:
    mesh = _sparse(arm / "meshes" / "a.stl")
    out = tmp_path / "out"
    err = _refused_for_size(_argv(HRDF_READERS[reader], arm, out), capsys, tmp_path, mesh)
    assert "mesh.csv" in err and "row 0" in err  # the row that names it
    assert not out.exists()


def test_validate_reports_the_mesh_row(arm: Path, capsys) -> None:
    mesh = _sparse(arm / "meshes" / "a.stl").resolve()
    capsys.readouterr()
    code = main(["validate", str(arm), *CAP])
    shown = "".join(capsys.readouterr())  # validate lists problems on stdout
    assert code == 1, shown
    line = next(x for x in shown.splitlines() if "mesh.csv" in x)
    assert "row 0" in line and "column 'name'" in line
    _names_the_cap(line, mesh)


def test_a_mesh_named_by_its_file_column_is_capped(arm: Path, capsys) -> None:
    mesh = _sparse(arm / "parts" / "big.stl").resolve()
    header = MESH_HEADER + ",file"
    (arm / "mesh.csv").write_text(f"{header}\n{MESH_ROW},parts/big.stl\n", encoding="utf-8")
    capsys.readouterr()
    code = main(["validate", str(arm), *CAP])
    shown = "".join(capsys.readouterr())
    assert code == 1, shown
    assert "column 'file'" in shown
    _names_the_cap(shown, mesh)


URDF_READERS: dict[str, list[str]] = {
    "convert": ["convert", "{src}", "-o", "{out}/r.xml"],
    "convert to hrdf": ["convert", "{src}", "-o", "{out}/robot"],
    "render": ["render", "{src}", "-o", "{out}/r.png"],
    "roundtrip": ["roundtrip", "{src}"],
}


@pytest.mark.parametrize("reader", sorted(URDF_READERS))
def test_every_urdf_reader_refuses_a_mesh_over_the_cap(reader: str, tmp_path: Path, capsys) -> None:
    urdf, mesh = _urdf(tmp_path / "u")
    out = tmp_path / "out"
    _refused_for_size(_argv(URDF_READERS[reader], urdf, out), capsys, tmp_path, mesh)
    assert not out.exists()


def test_the_default_cap_refuses_a_600_mb_sparse_mesh(arm: Path, tmp_path: Path, capsys) -> None:
    """No flag: 512 MB. Without the cap ``export`` read 600 MB for seconds and then said
    the file is not a mesh MuJoCo reads."""
    mesh = _sparse(arm / "meshes" / "a.stl", 600 * 10**6)
    code, err = _run(["export", str(arm), "-o", str(tmp_path / "o" / "a.xml")], capsys)
    assert code == 2
    _names_the_cap(err, mesh, limit="512 MB")
    assert "600,000,000 bytes" in err
    assert not (tmp_path / "o").exists()


# ------------------------------------------------------------------ Python readers


def _python_readers(tmp_path: Path, arm: Path) -> list[tuple[str, object, Path]]:
    from robotwright._paths import checked_mjcf_spec
    from robotwright.hrdf import HRDF
    from robotwright.parsers.mjcf.reader import parse_mjcf
    from robotwright.parsers.urdf.reader import parse_urdf
    from robotwright.render import load_model
    from robotwright.things import World

    scene, mjcf_mesh = _mjcf(tmp_path / "m", "stl mesh")
    urdf, urdf_mesh = _urdf(tmp_path / "u")
    arm_mesh = _sparse(arm / "meshes" / "a.stl").resolve()
    return [
        ("parse_mjcf", lambda: parse_mjcf(scene), mjcf_mesh),
        ("World.from_xml_path", lambda: World.from_xml_path(scene), mjcf_mesh),
        ("load_model mjcf", lambda: load_model(scene), mjcf_mesh),
        ("checked_mjcf_spec", lambda: checked_mjcf_spec(scene), mjcf_mesh),
        ("parse_urdf", lambda: parse_urdf(urdf), urdf_mesh),
        ("load_model urdf", lambda: load_model(urdf), urdf_mesh),
        ("HRDF.from_dir", lambda: HRDF.from_dir(arm), arm_mesh),
        ("load_model hrdf", lambda: load_model(arm), arm_mesh),
    ]


#: Python readers that do not compile the model or read the mesh's triangles themselves
#: (a file of zeros then loads: no triangles, noted); the others pass it to MuJoCo.
_LOAD_WITHOUT_COMPILING = {"checked_mjcf_spec", "parse_urdf", "load_model urdf", "HRDF.from_dir"}


def test_python_readers_refuse_and_the_limit_can_be_raised(arm: Path, tmp_path: Path) -> None:
    for name, read, asset in _python_readers(tmp_path, arm):
        with mesh_size_limit(1), pytest.raises(RobotwrightError) as info:
            read()
        _names_the_cap(str(info.value), asset)
        # Raised past the file, the cap lets it through: MuJoCo is then what refuses this
        # file of zeros, not the cap.
        with mesh_size_limit(4):
            if name in _LOAD_WITHOUT_COMPILING:
                assert read() is not None
            else:
                with pytest.raises(RobotwrightError) as info:
                    read()
                assert "--max-mesh-mb" not in str(info.value) and "MuJoCo" in str(info.value)


def test_python_mjcf_from_string_is_capped(tmp_path: Path) -> None:
    from robotwright.things import World

    mesh = _sparse(tmp_path / "a.stl").resolve()
    xml = '<mujoco><asset><mesh name="m" file="a.stl"/></asset><worldbody><geom type="mesh" mesh="m"/></worldbody></mujoco>'
    with mesh_size_limit(1), pytest.raises(InputFileError) as info:
        World.from_xml_string(xml, base_dir=tmp_path)
    _names_the_cap(str(info.value), mesh)


# ------------------------------------------------------------------ exactly at the cap


@pytest.mark.parametrize("seed", range(10))
def test_refused_exactly_when_over_the_cap(seed: int, tmp_path: Path, capsys) -> None:
    """A valid OBJ padded to a random size near a random cap: refused iff larger, and
    compiled when not (what passes the cap is the model MuJoCo reads)."""
    rng = random.Random(seed)
    cap = rng.randint(200, 50_000)
    size = max(200, cap + rng.choice([-2, -1, 0, 1, 2, rng.randint(-cap // 2, cap)]))
    folder = tmp_path / "in"
    _obj(folder / "a.obj", size)
    scene = folder / "scene.xml"
    asset, geom, _, _ = MJCF_ASSETS["obj mesh"]
    scene.write_text(SCENE.format(meshdir=".", asset=asset, geom=geom), encoding="utf-8")
    mb = f"{cap / 10**6:.6f}"
    out = tmp_path / "out.png"
    code, err = _run(["render", str(scene), "-o", str(out), "--max-mesh-mb", mb], capsys)
    if size > cap:
        assert code == 2, err
        assert f"{size:,} bytes" in err and "--max-mesh-mb" in err
        assert not out.exists()
    else:
        assert code == 0, err
        assert out.is_file()
    with mesh_size_limit(cap / 10**6):
        if size > cap:
            with pytest.raises(InputFileError, match="limit for a mesh"):
                check_asset_file(folder / "a.obj")
        else:
            assert check_asset_file(folder / "a.obj") == folder / "a.obj"


def test_a_small_png_height_field_and_texture_pass(tmp_path: Path, capsys) -> None:
    folder = tmp_path / "in"
    _png(folder / "h.png", 40, 30)
    _png(folder / "t.png", 16, 16)
    scene = folder / "scene.xml"
    asset = (
        '<hfield name="h" file="h.png" size="1 1 0.1 0.1"/>'
        '<texture name="t" type="2d" file="t.png"/><material name="mt" texture="t"/>'
    )
    geom = '<geom type="hfield" hfield="h"/><geom type="sphere" size="0.1" material="mt"/>'
    scene.write_text(SCENE.format(meshdir=".", asset=asset, geom=geom), encoding="utf-8")
    code, err = _run(["render", str(scene), "-o", str(tmp_path / "a.png"), *CAP], capsys)
    assert code == 0, err
    # 40 x 30 x 4 = 4,800 bytes once decoded: refused under a 4,799-byte cap only.
    code, err = _run(
        ["render", str(scene), "-o", str(tmp_path / "b.png"), "--max-mesh-mb", "0.004799"], capsys
    )
    assert code == 2 and "declares a 40 x 30 image (4,800 bytes" in err, err


# ------------------------------------------------------------------ declared sizes

HFIELD = """<mujoco><asset><hfield name="h" nrow="{nrow}" ncol="{ncol}" size="1 1 0.1 0.1"/></asset>
<worldbody><geom type="hfield" hfield="h"/></worldbody></mujoco>"""
TEXTURE = """<mujoco><asset><texture name="t" type="{type}" builtin="checker" width="{w}"
height="{h}" rgb1="1 1 1" rgb2="0 0 0"/></asset><worldbody><geom size="0.1"/></worldbody></mujoco>"""


def _declared_cases() -> list[tuple[str, str, bool]]:
    """(label, MJCF, refused under a 10,000-byte cap)."""
    cases = [
        ("hfield 50x50", HFIELD.format(nrow=50, ncol=50), False),  # 10,000 bytes: at the cap
        ("hfield 50x51", HFIELD.format(nrow=50, ncol=51), True),
        ("hfield 1x2501", HFIELD.format(nrow=1, ncol=2501), True),
        ("texture 2d 57x58", TEXTURE.format(type="2d", w=57, h=58), False),  # 9,918
        ("texture 2d 58x58", TEXTURE.format(type="2d", w=58, h=58), True),  # 10,092
        ("texture cube 23", TEXTURE.format(type="cube", w=23, h=1), False),  # 9,522
        ("texture cube 24", TEXTURE.format(type="cube", w=24, h=1), True),  # 10,368
        ("skybox 24", TEXTURE.format(type="skybox", w=24, h=1), True),
    ]
    rng = random.Random(19)
    for k in range(8):
        nrow, ncol = rng.randint(1, 200), rng.randint(1, 200)
        cases.append(
            (f"hfield random {k}", HFIELD.format(nrow=nrow, ncol=ncol), nrow * ncol * 4 > 10_000)
        )
    return cases


@pytest.mark.parametrize(
    ("label", "xml", "refused"),
    _declared_cases(),
    ids=lambda v: v if isinstance(v, str) and len(v) < 30 else "",
)
def test_declared_sizes_are_capped(
    label: str, xml: str, refused: bool, tmp_path: Path, capsys
) -> None:
    scene = tmp_path / "scene.xml"
    scene.write_text(xml, encoding="utf-8")
    out = tmp_path / "o.png"
    code, err = _run(["render", str(scene), "-o", str(out), "--max-mesh-mb", "0.01"], capsys)
    if refused:
        assert code == 2, err
        assert "declares" in err and "more than the 0.01 MB limit" in err and "--max-mesh-mb" in err
        assert str(scene) in err
        assert not out.exists()
    else:
        assert code == 0, err


@pytest.mark.parametrize("nrow", [30_000, 100_000, 2**31 - 1])
def test_a_huge_declared_height_field_is_refused_by_default(
    nrow: int, tmp_path: Path, capsys
) -> None:
    """30,000 x 30,000 samples is 3.6 GB: MuJoCo allocated it (or died trying)."""
    scene = tmp_path / "scene.xml"
    scene.write_text(HFIELD.format(nrow=nrow, ncol=nrow), encoding="utf-8")
    for argv in (
        ["convert", str(scene), "-o", str(tmp_path / "o.xml")],
        ["render", str(scene), "-o", str(tmp_path / "o.png")],
        ["things", str(scene), str(tmp_path / "t.xml")],
    ):
        code, err = _run(argv, capsys)
        assert code == 2, err
        assert '<hfield name="h">: declares nrow x ncol' in err and "512 MB limit" in err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["scene.xml"]


def test_a_png_declaring_a_huge_image_is_refused_unread(tmp_path: Path, capsys) -> None:
    """A 57-byte header declaring 60,000 x 60,000 pixels (14.4 GB once decoded)."""
    folder = tmp_path / "in"
    png = _png(folder / "h.png", 60_000, 60_000, data=False)
    scene = folder / "scene.xml"
    asset, geom, _, _ = MJCF_ASSETS["hfield png (declared)"]
    scene.write_text(SCENE.format(meshdir=".", asset=asset, geom=geom), encoding="utf-8")
    code, err = _run(["render", str(scene), "-o", str(tmp_path / "o.png")], capsys)
    assert code == 2
    assert "declares a 60,000 x 60,000 image" in err and "512 MB limit" in err
    assert str(png.resolve()) in err


# ------------------------------------------------------------------ copied files and --overwrite

#: Writers that copy the arm's mesh next to a model file: argv, and the copy's path.
COPY_WRITERS: dict[str, tuple[list[str], str]] = {
    "export mjcf": (
        ["export", "{src}", "-o", "{out}/{name}.xml", "--copy-meshes"],
        "meshes/arm/a.stl",
    ),
    "export urdf": (
        ["export", "{src}", "-o", "{out}/{name}.urdf", "--copy-meshes", "--no-mujoco-tag"],
        "meshes/arm/a.stl",
    ),
    "compose": (
        ["compose", "{src}", "-o", "{out}/{name}.xml", "--copy-meshes"],
        "meshes/arm/a.stl",
    ),
    "convert": (["convert", "{src}", "-o", "{out}/{name}.xml"], "meshes/arm/a.stl"),
    "things": (["things", "{src}", "{out}/{name}.xml"], "assets/a.stl"),
}


def _copy_argv(writer: str, src: Path, out: Path, name: str) -> list[str]:
    return [a.format(src=src, out=out, name=name) for a in COPY_WRITERS[writer][0]]


@pytest.fixture
def outside(tmp_path: Path) -> Path:
    folder = tmp_path / "outside"
    folder.mkdir()
    (folder / "mine.stl").write_bytes(b"precious")
    return folder


def _plant(kind: str, dest: Path, outside: Path) -> None:
    dest.parent.mkdir(parents=True, exist_ok=True)
    if kind == "other bytes":
        dest.write_bytes(b"a file of the user's")
    elif kind == "empty file":
        dest.write_bytes(b"")
    elif kind == "link outside":
        dest.symlink_to(outside / "mine.stl")
    elif kind == "dangling link":
        dest.symlink_to(outside / "nothing.stl")
    elif kind == "fifo":
        os.mkfifo(dest)
    else:
        raise AssertionError(kind)


PLANTED = ["other bytes", "empty file", "link outside", "dangling link", "fifo"]


@pytest.mark.parametrize("planted", PLANTED)
@pytest.mark.parametrize("writer", sorted(COPY_WRITERS))
def test_a_copy_never_replaces_another_file_without_overwrite(
    writer: str, planted: str, arm: Path, tmp_path: Path, outside: Path, capsys
) -> None:
    out = tmp_path / "out"
    dest = out / COPY_WRITERS[writer][1]
    _plant(planted, dest, outside)
    (out / "notes.txt").write_text("keep", encoding="utf-8")
    before, outside_before = snapshot(out), snapshot(outside)
    code, err = _run(_copy_argv(writer, arm, out, "new"), capsys)
    assert code == 2, err
    assert err.startswith("error: ") and str(dest) in err and "--overwrite" in err
    assert snapshot(out) == before and snapshot(outside) == outside_before
    # With --overwrite the copy replaces it (a link itself, never followed); the rest of
    # the folder and everything outside stay as they were.
    code, err = _run([*_copy_argv(writer, arm, out, "new"), "--overwrite"], capsys)
    assert code == 0, err
    assert not dest.is_symlink() and dest.read_bytes() == (arm / "meshes" / "a.stl").read_bytes()
    assert (out / "notes.txt").read_text(encoding="utf-8") == "keep"
    assert snapshot(outside) == outside_before


@pytest.mark.parametrize("writer", sorted(COPY_WRITERS))
def test_a_copy_holding_the_same_bytes_is_not_refused(
    writer: str, arm: Path, tmp_path: Path, capsys
) -> None:
    """Exporting a second model next to the first shares its copies: no --overwrite needed."""
    out = tmp_path / "out"
    assert _run(_copy_argv(writer, arm, out, "first"), capsys)[0] == 0
    dest = out / COPY_WRITERS[writer][1]
    assert dest.is_file()
    code, err = _run(_copy_argv(writer, arm, out, "second"), capsys)
    assert code == 0, err
    assert (out / dest.relative_to(out)).read_bytes() == (arm / "meshes" / "a.stl").read_bytes()
    # The model file itself still follows the file rule.
    code, err = _run(_copy_argv(writer, arm, out, "second"), capsys)
    assert code == 2 and "--overwrite" in err


@pytest.mark.parametrize("seed", range(6))
def test_copy_collisions_fuzzed(seed: int, arm: Path, tmp_path: Path, capsys) -> None:
    """Random writer, random content at the copy's name (the mesh's own bytes changed at
    one random position, truncated, extended): refused unless identical."""
    rng = random.Random(seed)
    writer = rng.choice(sorted(COPY_WRITERS))
    mesh = (arm / "meshes" / "a.stl").read_bytes()
    variant = rng.choice(["flip", "truncate", "extend", "same"])
    if variant == "flip":
        i = rng.randrange(len(mesh))
        content = mesh[:i] + bytes([mesh[i] ^ 0xFF]) + mesh[i + 1 :]
    elif variant == "truncate":
        content = mesh[: rng.randrange(len(mesh))]
    elif variant == "extend":
        content = mesh + bytes([rng.randrange(256)])
    else:
        content = mesh
    out = tmp_path / "out"
    dest = out / COPY_WRITERS[writer][1]
    dest.parent.mkdir(parents=True)
    dest.write_bytes(content)
    code, err = _run(_copy_argv(writer, arm, out, "m"), capsys)
    if variant == "same":
        assert code == 0, err
    else:
        assert code == 2 and str(dest) in err, (variant, err)
        assert dest.read_bytes() == content
        assert not (out / "m.xml").exists()


def test_python_export_keeps_replacing_its_copies(arm: Path, tmp_path: Path) -> None:
    """Python's export(path) replaces its output (as it replaces the model file): the
    overwrite flag is the command line's."""
    from robotwright.generators import MJCFHumanoidGenerator
    from robotwright.hrdf import HRDF

    dest = tmp_path / "meshes" / "arm" / "a.stl"
    dest.parent.mkdir(parents=True)
    dest.write_bytes(b"old copy")
    MJCFHumanoidGenerator.from_hrdf(HRDF.from_dir(arm)).export(tmp_path / "a.xml", copy_meshes=True)
    assert dest.read_bytes() == (arm / "meshes" / "a.stl").read_bytes()
