#!/usr/bin/env python3
"""Vectorised numpy Euler-Maruyama of specs/pendulum.sde: the peer figure for `reachc simulate`.

    python3 bench/numpy_em_pendulum.py RESULT_JSON [--paths N] [--seed S]

RESULT_JSON  DIR/<analysis>.json from `reachc run specs/pendulum.sde --analysis <name> -o DIR`
             (`contraction` or `interval`): the report times, the metric, each step's set and
             its time-uniform span are read from it.

The same model, step (0.01), horizon and number of paths as `reachc simulate --paths N`, all
paths advanced together with numpy array operations, normals from numpy's default generator
(PCG64, `standard_normal`). Like reachc's check, every state is tested against the set it
must lie in:

- every Euler-Maruyama step (here every step ends at a report time): the PRS at that time, a
  P-ball for `contraction` (`(x - c)' P (x - c) <= R^2`), for `interval` the parallelotope
  `lo <= T x <= hi` widened by `r_t` (the distance `|x - T^-1 clamp(T x)|_P <= r_t`);
- the time-uniform tube: the span of the step, `{lo <= x <= hi} (+) B_P(radius)`, with the
  distance to the clamped point.

Prints path-steps per second of the loop alone (numpy imports and result loading excluded).
Needs numpy only (install it in a virtual environment outside the repository).
"""

import time

import numpy as np

from em_common import report, setup


def main():
    n, res, p, steps, dt, rng = setup(__doc__, 100_000)
    transform = res.get("transform")
    t_mat = np.array(transform["matrix"], dtype=float) if transform else None
    t_inv = np.array(transform["inverse"], dtype=float) if transform else None
    g, length, k1, k2, noise = 10.0, 1.0, -20.0, -20.0, 0.1

    theta = rng.uniform(-np.pi / 10, np.pi / 10, n)
    omega = rng.uniform(-0.2, 0.2, n)
    outside = np.zeros(n, dtype=bool)
    left_tube = np.zeros(n, dtype=bool)

    def quad(d0, d1):
        return p[0, 0] * d0 * d0 + (p[0, 1] + p[1, 0]) * d0 * d1 + p[1, 1] * d1 * d1

    started = time.perf_counter()
    sqrt_dt = np.sqrt(dt)
    for st in steps[1:]:
        z = rng.standard_normal(n)
        f0 = omega
        f1 = g / length * np.sin(theta) + k1 * theta + k2 * omega
        theta = theta + f0 * dt
        omega = omega + f1 * dt + noise * sqrt_dt * z
        # The tube: distance to the span's box.
        span = st["span"]
        c0 = np.clip(theta, span["lo"][0], span["hi"][0])
        c1 = np.clip(omega, span["lo"][1], span["hi"][1])
        left_tube |= quad(theta - c0, omega - c1) > span["radius"] ** 2
        det = st["det_set"]
        if t_mat is None:
            c = st["nominal"]
            outside |= quad(theta - c[0], omega - c[1]) > st["prs_radius"] ** 2
        else:
            y0 = t_mat[0, 0] * theta + t_mat[0, 1] * omega
            y1 = t_mat[1, 0] * theta + t_mat[1, 1] * omega
            e0 = np.clip(y0, det["lo"][0], det["hi"][0]) - y0
            e1 = np.clip(y1, det["lo"][1], det["hi"][1]) - y1
            d0 = t_inv[0, 0] * e0 + t_inv[0, 1] * e1
            d1 = t_inv[1, 0] * e0 + t_inv[1, 1] * e1
            outside |= quad(d0, d1) > st["r_t"] ** 2
    secs = time.perf_counter() - started
    path_steps = n * (len(steps) - 1)
    report(
        path_steps,
        secs,
        [("outside at some time", outside.sum()), ("left the tube", left_tube.sum())],
    )


if __name__ == "__main__":
    main()
