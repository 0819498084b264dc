#!/usr/bin/env python3
"""Vectorised numpy Euler-Maruyama of specs/linear.sde: the peer figure for `reachc simulate`.

    python3 bench/numpy_em_linear.py RESULT_JSON [--paths N] [--seed S]

RESULT_JSON  DIR/<analysis>.json from `reachc run specs/linear.sde --analysis <name> -o DIR`
             (`amgf_rule` or `paper_rule`, the pointwise analyses): the report times, the
             metric and each step's PRS are read from it.

The same model (`x' = -0.4 x`, `G = sqrt(2) I`, `x0 = 0`), step (0.01), horizon and number of
paths as `reachc simulate --paths N`, all paths advanced together with numpy array operations,
normals from numpy's default generator (PCG64, `standard_normal`). Like reachc's check, every
state at a report time (here every Euler-Maruyama step) is tested against that time's PRS, the
P-ball `(x - c)' P (x - c) <= R^2`.

Prints path-steps per second of the loop alone (numpy imports and result loading excluded).
Needs numpy only (install it in a virtual environment outside the repository).
"""

import time

import numpy as np

from em_common import report, setup


def main():
    n, _, p, steps, dt, rng = setup(__doc__, 1_000_000)
    a, s = -0.4, np.sqrt(2.0)
    x1 = np.zeros(n)
    x2 = np.zeros(n)
    outside = np.zeros(n, dtype=bool)
    started = time.perf_counter()
    scale = s * np.sqrt(dt)
    for st in steps[1:]:
        z1 = rng.standard_normal(n)
        z2 = rng.standard_normal(n)
        x1 = x1 + a * x1 * dt + scale * z1
        x2 = x2 + a * x2 * dt + scale * z2
        c = st["nominal"]
        d1, d2 = x1 - c[0], x2 - c[1]
        q = p[0, 0] * d1 * d1 + (p[0, 1] + p[1, 0]) * d1 * d2 + p[1, 1] * d2 * d2
        outside |= q > st["prs_radius"] ** 2
    secs = time.perf_counter() - started
    path_steps = n * (len(steps) - 1)
    report(path_steps, secs, [("outside at some time", outside.sum())])


if __name__ == "__main__":
    main()
