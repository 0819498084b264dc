#!/usr/bin/env python3
"""Recomputes core/tests/data/kappa.jsonl in 30-digit arithmetic (mpmath).

Not run by the tests: the tests read the file this writes. Run it to check or regenerate the
reference (`python3 scripts/reference/kappa.py > core/tests/data/kappa.jsonl`); it needs only
mpmath (`pip install mpmath`). Each value is the exact quantity below, rounded to the nearest
double at the end (docs/method.md section 5 gives the formulas):

- kappa_amgf: inf over z > 0 of h(z) = z^2 / (2 (ln Phi_n(z) - ln(1/delta))), over the z where
  the denominator is positive, with Phi_n(z) = Gamma(n/2) (2/z)^(n/2-1) I_(n/2-1)(z), the mean of
  e^(z l_1) over the unit sphere (cosh z for n = 1). Minimised by golden-section search on the
  convex valley of h after a geometric scan, to 25 digits.
- kappa_paper_eps_1_16: the paper's Theorem 1 constant at eps = 1/16,
  eps1 n + eps2 ln(1/delta), eps1 = 2 ln(1 + 2/eps) / (1 - eps)^2, eps2 = 2 / (1 - eps)^2.
- chi2_quantile: the chi-square quantile chi2_n^-1(1 - delta), the root of the regularised
  lower incomplete gamma function P(n/2, x/2) = 1 - delta.
"""
import json
import sys

import mpmath as mp

mp.mp.dps = 30

DIMENSIONS = [1, 2, 3, 4, 6, 10]
DELTAS = ["0.1", "0.01", "0.001", "1e-6", "1e-9"]


def log_phi(n, z):
    """ln Phi_n(z), the log of the mean of exp(z l_1) over the unit sphere in R^n."""
    nu = mp.mpf(n) / 2 - 1
    return mp.loggamma(mp.mpf(n) / 2) + nu * mp.log(2 / z) + mp.log(mp.besseli(nu, z))


def kappa_amgf(n, delta):
    log_inv = mp.log(1 / delta)

    def h(z):
        d = log_phi(n, z) - log_inv
        return mp.inf if d <= 0 else z * z / (2 * d)

    # The denominator turns positive once ln Phi_n(z) > ln(1/delta) (ln Phi_n(z) ~ z): scan
    # geometrically past that point, then refine the minimum by golden-section search.
    grid = [mp.mpf(2) ** (k / mp.mpf(8)) for k in range(-40, 120)]
    values = [h(z) for z in grid]
    k = min(range(len(grid)), key=lambda i: values[i])
    lo, hi = grid[max(k - 1, 0)], grid[min(k + 1, len(grid) - 1)]
    g = (mp.sqrt(5) - 1) / 2
    a, b = lo, hi
    c, d = b - g * (b - a), a + g * (b - a)
    fc, fd = h(c), h(d)
    for _ in range(200):
        if fc < fd:
            b, d, fd = d, c, fc
            c = b - g * (b - a)
            fc = h(c)
        else:
            a, c, fc = c, d, fd
            d = a + g * (b - a)
            fd = h(d)
    return min(fc, fd)


def kappa_paper(n, delta, eps):
    eps1 = 2 * mp.log(1 + 2 / eps) / (1 - eps) ** 2
    eps2 = 2 / (1 - eps) ** 2
    return eps1 * n + eps2 * mp.log(1 / delta)


def chi2_quantile(n, delta):
    k = mp.mpf(n) / 2
    target = 1 - delta
    cdf = lambda x: mp.gammainc(k, 0, x / 2, regularized=True) - target
    # Bisection on the increasing CDF: bracket, then 120 halvings (far below 30 digits).
    lo, hi = mp.mpf(0), mp.mpf(1)
    while cdf(hi) < 0:
        hi *= 2
    for _ in range(120):
        mid = (lo + hi) / 2
        if cdf(mid) < 0:
            lo = mid
        else:
            hi = mid
    return hi


def main():
    for n in DIMENSIONS:
        for text in DELTAS:
            delta = mp.mpf(text)
            row = {
                "n": n,
                "delta": float(text),
                "kappa_amgf": float(kappa_amgf(n, delta)),
                "kappa_paper_eps_1_16": float(kappa_paper(n, delta, mp.mpf(1) / 16)),
                "chi2_quantile": float(chi2_quantile(n, delta)),
            }
            json.dump(row, sys.stdout)
            sys.stdout.write("\n")


if __name__ == "__main__":
    main()
