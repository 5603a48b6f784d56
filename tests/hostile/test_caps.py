"""Hostile inputs against the caps (issue 19 item 4): names, terminal output, grammar
names and infinite grammars, worker counts, scan .npz bombs, rays per frame, keyframes.

Each cap is tried over its limit (a clear one-line error, nothing written) and with its
override (the same input accepted)."""

from __future__ import annotations

import csv
import io
import os
import random
import shutil
import zipfile
from pathlib import Path

import numpy as np
import pytest
import yaml

from robotwright.cli import main

ARM6 = Path(__file__).resolve().parents[2] / "src" / "robotwright" / "robots" / "arm6"

#: Every character a name may not hold: C0 controls, DEL, C1 controls, bidirectional
#: formatting characters and the line/paragraph separators.
C0 = [chr(c) for c in range(0x00, 0x20)]
C1 = [chr(c) for c in range(0x80, 0xA0)]
BIDI = ["\u061c", "\u200e", "\u200f", *map(chr, range(0x202A, 0x202F))]
BIDI += [*map(chr, range(0x2066, 0x206A)), "\u2028", "\u2029"]
BAD_CHARS = [*C0, "\x7f", *C1, *BIDI]


def _cid(ch: str) -> str:
    return f"U+{ord(ch):04X}"


def _rename(folder: Path, old: str, new: str) -> None:
    """Rename ``old`` to ``new`` in every CSV cell of an HRDF folder (written with the csv
    module, so a newline or quote is quoted as any CSV writer would)."""
    for table in folder.glob("*.csv"):
        with table.open(newline="", encoding="utf-8") as f:
            rows = list(csv.reader(f))
        rows = [[new if cell == old else cell for cell in row] for row in rows]
        with table.open("w", newline="", encoding="utf-8") as f:
            csv.writer(f, lineterminator="\n").writerows(rows)


def _printed(capsys) -> str:
    out = capsys.readouterr()
    return out.out + out.err


# ------------------------------------------------------------------ names in HRDF
# (the name, the kind of row it names) in the bundled arm6 robot
_HRDF_NAMES = [
    ("wrist_3_link", "body.csv"),
    ("wrist_3_joint", "joint.csv"),
    ("tool0", "site.csv"),
    ("tool0_pos", "sensor.csv"),
]


def _arm6_names() -> list[tuple[str, str]]:
    names = list(_HRDF_NAMES)
    with (ARM6 / "actuator.csv").open(encoding="utf-8") as f:
        names.append((next(csv.DictReader(f))["name"], "actuator.csv"))
    return names


@pytest.mark.parametrize("ch", BAD_CHARS, ids=_cid)
@pytest.mark.parametrize(("old", "table"), _arm6_names(), ids=lambda v: str(v))
def test_control_characters_in_hrdf_names_are_refused(tmp_path, capsys, ch, old, table):
    robot = tmp_path / "arm6"
    shutil.copytree(ARM6, robot)
    _rename(robot, old, f"x{ch}y")
    assert main(["validate", str(robot)]) == 1
    printed = _printed(capsys)
    if ch not in "\n\t":
        assert ch not in printed  # shown escaped, never raw
    assert table in printed or "csv" in printed
    out = tmp_path / "out.xml"
    assert main(["export", str(robot), "-o", str(out)]) == 2
    assert not out.exists()


@pytest.mark.parametrize("length", [1025, 5000, 100_000])
def test_overlong_hrdf_names_are_refused(tmp_path, capsys, length):
    robot = tmp_path / "arm6"
    shutil.copytree(ARM6, robot)
    _rename(robot, "tool0_pos", "s" * length)
    assert main(["validate", str(robot)]) == 1
    assert "at most 1024" in _printed(capsys)


def test_names_at_the_limit_and_unicode_letters_pass(tmp_path, capsys):
    robot = tmp_path / "arm6"
    shutil.copytree(ARM6, robot)
    _rename(robot, "tool0_pos", "s" * 1024)
    _rename(robot, "tool0", "outil_é_工具")
    assert main(["validate", str(robot)]) == 0, _printed(capsys)


