"""Plot the standing tests' base-height curves, one line per framework.

Usage: ``python tools/plot_standing_curves.py OUT.png CURVE.json [CURVE.json ...]``

Each ``CURVE.json`` is what a standing test writes with ``ROBOTWRIGHT_STANDING_CURVE``
set (``tests/isaaclab/test_go2_stands.py``, ``tests/generators/test_mjlab_go2_stands.py``):
``{"framework": ..., "dt": seconds, "base_z": [metres per step]}``. Draws base height
against simulated time with the test's band (2 cm around the last second's mean, from
1 s on) and prints each curve's settled height and largest excursion after 1 s.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

#: The test's bounds: the band's half width [m] and when it starts [s].
BAND_M = 0.02
LANDED_S = 1.0


def _load(path: Path) -> dict | str:
    try:
        curve = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, ValueError) as exc:
        return f"error: {path}: {exc}"
    if not isinstance(curve, dict) or not isinstance(curve.get("base_z"), list):
        return f"error: {path}: expected a standing test's curve (framework, dt, base_z)"
    return curve


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("out", type=Path)
    parser.add_argument("curves", type=Path, nargs="+")
    args = parser.parse_args(argv)
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7.0, 3.2))
    for path in args.curves:
        curve = _load(path)
        if isinstance(curve, str):
            print(curve, file=sys.stderr)
            return 2
        z, dt = curve["base_z"], float(curve["dt"])
        t = [dt * (i + 1) for i in range(len(z))]
        tail = z[-round(1.0 / dt) :]
        settled = sum(tail) / len(tail)
        after = z[round(LANDED_S / dt) :]
        worst = max(abs(v - settled) for v in after)
        line = ax.plot(t, z, lw=1.2, label=f"{curve['framework']}: {settled:.3f} m")[0]
        ax.fill_between(
            [LANDED_S, t[-1]], settled - BAND_M, settled + BAND_M, color=line.get_color(), alpha=0.1
        )
        print(
            f"{curve['framework']}: settled {settled:.4f} m, largest excursion after "
            f"{LANDED_S:g} s {worst * 100:.2f} cm (bound {BAND_M * 100:g} cm)"
        )
    ax.set_xlabel("simulated time [s]")
    ax.set_ylabel("base height [m]")
    ax.set_title("Go2 from one command, standing under its PD drives (band: the test's 2 cm)")
    ax.legend(loc="upper right", fontsize=8)
    ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(args.out, dpi=110)
    print(f"wrote {args.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
