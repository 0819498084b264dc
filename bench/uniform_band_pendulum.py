"""The time-uniform truth for the pendulum's per-state PRS widths: the smallest factor `u` such
that `u` times the PRS's per-state half-widths (from a `reachc simulate` report) holds
`1 - delta` of Euler-Maruyama paths at every report time of a window at once.

    python bench/uniform_band_pendulum.py SIM_JSON [--paths N] [--seed S]

SIM_JSON is `reachc simulate specs/pendulum.sde --analysis contraction -o DIR`'s
`DIR/contraction.sim.json` (its `steps[k].states[i].prs`). Paths start uniformly in the
initial box, `dt = 1e-3` (10 steps per report step of 0.01); the nominal (from the box centre,
an equilibrium) is 0. `1 / u` is how many times the tightest time-uniform band of the PRS's
own shape the PRS is (figures in docs/benchmarks.md). Needs numpy only.
"""

import argparse
import json

import numpy as np

ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
ap.add_argument("sim")
ap.add_argument("--paths", type=int, default=100_000)
ap.add_argument("--seed", type=int, default=1)
args = ap.parse_args()
with open(args.sim) as f:
    sim = json.load(f)
delta = sim["delta"]
h = np.array([[s["prs"] for s in st["states"]] for st in sim["steps"]])
rng = np.random.default_rng(args.seed)
n, dt, per_report = args.paths, 1e-3, 10
theta = rng.uniform(-np.pi / 10, np.pi / 10, n)
omega = rng.uniform(-0.2, 0.2, n)
windows = {"[0, 4]": 1, "[1, 4]": 100, "[2, 4]": 200}
worst = {w: np.zeros((n, 2)) for w in windows}
for k in range(1, len(h)):
    for _ in range(per_report):
        dw = rng.standard_normal(n) * np.sqrt(dt)
        theta, omega = (
            theta + omega * dt,
            omega + (10 * np.sin(theta) - 20 * theta - 20 * omega) * dt + 0.1 * dw,
        )
    r = np.stack([np.abs(theta) / h[k, 0], np.abs(omega) / h[k, 1]], axis=1)
    for w, first in windows.items():
        if k >= first:
            worst[w] = np.maximum(worst[w], r)
for w, arr in worst.items():
    for i, name in enumerate(["theta", "omega"]):
        u = np.quantile(arr[:, i], 1 - delta)
        print(f"{w} {name}: u = {u:.3f}, PRS / tightest uniform band = {1 / u:.2f}x")