# ------------------------------------------------------------------ names in MJCF/URDF
_MJCF = """<mujoco model="m"><worldbody><body name="{name}"><joint name="j"/>
<geom size="0.1" mass="1"/></body></worldbody></mujoco>"""
_URDF = """<robot name="r"><link name="base"><inertial><mass value="1"/>
<inertia ixx="1" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/></inertial></link>
<link name="{name}"><inertial><mass value="1"/>
<inertia ixx="1" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/></inertial></link>
<joint name="j" type="revolute"><parent link="base"/><child link="{name}"/>
<axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint></robot>"""


@pytest.mark.parametrize("ch", BAD_CHARS, ids=_cid)
@pytest.mark.parametrize("fmt", ["mjcf", "urdf"])
def test_control_characters_in_mjcf_and_urdf_names_are_refused(tmp_path, capsys, ch, fmt):
    # Written as an XML character reference: the reader decides (XML 1.0 refuses most
    # C0 references; the rest reach the name checks).
    name = f"wrist&#x{ord(ch):x};3"
    src = tmp_path / ("robot.xml" if fmt == "mjcf" else "robot.urdf")
    src.write_text((_MJCF if fmt == "mjcf" else _URDF).format(name=name), encoding="utf-8")
    out = tmp_path / "out"
    assert main(["convert", str(src), "-o", str(out)]) == 2
    assert not out.exists()
    printed = _printed(capsys)
    if ch not in "\n\t":
        assert ch not in printed
    assert printed.startswith("error:") or "\nerror:" in printed or "error:" in printed


@pytest.mark.parametrize("fmt", ["mjcf", "urdf"])
def test_plain_names_in_mjcf_and_urdf_still_convert(tmp_path, fmt):
    src = tmp_path / ("robot.xml" if fmt == "mjcf" else "robot.urdf")
    src.write_text((_MJCF if fmt == "mjcf" else _URDF).format(name="wrist_3"), encoding="utf-8")
    out = tmp_path / "out"
    assert main(["convert", str(src), "-o", str(out)]) == 0
    assert "wrist_3" in (out / "body.csv").read_text(encoding="utf-8")


# ------------------------------------------------------------------ names in Things
def _thing_kinds():
    from robotwright.things import Body, Hinge, Motor, Site, Sphere

    return {"body": Body, "joint": Hinge, "site": Site, "geom": Sphere, "actuator": Motor}


@pytest.mark.parametrize("ch", BAD_CHARS, ids=_cid)
@pytest.mark.parametrize("kind", ["body", "joint", "site", "geom", "actuator"])
def test_control_characters_in_things_names_are_refused(ch, kind):
    from robotwright.things import ThingAttributeError

    cls = _thing_kinds()[kind]
    with pytest.raises(ThingAttributeError, match="control or bidirectional"):
        cls(f"x{ch}y")
    thing = cls("fine")
    with pytest.raises(ThingAttributeError, match="control or bidirectional"):
        thing.name = f"{ch}"
    assert thing.name == "fine"


@pytest.mark.parametrize("ch", ["\x1b", "\n", "\u202e", "\x9b"], ids=_cid)
def test_control_characters_in_things_references_are_refused(ch):
    from robotwright.things import Motor, ThingAttributeError

    with pytest.raises(ThingAttributeError):
        Motor("m", refsite=f"hip{ch}")


def test_overlong_things_name_is_refused():
    from robotwright.things import Body, ThingAttributeError

    assert Body("b" * 1024).name == "b" * 1024
    with pytest.raises(ThingAttributeError, match="at most 1024"):
        Body("b" * 1025)


# ------------------------------------------------------------------ terminal output
_ESCAPES = ["\x1b[2J", "\x1b]0;owned\x07", "\x9b31m", "\r", "\x08\x08", "\u202eevil", "\x00"]


@pytest.mark.parametrize("payload", _ESCAPES, ids=lambda p: ascii(p))
def test_escape_codes_from_csv_cells_are_printed_escaped(tmp_path, capsys, payload):
    robot = tmp_path / "arm6"
    shutil.copytree(ARM6, robot)
    # An unknown body: the message quotes the cell.
    with (robot / "site.csv").open(newline="", encoding="utf-8") as f:
        rows = list(csv.reader(f))
    rows[1][1] = f"ghost{payload}"
    with (robot / "site.csv").open("w", newline="", encoding="utf-8") as f:
        csv.writer(f, lineterminator="\n").writerows(rows)
    assert main(["validate", str(robot)]) != 0
    printed = _printed(capsys)
    assert "site.csv" in printed  # (a CR or NUL breaks the row itself: still named)
    for ch in payload:
        if ord(ch) < 0x20 or 0x7F <= ord(ch) < 0xA0 or ch == "\u202e":
            assert ch not in printed


