"""Feasibility study for issue 28 item 1 (method.md of the shared notes, 8.9): can a scalar
P_t-ball with a time-varying metric close its local-rate regions where no constant metric does?

Not a rigorous computation: the generalised rate

    c_k = max over the step's ends e, over sampled states x of the region,
          lambda_max( L_e^-1 (sym(P_e J(x)) + (P_(k+1) - P_k) / (2 h)) L_e^-T ),  P_e = L_e L_e'

(the exact condition for P_t linear in t on the step: the matrix is affine in t, so its
largest eigenvalue is convex and the ends bound it) is estimated by sampling J over the region
instead of enclosing it, and the radius follows the per-step recursion of the AMGF tube,
r = sqrt(Psi kappa) with Psi' = 2 c Psi + sigma^2, as reachc's local rates do (method.md 8.3).
The region is the box holding the ball of radius (R + r) * 1.25 in P_t. Sampling only makes the
rates smaller than certified ones, so a failure here is a failure of the approach.

Metrics: `riccati` integrates Q' = A Q + Q A' + G G' + alpha Q along the nominal (A the Jacobian
there) and takes P = Q^-1: at the nominal the rate is -alpha/2 - lambda_min(P^1/2 G G' P^1/2)/2,
and for a scalar linear system the ball is the exact Gaussian; `frame` (unicycle only) takes
P_t = T(theta*_t)' diag(1, 1, eps) T(theta*_t), T the Jacobian of the look-ahead coordinates
q = p + l (cos theta, sin theta): the coordinates in which the closed loop contracts.

    python bench/time_varying_metric.py unicycle riccati 0.5
    python bench/time_varying_metric.py unicycle frame 0.05
    python bench/time_varying_metric.py vanderpol riccati 0.5 [x0_lo,y0_lo x0_hi,y0_hi]

Prints per half second: the rate c, the ball's P-radius and its half-widths per state.
Results (2026-12-07) are in docs/benchmarks.md, "Time-varying metrics: a study".
"""

import csv
import os
import sys

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))


def unicycle():
    rows = list(csv.DictReader(open(os.path.join(HERE, "..", "specs", "unicycle_ref.csv"))))
    t_ref = np.array([float(r["t"]) for r in rows])
    col = {k: np.array([float(r[k]) for r in rows]) for k in rows[0]}
    l, k = 0.3, 2.0

    def f(x, t):
        px, py, th = x
        q = {c: np.interp(t, t_ref, col[c]) for c in ("qx", "qy", "qvx", "qvy")}
        ax = q["qvx"] - k * np.tanh(px + l * np.cos(th) - q["qx"])
        ay = q["qvy"] - k * np.tanh(py + l * np.sin(th) - q["qy"])
        v = np.cos(th) * ax + np.sin(th) * ay
        w = (np.cos(th) * ay - np.sin(th) * ax) / l
        return np.array([v * np.cos(th), v * np.sin(th), w])

    def frame(x, eps):
        th = x[2]
        t = np.array([[1, 0, -l * np.sin(th)], [0, 1, l * np.cos(th)], [0, 0, 1]])
        return t.T @ np.diag([1, 1, eps]) @ t

    x0 = np.array([5.0, 5.0, -2 * np.pi / 3])
    return f, x0, np.zeros(3), 0.1 * np.eye(3), 5.0, 27.0, frame


def vanderpol(lo, hi):
    def f(x, t):
        return np.array([x[1], (1 - x[0] ** 2) * x[1] - x[0]])

    g = np.array([[0.0], [0.05]])
    c = (lo + hi) / 2
    return f, c, (hi - lo) / 2, g, 2.0, 20.0, None


def jac(f, x, t, e=1e-6):
    n = len(x)
    return np.array([(f(x + e * np.eye(n)[i], t) - f(x - e * np.eye(n)[i], t)) / (2 * e)
                     for i in range(n)]).T


def main():
    system, metric, param = sys.argv[1], sys.argv[2], float(sys.argv[3])
    if system == "unicycle":
        f, x0, half0, g, horizon, kappa, frame = unicycle()
    else:
        lo = np.array([float(v) for v in (sys.argv[4] if len(sys.argv) > 4 else "1.0,-0.1").split(",")])
        hi = np.array([float(v) for v in (sys.argv[5] if len(sys.argv) > 5 else "1.2,0.1").split(",")])
        f, x0, half0, g, horizon, kappa, frame = vanderpol(lo, hi)
    h = 0.01
    steps = int(round(horizon / h))
    n = len(x0)
    xs = [x0]
    x = x0.copy()
    for i in range(steps):
        t = i * h
        k1 = f(x, t)
        k2 = f(x + h / 2 * k1, t + h / 2)
        k3 = f(x + h / 2 * k2, t + h / 2)
        k4 = f(x + h * k3, t + h)
        x = x + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
        xs.append(x)
    w = g @ g.T
    if metric == "frame":
        ps = [frame(x, param) for x in xs]
    else:
        q = np.diag(n * half0 ** 2) + w * h + 1e-9 * np.eye(n)
        qs = [q]
        for i in range(steps):
            a = jac(f, xs[i], i * h)
            for _ in range(10):
                q = q + h / 10 * (a @ q + q @ a.T + w + param * q)
            q = (q + q.T) / 2
            qs.append(q)
        ps = [np.linalg.inv(q) for q in qs]
    qs = [np.linalg.inv(p) for p in ps]
    rng = np.random.default_rng(0)

    def rate(i, rad):
        d = (ps[i + 1] - ps[i]) / h
        half = np.sqrt(np.maximum(np.diag(qs[i]), np.diag(qs[i + 1]))) * rad
        pts = [xs[i], xs[i + 1]] + [xs[i] + half * s for s in rng.uniform(-1, 1, (60, n))]
        c = -np.inf
        for p in (ps[i], ps[i + 1]):
            li = np.linalg.inv(np.linalg.cholesky(p))
            for y in pts:
                j = jac(f, y, i * h)
                m = li @ ((p @ j + j.T @ p) / 2 + d / 2) @ li.T
                c = max(c, np.linalg.eigvalsh((m + m.T) / 2).max())
        s2 = max(np.linalg.eigvalsh(np.linalg.cholesky(p).T @ w @ np.linalg.cholesky(p)).max()
                 for p in (ps[i], ps[i + 1]))
        return c, s2

    psi, big_r = 0.0, (1.0 if half0.any() else 0.0)
    rad = max(big_r, 1e-3)
    for i in range(steps):
        guess = rad * 1.25
        for _ in range(12):
            c, s2 = rate(i, guess)
            e = np.exp(min(2 * c * h, 700))
            psi_next = e * psi + s2 * ((e - 1) / (2 * c) if abs(c) > 1e-12 else h)
            r_next = big_r * np.exp(min(c * h, 700))
            total = np.sqrt(psi_next * kappa) + max(big_r, r_next)
            if total <= guess:
                break
            guess = total * 1.25
        psi, big_r = psi_next, r_next
        rad = np.sqrt(psi * kappa) + big_r
        if (i + 1) % 50 == 0:
            hw = np.sqrt(np.diag(qs[i + 1])) * rad
            print(f"t = {(i + 1) * h:4.2f}  c = {c:9.3g}  radius = {rad:9.3g}  half-widths = "
                  + " ".join(f"{v:9.3g}" for v in hw))


if __name__ == "__main__":
    main()
