"""How much the physics scores move when a design's masses move by 1e-9 of their value.

For random designs (uniform over the designs of at most --max-links links, per seed),
each limb body's mass in the mounted model is scaled by (1 + 1e-9) and ``track``,
``energy`` and ``payload`` are computed again. Prints, per objective, how many designs
moved by more than 1e-6 of their value and the largest relative change: a score that
moves more than the model does depends on the last digits of the arithmetic, and a
search ranking designs by it ranks noise.

    python benchmarks/grammar_stability.py [--designs 24] [--seeds 3 7 11] [--max-links 4]
"""

from __future__ import annotations

import argparse
import random
import warnings

from _machine import measured

from robotwright.grammar import default_grammar
from robotwright.grammar import physics as P
from robotwright.grammar.build import build
from robotwright.grammar.derive import Counter, sample

#: Relative change of a mass, and the largest relative change of a score called stable.
NUDGE, STABLE = 1e-9, 1e-6


def _changes(limb) -> dict[str, float]:  # noqa: ANN001
    """Relative change of each score under the nudge."""
    base, nudged = P.mount(limb), P.mount(limb)
    for b in nudged.limb_bodies:
        nudged.model.body_mass[b] *= 1 + NUDGE
    a, b = P.track(limb, mounted=base), P.track(limb, mounted=nudged)
    pa = P.payload(limb, mounted=base).mass
    pb = P.payload(limb, mounted=nudged).mass

    def rel(x: float, y: float) -> float:
        return abs(x - y) / abs(x) if x else abs(y)

    return {"track": rel(a.error, b.error), "energy": rel(a.power, b.power), "payload": rel(pa, pb)}


def main() -> None:
    ap = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    ap.add_argument("--designs", type=int, default=24, help="designs per seed")
    ap.add_argument("--seeds", type=int, nargs="+", default=[3, 7, 11])
    ap.add_argument("--max-links", type=int, default=4)
    args = ap.parse_args()
    warnings.simplefilter("ignore")
    g = default_grammar()
    moved: dict[str, list[float]] = {"track": [], "energy": [], "payload": []}
    for seed in args.seeds:
        rng, counter = random.Random(seed), Counter(g)
        for _ in range(args.designs):
            limb = build(g, sample(g, args.max_links, rng, counter))
            if not limb.joints:
                continue
            for name, change in _changes(limb).items():
                moved[name].append(change)
    print(f"a {NUDGE:g} change of every limb mass, {len(moved['track'])} designs "
          f"(seeds {args.seeds}, <= {args.max_links} links)")  # fmt: skip
    for name, changes in moved.items():
        unstable = sum(c > STABLE for c in changes)
        print(
            f"  {name:8s} {unstable:3d} of {len(changes)} moved by more than {STABLE:g} of "
            f"their value; largest change {max(changes, default=0.0):.2g}"
        )


if __name__ == "__main__":
    with measured(()):
        main()