def test_printable_keeps_ordinary_text():
    from robotwright._names import printable

    text = "error: body.csv: row 3: 'épaule 肩'\n\tnext line"
    assert printable(text) == text
    assert printable("a\x1bb\u202ec") == "a\\x1bb\\u202ec"


# ------------------------------------------------------------------ grammar names
def _grammar_copy(tmp_path: Path) -> tuple[Path, dict]:
    from robotwright.grammar.loader import default_grammar_path

    src = Path(default_grammar_path())
    shutil.copy(src.parent / "srl_library.yaml", tmp_path / "srl_library.yaml")
    data = yaml.safe_load(src.read_text(encoding="utf-8"))
    data["library"] = "srl_library.yaml"
    return tmp_path / "g.yaml", data


_BAD_RULE_NAMES = [f"r{ch}1" for ch in BAD_CHARS] + [
    "r 1",
    "r@1",
    "r:1",
    "1r",
    "r=1",
    "r;1",
    "r-1",
    "",
    "r" * 1025,
]


@pytest.mark.parametrize("name", _BAD_RULE_NAMES, ids=ascii)
def test_rule_names_a_design_file_cannot_hold_are_refused(tmp_path, capsys, name):
    from robotwright.errors import GrammarError
    from robotwright.grammar.loader import load_grammar

    path, data = _grammar_copy(tmp_path)
    data["rules"][name] = data["rules"].pop("r3")
    path.write_text(yaml.safe_dump(data, allow_unicode=True), encoding="utf-8")
    with pytest.raises(GrammarError, match="column 'rules'"):
        load_grammar(path)
    assert main(["grammar", "check", str(path)]) == 1


@pytest.mark.parametrize("where", ["symbols", "components", "params", "name"])
@pytest.mark.parametrize("ch", ["\n", "\x1b", "\u202e", " "], ids=_cid)
def test_other_grammar_names_are_refused(tmp_path, where, ch):
    from robotwright.errors import GrammarError
    from robotwright.grammar.loader import load_grammar

    path, data = _grammar_copy(tmp_path)
    lib_path = tmp_path / "srl_library.yaml"
    lib = yaml.safe_load(lib_path.read_text(encoding="utf-8"))
    if where == "symbols":
        data["symbols"][f"E{ch}"] = data["symbols"]["E"]
    elif where == "name":
        data["name"] = f"srl{ch}x"
    elif where == "components":
        first = next(iter(lib["components"]))
        lib["components"][f"c{ch}x"] = lib["components"].pop(first)
    else:
        comp = next(c for c in lib["components"].values() if c.get("params"))
        pname = next(iter(comp["params"]))
        comp["params"][f"p{ch}x"] = comp["params"][pname]
    lib_path.write_text(yaml.safe_dump(lib, allow_unicode=True), encoding="utf-8")
    path.write_text(yaml.safe_dump(data, allow_unicode=True), encoding="utf-8")
    with pytest.raises(GrammarError, match="name"):
        load_grammar(path)


def test_word_rule_names_load_and_their_designs_read_back(tmp_path):
    from robotwright.grammar.derive import Counter, sample
    from robotwright.grammar.design import Design
    from robotwright.grammar.loader import load_grammar

    path, data = _grammar_copy(tmp_path)
    data["rules"]["grow_Link_2"] = data["rules"].pop("r3")
    path.write_text(yaml.safe_dump(data), encoding="utf-8")
    g = load_grammar(path)
    rng = random.Random(3)
    for _ in range(5):
        d = sample(g, 3, rng, Counter(g))
        assert Design.from_text(d.to_text()) == d


def test_grammar_with_infinitely_many_designs_per_link_count_is_an_error(tmp_path, capsys):
    path, data = _grammar_copy(tmp_path)
    # The base may grow connectors forever without adding a link.
    data["rules"]["r5"] = {"lhs": "-B*", "rhs": "-B -> C -> B*"}
    path.write_text(yaml.safe_dump(data), encoding="utf-8")
    code = main(["grammar", "check", str(path)])
    printed = _printed(capsys)
    assert code == 1, printed
    assert "infinite" in printed and "valid" not in printed.splitlines()[-1]


