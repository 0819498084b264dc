#!/usr/bin/env python3
"""Recomputes the independent checks in core/tests/data/pendulum.json (mpmath, 30 digits).

Not run by the tests. The pendulum of the paper's Section VIII-B, theta' = omega,
omega' = 10 sin(theta) - 20 theta - 20 omega, has the Jacobians conv{A1, A2} with
A1 = [[0, 1], [-10, -20]] (cos theta = -1) and A2 = [[0, 1], [-30, -20]] (cos theta = 1), and
G = [0, 0.1]'. This prints:

- mu_P(A1), mu_P(A2) for the paper's P = [[35.68, 2.21], [2.21, 1.27]]: the largest root of
  det(sym(P A) - lambda P) = 0 (the largest eigenvalue of P^1/2 A P^-1/2, symmetrised);
- sigma for the paper's P: sqrt(G' P G);
- the optimum of min over P > 0 of max(mu_P(A1), mu_P(A2)) (the semidefinite program the
  `sdp` feature solves by bisection): mu_P is scale-invariant in P and quasi-convex (its
  sublevel sets {P : A'P + PA <= 2 c P} are convex cones), so a pattern search over
  P = [[1, b], [b, d]] from the paper's P finds the global minimum.
"""
import json

import mpmath as mp

mp.mp.dps = 30

A1 = mp.matrix([[0, 1], [-10, -20]])
A2 = mp.matrix([[0, 1], [-30, -20]])
PAPER_P = mp.matrix([[mp.mpf("35.68"), mp.mpf("2.21")], [mp.mpf("2.21"), mp.mpf("1.27")]])


def mu(p, a):
    """Largest generalised eigenvalue of (sym(P A), P) for 2x2 matrices."""
    s = (p * a + (p * a).T) / 2
    # det(S - l P) = det(P) l^2 - (s11 p22 + s22 p11 - 2 s12 p12) l + det(S)
    qa = p[0, 0] * p[1, 1] - p[0, 1] ** 2
    qb = -(s[0, 0] * p[1, 1] + s[1, 1] * p[0, 0] - 2 * s[0, 1] * p[0, 1])
    qc = s[0, 0] * s[1, 1] - s[0, 1] ** 2
    return (-qb + mp.sqrt(qb * qb - 4 * qa * qc)) / (2 * qa)


def rate(b, d):
    if d <= b * b:
        return mp.inf
    p = mp.matrix([[1, b], [b, d]])
    return max(mu(p, A1), mu(p, A2))


def sdp_optimum():
    b, d = PAPER_P[0, 1] / PAPER_P[0, 0], PAPER_P[1, 1] / PAPER_P[0, 0]
    best, step = rate(b, d), mp.mpf("0.01")
    while step > mp.mpf("1e-12"):
        moved = False
        for db, dd in [(1, 0), (-1, 0), (0, 1), (0, -1), (1, 1), (-1, -1), (1, -1), (-1, 1)]:
            value = rate(b + db * step, d + dd * step * d)
            if value < best:
                best, b, d, moved = value, b + db * step, d + dd * step * d, True
        if not moved:
            step /= 2
    return best


def main():
    g = mp.matrix([0, mp.mpf("0.1")])
    out = {
        "mu_P_of_vertices_with_paper_P": [float(mu(PAPER_P, A1)), float(mu(PAPER_P, A2))],
        "sigma_with_paper_P": float(mp.sqrt((g.T * PAPER_P * g)[0])),
        "sdp_optimum_c": float(sdp_optimum()),
    }
    print(json.dumps(out, indent=2))


if __name__ == "__main__":
    main()
