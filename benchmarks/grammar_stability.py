"""How much the physics scores move when a design's masses move by 1e-9 of their value.

For random designs (uniform over the designs of at most --max-links links, per seed),
each limb body's mass in the mounted model is scaled by (1 + 1e-9) and ``track``,
``energy`` and ``payload`` are computed again. Prints, per objective, how many designs
moved by more than 1e-6 of their value and the largest relative change, over all designs
and split by whether the tracking run is clean (touches nothing, no overlap, every joint
within its rating): a score that moves more than the model does depends on the last
digits of the arithmetic, and a search ranking designs by it ranks noise. A run with
contacts is the exception that cannot be helped: contact dynamics amplify any change,
and such a design is infeasible for a track or energy search.

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


def _changes(limb) -> tuple[dict[str, float], bool]:  # noqa: ANN001
    """Relative change of each score under the nudge, and whether the tracking run is
    clean (no touch, no overlap, every joint within its rating: what the default
    constraints of a track or energy search ask)."""
    base, nudged = P.mount(limb), P.mount(limb)
    for b in nudged.limb_bodies:
        nudged.model.body_mass[b] *= 1 + NUDGE
    a, b = P.track(limb, mounted=base), P.track(limb, mounted=nudged)
    pa = P.payload(limb, mounted=base).mass
    pb = P.payload(limb, mounted=nudged).mass

    def rel(x: float, y: float) -> float:
        return abs(x - y) / abs(x) if x else abs(y)

    clean = a.first_contact is None and a.first_overlap is None and a.speed_ratio <= 1
    changes = {"track": rel(a.error, b.error), "energy": rel(a.power, b.power)}
    return {**changes, "payload": rel(pa, pb)}, clean


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
    clean_runs: list[bool] = []
    for seed in args.seeds:
        rng, counter = random.Random(seed), Counter(g)
        for _ in range(args.designs):
            limb = build(g, sample(g, args.max_links, rng, counter))
            if not limb.joints:
                continue
            changes, clean = _changes(limb)
            clean_runs.append(clean)
            for name, change in changes.items():
                moved[name].append(change)
    n_clean = sum(clean_runs)
    print(f"a {NUDGE:g} change of every limb mass, {len(moved['track'])} designs "
          f"(seeds {args.seeds}, <= {args.max_links} links), {n_clean} with a clean "
          "tracking run (no touch, no overlap, within ratings)")  # fmt: skip
    for name, changes in moved.items():
        for label, keep in (("all", None), ("clean", True), ("touching", False)):
            picked = [c for c, ok in zip(changes, clean_runs) if keep is None or ok == keep]
            unstable = sum(c > STABLE for c in picked)
            print(
                f"  {name:8s} {label:9s} {unstable:3d} of {len(picked):3d} moved by more than "
                f"{STABLE:g} of their value; largest change {max(picked, default=0.0):.2g}"
            )


if __name__ == "__main__":
    with measured(()):
        main()