def test_bundled_grammar_still_checks_valid(capsys):
    from robotwright.grammar.loader import default_grammar_path

    assert main(["grammar", "check", str(default_grammar_path())]) == 0
    assert capsys.readouterr().out.rstrip().endswith("valid")


# ------------------------------------------------------------------ worker counts
class _RecordingPool:
    """Stands in for ProcessPoolExecutor: records the size asked for, starts nothing."""

    sizes: list[int] = []

    def __init__(self, max_workers: int, initializer=None, initargs=()) -> None:
        type(self).sizes.append(max_workers)
        # the pool's workers are told to die with the search (see executors.die_with_parent)
        assert initializer is not None and initargs == (os.getpid(),)

    def map(self, fn, items, chunksize=1):
        return map(fn, items)

    def shutdown(self, wait=True):
        pass


@pytest.fixture
def pool(monkeypatch):
    import robotwright.grammar.search as search

    _RecordingPool.sizes = []
    monkeypatch.setattr(search, "ProcessPoolExecutor", _RecordingPool)
    return _RecordingPool


@pytest.mark.parametrize("extra", [1, 2, 7, 4998, 99_998, 10**9])
def test_worker_counts_above_the_cores_are_refused(pool, capsys, extra):
    from robotwright.grammar.search import usable_cores

    n = usable_cores() + extra
    code = main(["grammar", "search", "--workers", str(n), "--budget", "2", "--max-links", "1"])
    assert code == 2
    err = capsys.readouterr().err
    assert err.startswith("error: --workers") and "--force-workers" in err
    assert err.count("\n") == 1
    assert pool.sizes == []  # no process pool was made


@pytest.mark.parametrize("method", ["random_search", "beam_search", "mcts_search"])
def test_api_refuses_worker_counts_above_the_cores(pool, method):
    import robotwright.grammar.search as search
    from robotwright.grammar import default_grammar
    from robotwright.grammar.objectives import DoFCount

    fn = getattr(search, method)
    with pytest.raises(ValueError, match="force_workers=True"):
        fn(
            default_grammar(),
            [DoFCount()],
            budget=2,
            max_links=1,
            workers=search.usable_cores() + 1,
        )
    assert pool.sizes == []


def test_forced_workers_run_and_never_exceed_the_budget(pool, capsys):
    from robotwright.grammar.search import usable_cores

    n = usable_cores() + 50
    argv = ["grammar", "search", "--workers", str(n), "--force-workers", "--budget", "3"]
    assert main([*argv, "--max-links", "1", "--objective", "dof"]) == 0, capsys.readouterr()
    assert pool.sizes == [3]


def test_worker_counts_within_the_cores_run(pool, capsys):
    from robotwright.grammar.search import usable_cores

    argv = ["grammar", "search", "--workers", str(usable_cores()), "--budget", "2"]
    assert main([*argv, "--max-links", "1", "--objective", "dof"]) == 0, capsys.readouterr()
    assert pool.sizes == [min(usable_cores(), 2)]


# ------------------------------------------------------------------ scan .npz bombs
def _npz_bomb(path: Path, shape: tuple[int, ...], dtype: str, data_bytes: int = 1 << 16) -> Path:
    """A small .npz whose ``points`` entry declares ``shape`` of ``dtype`` in its .npy
    header and holds ``data_bytes`` of deflated zeros (far less than declared)."""
    header = io.BytesIO()
    np.lib.format.write_array_header_1_0(
        header, {"descr": np.dtype(dtype).str, "fortran_order": False, "shape": shape}
    )
    with zipfile.ZipFile(path, "w", zipfile.ZIP_DEFLATED) as z:
        with z.open("points.npy", "w", force_zip64=True) as f:
            f.write(header.getvalue())
            f.write(b"\0" * data_bytes)
        for name in ("labels", "class_names"):
            buf = io.BytesIO()
            np.save(buf, np.zeros(1, dtype=np.int64 if name == "labels" else "<U3"))
            z.writestr(f"{name}.npy", buf.getvalue())
    return path


_BOMBS = [
    ((600_000_000, 3), "<f8"),
    ((200_000_000, 3), "<f8"),
    ((10**12,), "|u1"),
    ((2_000_000_000,), "<i8"),
    ((1000, 1000, 1000), "<f4"),
    ((50_000_000, 3), "<c16"),
    ((2**40, 3), "<f8"),
]


