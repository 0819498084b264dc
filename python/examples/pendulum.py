"""The paper's pendulum figure (Fig. 6) from Python: the contraction-based PRS (left) and the
interval-based one with Euler steps (right) of specs/pendulum.sde, with 100 sample paths.

    python python/examples/pendulum.py [OUT.png]
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

import reachc  # noqa: E402
import reachc.plot  # noqa: E402

SPEC = Path(__file__).resolve().parents[2] / "specs" / "pendulum.sde"


def main() -> None:
    out = Path(sys.argv[1]) if len(sys.argv) > 1 else Path("pendulum.png")
    started = time.perf_counter()
    spec = reachc.load(SPEC)
    contraction = spec.reach("paper_contraction").run()
    interval = spec.reach("paper_interval").run()
    paths = spec.sample_paths(
        contraction.times, paths=100, seed=0, center=list(contraction.nominal[0])
    )
    fig, (left, right) = plt.subplots(1, 2, figsize=(11, 4.5))
    reachc.plot.sets(contraction, ax=left, paths=paths, label="delta-PRS (P-ball)")
    left.set_title("contraction-based PRS (paper_contraction)")
    reachc.plot.sets(interval, ax=right, paths=paths, color="C1", label="delta-PRS (bounding box)")
    right.set_title("interval-based PRS, Euler steps (paper_interval)")
    for ax in (left, right):
        ax.legend(loc="upper right")
        ax.grid(alpha=0.3)
    fig.suptitle(f"pendulum, delta = {contraction.delta:g}, t = 0 .. {contraction.times[-1]:g}")
    fig.tight_layout()
    fig.savefig(out, dpi=120)
    print(f"wrote {out} ({time.perf_counter() - started:.2f} s)")


if __name__ == "__main__":
    main()
