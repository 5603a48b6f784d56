"""Grow robot limbs from the SRL graph grammar, pick the best-reaching one, wear it.

Run: python examples/grow_a_limb.py [OUT_DIR]   (default ./grow_a_limb)

1. count the designs with at most 3 links, and sample three of them (seeded);
2. search for the design with the longest reach (beam search);
3. print its modified-DH table and mount it on the bundled humanoid's back.
"""

from __future__ import annotations

import random
import sys
import warnings
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

from robotwright.errors import ConversionWarning
from robotwright.grammar import count, default_grammar, mount_on, sample
from robotwright.grammar.build import build, build_hrdf
from robotwright.grammar.demo import BACKWARDS
from robotwright.grammar.export import export_design, export_mjcf
from robotwright.grammar.objectives import NoSelfCollision, Reach
from robotwright.grammar.search import beam_search
from robotwright.hrdf import HRDF


def main(out_dir: str = "grow_a_limb") -> None:
    out = Path(out_dir)
    g = default_grammar()
    print(f"designs with at most 3 links: {count(g, 3)}")
    for seed in range(3):
        print(f"  sample {seed}: {sample(g, 3, random.Random(seed)).hash()}")

    with ThreadPoolExecutor(2) as pool:
        best = beam_search(
            g, [Reach()], [NoSelfCollision()], budget=60, max_links=3, executor=pool
        ).best
    print(f"best reach {best.values['reach']:.3f} m:\n{best.design.to_text()}", end="")
    limb = build(g, best.design)
    for branch in limb.branches:
        print(f"  branch to {branch.site}, joints {branch.joints}:")
        for row in branch.rows:
            print(
                f"    a={row.a:.3f} m  alpha={row.alpha:+.4f} rad  d={row.d:.3f} m  theta={row.theta:+.4f} rad  {row.type}"
            )

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ConversionWarning)  # listed in each folder's warnings.txt
        export_design(g, best.design, out / "limb", overwrite=True)
        wearer = mount_on(
            HRDF.from_robot_name("mini_humanoid"),
            build_hrdf(g, best.design),
            "back_mount",
            quat=BACKWARDS,
        )
        export_mjcf(wearer, out / "humanoid_with_limb.xml")
    print(f"wrote {out / 'limb'} and {out / 'humanoid_with_limb.xml'} ({wearer.dof} DoF)")


if __name__ == "__main__":
    main(*sys.argv[1:])