@pytest.mark.parametrize(("shape", "dtype"), _BOMBS, ids=str)
def test_npz_declaring_huge_arrays_is_refused_before_loading(tmp_path, capsys, shape, dtype):
    bomb = _npz_bomb(tmp_path / "bomb.npz", shape, dtype)
    assert bomb.stat().st_size < 200_000
    png = tmp_path / "out.png"
    assert main(["render", str(bomb), "-o", str(png)]) == 2
    err = capsys.readouterr().err
    assert err.startswith("error:") and "--max-scan-mb" in err and err.count("\n") == 1
    assert not png.exists()


def test_npz_zip_directory_declaring_a_huge_entry_is_refused(tmp_path):
    from robotwright.scene.load import ViewError, read_scan

    path = tmp_path / "big.npz"
    with (
        zipfile.ZipFile(path, "w", zipfile.ZIP_DEFLATED) as z,
        z.open("points.npy", "w", force_zip64=True) as f,
    ):
        for _ in range(80):  # 1.3 GB of zeros, deflated to about 1.3 MB
            f.write(b"\0" * (1 << 24))
    assert path.stat().st_size < 5_000_000
    with pytest.raises(ViewError, match="1,000.0 MB limit"):
        read_scan(path)


@pytest.mark.parametrize("junk", ["pickle", "not_zip", "truncated", "bad_header", "short_data"])
def test_malformed_npz_gets_one_line(tmp_path, capsys, junk):
    path = tmp_path / "scan.npz"
    if junk == "pickle":
        np.savez(path, points=np.array([object()]), labels=np.zeros(1, int), class_names=["a"])
    elif junk == "not_zip":
        path.write_bytes(b"PK\x03\x04" + b"\xff" * 200)
    elif junk == "truncated":
        np.savez(path, points=np.zeros((10, 3)), labels=np.zeros(10, int), class_names=["a"])
        path.write_bytes(path.read_bytes()[:150])
    elif junk == "bad_header":
        with zipfile.ZipFile(path, "w") as z:
            z.writestr("points.npy", b"\x93NUMPY\x01\x00\x10\x00{'descr': 'x'}   \n")
            z.writestr("labels.npy", b"junk")
            z.writestr("class_names.npy", b"junk")
    else:
        _npz_bomb(path, (1000, 3), "<f8", data_bytes=100)
    assert main(["render", str(path), "-o", str(tmp_path / "o.png")]) == 2
    err = capsys.readouterr().err
    assert err.startswith("error:") and err.count("\n") == 1 and "Traceback" not in err


def test_npz_limit_is_raised_and_lowered_by_the_flag(tmp_path, capsys):
    from robotwright._npz import load_npz, npz_limit
    from robotwright.errors import InputFileError

    path = tmp_path / "scan.npz"
    np.savez(path, points=np.zeros((10_000, 3)), labels=np.zeros(10_000, int), class_names=["a"])
    # 100 kB: the 240 kB of points do not fit
    with npz_limit(0.1), pytest.raises(InputFileError, match="0.1 MB limit"):
        load_npz(path)
    with npz_limit(1.0):
        assert load_npz(path)["points"].shape == (10_000, 3)
    bomb = _npz_bomb(tmp_path / "b.npz", (2_000_000, 3), "<f8", data_bytes=48_000_000)
    png = tmp_path / "o.png"
    assert main(["render", str(bomb), "-o", str(png), "--max-scan-mb", "10"]) == 2
    assert "10.0 MB limit" in capsys.readouterr().err
    # Raised: the 48 MB array loads (and fails later only as a scan, not on its size).
    assert main(["render", str(bomb), "-o", str(png), "--max-scan-mb", "100"]) == 2
    err = capsys.readouterr().err
    assert "MB limit" not in err and "'labels'" in err


# ------------------------------------------------------------------ rays per frame
def _huge_patterns():
    from robotwright.sensors import (
        GridPatternCfg,
        LivoxPatternCfg,
        PinholeCameraPatternCfg,
        SpinningLidarPatternCfg,
    )

    return [
        lambda: GridPatternCfg(resolution=1e-4, size=(2.0, 2.0)),
        lambda: GridPatternCfg(resolution=1e-9),
        lambda: PinholeCameraPatternCfg(width=5000, height=5000),
        lambda: PinholeCameraPatternCfg(width=10**6, height=10**6),
        lambda: LivoxPatternCfg(num_rays=20_000_000),
        lambda: SpinningLidarPatternCfg.os128(columns=10**6),
    ]


