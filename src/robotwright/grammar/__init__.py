"""Graph grammar that generates robot limbs (supernumerary robotic limbs, SRLs).

G = (N, T, A, R, S): a derivation from the start symbol applies rules from a YAML
grammar, choosing components and parameters from a YAML component library. A design
is that derivation (readable, serialisable, hashed); it builds into a limb with a
modified-DH table per branch, into an HRDF robot, and through the generators into MJCF
and URDF.

Quick use::

    from robotwright.grammar import default_grammar, sample, build_hrdf, mount_on
    g = default_grammar()
    design = sample(g, max_links=3, rng=random.Random(0))
    limb = build_hrdf(g, design)                      # HRDF robot, fixed base
    robot = mount_on(HRDF.from_robot_name("mini_humanoid"), limb, "back_mount")
"""

from __future__ import annotations

import random
from typing import TYPE_CHECKING

from robotwright._lazy import attach

if TYPE_CHECKING:
    from robotwright.grammar.build import Limb, build, build_hrdf
    from robotwright.grammar.derive import count, count_by_links, enumerate_designs, replay, sample
    from robotwright.grammar.design import Design, to_dot
    from robotwright.grammar.dh import DHRow, fk
    from robotwright.grammar.loader import default_grammar, load_grammar, load_library
    from robotwright.grammar.mount import mount_on
    from robotwright.grammar.rules import Grammar
    from robotwright.hrdf.model import HRDF

__all__ = [
    "DHRow",
    "Design",
    "Grammar",
    "Limb",
    "build",
    "build_hrdf",
    "count",
    "count_by_links",
    "default_grammar",
    "demo_limb",
    "demo_limb_design",
    "enumerate_designs",
    "fk",
    "load_grammar",
    "load_library",
    "mount_on",
    "replay",
    "sample",
    "to_dot",
]

attach(__name__, __file__)


def demo_limb_design(seed: int = 0, max_links: int = 3) -> Design:
    """A design drawn uniformly with ``random.Random(seed)`` from the bundled grammar,
    redrawn until it has no self-collision at the zero pose (deterministic per seed)."""
    from robotwright.grammar.derive import sample
    from robotwright.grammar.loader import default_grammar
    from robotwright.grammar.objectives import EvalContext, NoSelfCollision

    g = default_grammar()
    rng = random.Random(seed)
    check = NoSelfCollision()
    for _ in range(100):
        design = sample(g, max_links, rng)
        if check(EvalContext(g, design)) is None:
            return design
    raise RuntimeError(f"no collision-free design in 100 draws (seed {seed})")


def demo_limb(seed: int = 0, max_links: int = 3, name: str = "srl") -> HRDF:
    """A grammar-generated limb as an HRDF robot (fixed base at its mount frame)."""
    from robotwright.grammar.build import build_hrdf
    from robotwright.grammar.loader import default_grammar

    return build_hrdf(default_grammar(), demo_limb_design(seed, max_links), name=name)
