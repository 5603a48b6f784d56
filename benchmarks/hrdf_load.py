#!/usr/bin/env python
"""Time ``HRDF.from_dir`` on the G1 fixture: robotwright vs hurodes, same folder, same run.

    python benchmarks/hrdf_load.py [--hurodes-python /path/to/python-with-hurodes]

hurodes only loads folders under ``$HURODES_ASSETS_PATH/robots`` (default
``~/.hurodes/robots``); the script copies the fixture under a temporary assets folder it
removes afterwards, for the peer's run.
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import sys
import tempfile
import uuid
import warnings
from pathlib import Path

from _machine import measured, print_peer

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _timing import median_seconds, report, run_peer  # noqa: E402

from robotwright.hrdf import HRDF  # noqa: E402

#: The hurodes-written G1 that tools/fetch_test_data.py makes.
DEFAULT_FIXTURE = Path(__file__).resolve().parents[1] / ".testdata" / "hurodes-fixtures" / "g1_29"

PEER_CODE = """
import json, statistics, time, warnings
warnings.simplefilter("ignore")
from hurodes.hrdf.hrdf import HRDF
path = {path!r}
HRDF.from_dir(path)
samples = []
for _ in range({repeat}):
    t0 = time.perf_counter()
    for _ in range({number}):
        HRDF.from_dir(path)
    samples.append((time.perf_counter() - t0) / {number})
print(json.dumps({{"median": statistics.median(samples)}}))
"""


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--fixture", type=Path, default=DEFAULT_FIXTURE)
    ap.add_argument("--hurodes-python", help="python interpreter that has hurodes installed")
    ap.add_argument("--repeat", type=int, default=15)
    ap.add_argument("--number", type=int, default=10)
    args = ap.parse_args()
    print_peer(args.hurodes_python, "hurodes")
    if not (args.fixture / "meta.yaml").is_file():
        print(
            f"fixture not found: {args.fixture} (run python tools/fetch_test_data.py)",
            file=sys.stderr,
        )
        return 2

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        hrdf = HRDF.from_dir(args.fixture)
        ours = median_seconds(
            lambda: HRDF.from_dir(args.fixture), repeat=args.repeat, number=args.number
        )
    print(f"robot: {hrdf.name}, {len(hrdf.bodies)} bodies, {len(hrdf.meshes)} mesh rows")

    peer = None
    if args.hurodes_python:
        # hurodes reads robots only under $HURODES_ASSETS_PATH/robots: a temporary one,
        # so that nothing is written into the user's ~/.hurodes.
        with tempfile.TemporaryDirectory() as assets:
            robot = Path(assets) / "robots" / f"bench_{uuid.uuid4().hex[:8]}"
            shutil.copytree(args.fixture, robot)
            os.environ["HURODES_ASSETS_PATH"] = assets
            code = PEER_CODE.format(path=str(robot), repeat=args.repeat, number=args.number)
            peer = run_peer(args.hurodes_python, code)["median"]
    report([("HRDF.from_dir (G1, 30 bodies)", ours, peer)])
    print(json.dumps({"ours_s": ours, "hurodes_s": peer}))
    return 0


if __name__ == "__main__":
    with measured():
        sys.exit(main())