@pytest.mark.parametrize("k", range(6))
def test_patterns_over_the_ray_cap_are_refused(k):
    from robotwright.errors import SensorError

    with pytest.raises(SensorError, match="ray_limit"):
        _huge_patterns()[k]()


def test_ray_limit_lowers_and_raises_the_cap():
    from robotwright.errors import SensorError
    from robotwright.sensors import PinholeCameraPatternCfg, ray_limit

    with ray_limit(1000), pytest.raises(SensorError, match="at most 1,000"):
        PinholeCameraPatternCfg(width=64, height=48)
    with ray_limit(5000):
        assert PinholeCameraPatternCfg(width=64, height=48).num_rays == 64 * 48
    with pytest.raises(SensorError), ray_limit(0):
        pass


# ------------------------------------------------------------------ keyframes
def _keyframe_mjcf(path: Path, keys: int, nkey: int | None = None) -> Path:
    size = f'<size nkey="{nkey}"/>' if nkey is not None else ""
    body = '<body name="b"><joint name="j"/><geom size="0.1" mass="1"/></body>'
    frames = "".join(f'<key qpos="{i * 1e-3}"/>' for i in range(keys))
    path.write_text(
        f"<mujoco>{size}<worldbody>{body}</worldbody><keyframe>{frames}</keyframe></mujoco>",
        encoding="utf-8",
    )
    return path


@pytest.mark.parametrize(
    ("keys", "nkey"), [(10_001, None), (0, 100_000_000), (0, 2**31 - 1), (5, 10**6)]
)
def test_models_asking_for_too_many_keyframes_are_refused(tmp_path, capsys, keys, nkey):
    src = _keyframe_mjcf(tmp_path / "k.xml", keys, nkey)
    out = tmp_path / "out"
    assert main(["convert", str(src), "-o", str(out)]) == 2
    err = capsys.readouterr().err
    assert "keyframes" in err and "--max-keyframes" in err
    assert not out.exists()


def test_max_keyframes_flag_lowers_and_raises_the_limit(tmp_path, capsys):
    src = _keyframe_mjcf(tmp_path / "k.xml", 3)
    assert main(["convert", str(src), "-o", str(tmp_path / "a"), "--max-keyframes", "2"]) == 2
    assert "3 keyframes" in capsys.readouterr().err
    assert main(["convert", str(src), "-o", str(tmp_path / "b"), "--max-keyframes", "3"]) == 0
    big = _keyframe_mjcf(tmp_path / "big.xml", 10_001)
    out = tmp_path / "c"
    assert main(["convert", str(big), "-o", str(out), "--max-keyframes", "20000"]) == 0
    assert (out / "extra.xml").read_text(encoding="utf-8").count("<key ") == 10_001


def test_python_keyframe_limit_lowers_and_raises_the_limit(tmp_path):
    import robotwright
    from robotwright.errors import RobotwrightError
    from robotwright.parsers import mjcf_to_hrdf

    src = _keyframe_mjcf(tmp_path / "k.xml", 3)
    with robotwright.keyframe_limit(2), pytest.raises(RobotwrightError, match="3 keyframes"):
        mjcf_to_hrdf(src)
    with robotwright.keyframe_limit(3):
        assert "<key " in mjcf_to_hrdf(src).mjcf_extra


@pytest.mark.parametrize("keys", [3, 50])
def test_hrdf_extra_xml_keyframes_are_capped(tmp_path, capsys, keys):
    robot = tmp_path / "arm6"
    shutil.copytree(ARM6, robot)
    frames = "".join("<key/>" for _ in range(keys))
    (robot / "extra.xml").write_text(
        f"<mujoco><keyframe>{frames}</keyframe></mujoco>", encoding="utf-8"
    )
    assert main(["validate", str(robot), "--max-keyframes", "2"]) == 1
    assert f"{keys} keyframes" in _printed(capsys)
    assert main(["validate", str(robot), "--max-keyframes", str(keys)]) == 0, _printed(capsys)
