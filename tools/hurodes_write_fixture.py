"""Run by hurodes' own interpreter (``.testdata/hurodes-venv``): convert one MJCF file into
an HRDF folder with hurodes 0.1.9, then let hurodes export its own MJCF of that folder.

Usage: ``python hurodes_write_fixture.py SOURCE.xml ASSETS_ROOT ROBOT_NAME [--export]``

hurodes only writes under ``$HURODES_ASSETS_PATH/robots/<name>``, read at import time, so
the caller sets ``HURODES_ASSETS_PATH=ASSETS_ROOT`` and this script checks that it did.
Meshes are copied as they are: hurodes' largest ``max_faces`` keeps it from decimating
them (decimation would change the robot's geometry, and needs a further package).
"""

from __future__ import annotations

import os
import sys
from pathlib import Path


def main(argv: list[str]) -> int:
    export = "--export" in argv
    args = [a for a in argv if a != "--export"]
    if len(args) != 3:
        print(__doc__, file=sys.stderr)
        return 2
    source, assets_root, name = Path(args[0]), Path(args[1]), args[2]
    if Path(os.environ.get("HURODES_ASSETS_PATH", "")).resolve() != assets_root.resolve():
        print("set HURODES_ASSETS_PATH to ASSETS_ROOT", file=sys.stderr)
        return 2

    import hurodes
    from hurodes.humanoid_robot import HumanoidRobot
    from hurodes.parsers import HumanoidMJCFParser
    from hurodes.utils.mesh import MUJOCO_MAX_FACES

    parser = HumanoidMJCFParser(source, name)
    parser.parse()
    parser.save(max_faces=MUJOCO_MAX_FACES)
    if export:
        # hurodes' default export: ``<folder>/exported/robot.xml``, meshdir ``../meshes``.
        HumanoidRobot.from_name(name).export_mjcf()
    print(f"hurodes {hurodes.VERSION} wrote {hurodes.ROBOTS_PATH / name}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
