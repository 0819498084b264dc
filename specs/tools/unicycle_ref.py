#!/usr/bin/env python3
"""Generate specs/unicycle_ref.csv: the reference trajectory for specs/unicycle.sde.

The paper (Sec. VIII-C) tracks an MPC plan that drives the deterministic unicycle
    px' = v cos(theta),  py' = v sin(theta),  theta' = w
from (5, 5, -2*pi/3) to the origin over t in [0, 5] while avoiding obstacles. The plan itself is
not published, so this script makes a plausible stand-in: the same unicycle driven by a pure-pursuit
steering law along a waypoint polyline that passes between the obstacles, with a smooth bell-shaped
speed profile (v = 0 at t = 0 and t = 5). Being an integrated unicycle trajectory, the heading is
always the direction of motion, as it would be for an MPC plan.

Usage:
    python3 specs/tools/unicycle_ref.py            # writes specs/unicycle_ref.csv, prints a summary
    python3 specs/tools/unicycle_ref.py --check    # also simulates the paper's tracking controller

Standard library only. Output: header `t,px,py,theta,qx,qy,qvx,qvy`, one row every 0.05 s for t in
[0, 5], 6 significant digits. `(qx, qy)` is the plan's look-ahead point p + L_Q (cos theta, sin theta)
(L_Q = 0.3) and `(qvx, qvy)` its velocity, the feedforward of specs/unicycle_lookahead.sde.
"""

import math
import os
import sys

T_END = 5.0
SAMPLE = 0.05
DT = 1e-3  # RK4 step of the integration

START = (5.0, 5.0, -2.0 * math.pi / 3.0)  # the vehicle's x0 (the spec's initial state)
# The plan starts LEAD ahead of the vehicle along its heading. Starting exactly on the vehicle
# would put the controller's atan2 at its singular point (zero position error) at t = 0, where
# the nominal trajectory depends on the convention atan2(0, 0) = 0 and sample paths turn in
# random directions: a discontinuity no contraction argument covers.
LEAD = 0.25
PLAN_START = (
    START[0] + LEAD * math.cos(START[2]),
    START[1] + LEAD * math.sin(START[2]),
    START[2],
)
# Waypoints of the plan: leave (5, 5) along the initial heading, pass left of obs2, then between
# obs3 (above) and obs1 (below), and come into the origin.
WAYPOINTS = [(5.0, 5.0), (4.15, 3.5), (3.1, 2.0), (1.5, 0.75), (0.0, 0.0)]
LOOKAHEAD = 0.8  # pure-pursuit look-ahead distance
V_START = 0.4  # speed at t = 0 and t = 5, relative to the peak
L_Q = 0.3  # look-ahead of the tracking point of specs/unicycle_lookahead.sde (its const l)

# Obstacles, mirrored in specs/unicycle.sde (keep the two in sync).
OBSTACLES = [
    ("obs1", "box", (2.4, 3.4, -0.3, 0.5)),  # px in [2.4, 3.4], py in [-0.3, 0.5]
    ("obs2", "ball", (4.4, 1.9, 0.5)),  # centre (4.4, 1.9), radius 0.5
    ("obs3", "box", (0.0, 0.8, 1.2, 2.0)),  # px in [0, 0.8], py in [1.2, 2.0]
]


def polyline():
    """Waypoints with a short extension past the goal (so the look-ahead never collapses)."""
    pts = list(WAYPOINTS)
    (ax, ay), (bx, by) = pts[-2], pts[-1]
    d = math.hypot(bx - ax, by - ay)
    pts.append((bx + (bx - ax) / d * 2 * LOOKAHEAD, by + (by - ay) / d * 2 * LOOKAHEAD))
    cum = [0.0]
    for (x0, y0), (x1, y1) in zip(pts, pts[1:]):
        cum.append(cum[-1] + math.hypot(x1 - x0, y1 - y0))
    return pts, cum


PTS, CUM = polyline()
PATH_LEN = CUM[len(WAYPOINTS) - 1]  # length up to the goal


def project(x, y):
    """Arc length of the closest point of the polyline to (x, y)."""
    best = (float("inf"), 0.0)
    for i, ((x0, y0), (x1, y1)) in enumerate(zip(PTS, PTS[1:])):
        dx, dy = x1 - x0, y1 - y0
        L2 = dx * dx + dy * dy
        s = max(0.0, min(1.0, ((x - x0) * dx + (y - y0) * dy) / L2))
        d = math.hypot(x0 + s * dx - x, y0 + s * dy - y)
        if d < best[0]:
            best = (d, CUM[i] + s * math.sqrt(L2))
    return best[1]


def point_at(s):
    s = max(0.0, min(s, CUM[-1]))
    for i in range(len(PTS) - 1):
        if s <= CUM[i + 1] or i == len(PTS) - 2:
            (x0, y0), (x1, y1) = PTS[i], PTS[i + 1]
            f = (s - CUM[i]) / (CUM[i + 1] - CUM[i])
            return x0 + f * (x1 - x0), y0 + f * (y1 - y0)


def wrap(a):
    return (a + math.pi) % (2 * math.pi) - math.pi


def plan_rhs(t, st, vpeak):
    x, y, th = st
    # Already moving at t = 0: a plan starting at rest leaves the tracking error, the argument
    # of the controller's atan2, at the noise level for the first second (see the spec).
    v = vpeak * (V_START + (1 - V_START) * math.sin(math.pi * t / T_END) ** 2)
    tx, ty = point_at(project(x, y) + LOOKAHEAD)
    eta = wrap(math.atan2(ty - y, tx - x) - th)
    w = v * 2.0 * math.sin(eta) / LOOKAHEAD  # pure pursuit: curvature 2 sin(eta) / L
    return (v * math.cos(th), v * math.sin(th), w)


def rk4(rhs, t, st, h, *args):
    k1 = rhs(t, st, *args)
    k2 = rhs(t + h / 2, [s + h / 2 * k for s, k in zip(st, k1)], *args)
    k3 = rhs(t + h / 2, [s + h / 2 * k for s, k in zip(st, k2)], *args)
    k4 = rhs(t + h, [s + h * k for s, k in zip(st, k3)], *args)
    return [s + h / 6 * (a + 2 * b + 2 * c + d) for s, a, b, c, d in zip(st, k1, k2, k3, k4)]


def simulate(rhs, start, *args):
    """Samples (t, state) every SAMPLE seconds on [0, T_END] from `start`."""
    st = list(start)
    per = round(SAMPLE / DT)
    n = round(T_END / DT)
    out = [(0.0, st)]
    for k in range(n):
        st = rk4(rhs, k * DT, st, DT, *args)
        if (k + 1) % per == 0:
            out.append(((k + 1) * DT, st))
    return out


def make_plan():
    # The speed peak is tuned (secant method) so that the plan ends at the origin at t = 5.
    def miss(vpeak):
        x, y, _ = simulate(plan_rhs, PLAN_START, vpeak)[-1][1]
        return project(x, y) - PATH_LEN

    mean = V_START + (1 - V_START) / 2  # mean speed over [0, T_END], relative to the peak
    a, b = PATH_LEN / (T_END * mean) * 0.9, PATH_LEN / (T_END * mean) * 1.1
    fa, fb = miss(a), miss(b)
    for _ in range(30):
        if abs(fb) < 1e-9 or fa == fb:
            break
        a, b, fa = b, b - fb * (b - a) / (fb - fa), fb
        fb = miss(b)
    return simulate(plan_rhs, PLAN_START, b), b


def clearance(x, y, obs):
    _, kind, p = obs
    if kind == "box":
        x0, x1, y0, y1 = p
        dx = max(x0 - x, 0.0, x - x1)
        dy = max(y0 - y, 0.0, y - y1)
        return math.hypot(dx, dy) if (dx > 0 or dy > 0) else -min(x - x0, x1 - x, y - y0, y1 - y)
    cx, cy, r = p
    return math.hypot(x - cx, y - cy) - r


def min_clearance(samples):
    """Minimum distance from the polyline through the samples (refined 20x) to each obstacle."""
    res = {}
    for o in OBSTACLES:
        best = (float("inf"), 0.0)
        for (t0, s0), (t1, s1) in zip(samples, samples[1:]):
            for j in range(20):
                f = j / 20
                d = clearance(s0[0] + f * (s1[0] - s0[0]), s0[1] + f * (s1[1] - s0[1]), o)
                if d < best[0]:
                    best = (d, t0 + f * (t1 - t0))
        res[o[0]] = best
    return res


def interp(samples, t):
    """The table semantics of reachc: linear interpolation, constant outside the range."""
    if t <= samples[0][0]:
        return samples[0][1]
    if t >= samples[-1][0]:
        return samples[-1][1]
    k = min(int(t / SAMPLE), len(samples) - 2)
    (t0, a), (t1, b) = samples[k], samples[k + 1]
    f = (t - t0) / (t1 - t0)
    return [p + f * (q - p) for p, q in zip(a, b)]


def tracking_rhs(t, st, table):
    """Paper eq. (polar controller) with K_r = -0.8, K_alpha = -1.5, u = 0 (spec's nominal)."""
    px, py, th = st
    rx, ry, rth = interp(table, t)
    kr, ka = -0.8, -1.5
    r = math.hypot(px - rx, py - ry)
    phi = math.atan2(py - ry, px - rx)
    alpha = th - phi
    beta = phi - rth
    sinc = math.sin(alpha) / alpha if alpha != 0 else 1.0
    v = kr * r * math.cos(alpha)
    w = ka * alpha + kr * sinc * math.cos(alpha) * (alpha + beta)
    return (v * math.cos(th), v * math.sin(th), w)


def lookahead_columns(t, st, vpeak):
    """The look-ahead point q = p + L_Q (cos theta, sin theta) of the plan and its velocity."""
    x, y, th = st
    dx, dy, w = plan_rhs(t, st, vpeak)
    c, s = math.cos(th), math.sin(th)
    return [x + L_Q * c, y + L_Q * s, dx - L_Q * w * s, dy + L_Q * w * c]


def main():
    samples, vpeak = make_plan()
    table = [(t, [float("%.6g" % c) for c in s]) for t, s in samples]
    here = os.path.dirname(os.path.abspath(__file__))
    out = os.path.join(here, "..", "unicycle_ref.csv")
    with open(out, "w") as f:
        f.write("t,px,py,theta,qx,qy,qvx,qvy\n")
        for (t, s), (_, exact) in zip(table, samples):
            row = [round(t, 10)] + s + lookahead_columns(t, exact, vpeak)
            f.write(",".join("%.6g" % (c + 0.0) for c in row) + "\n")  # no "-0"
    print("wrote %s (%d rows), peak speed %.4f" % (os.path.normpath(out), len(table), vpeak))
    x, y, th = samples[-1][1]
    print("end state at t = 5: (%.4f, %.4f, %.4f), distance to origin %.2e"
          % (x, y, th, math.hypot(x, y)))
    ths = [s[2] for _, s in samples]
    print("heading range [%.4f, %.4f]" % (min(ths), max(ths)))
    for name, (d, t) in min_clearance(table).items():
        print("reference: min clearance to %s = %.3f at t = %.2f" % (name, d, t))
    if "--check" in sys.argv:
        closed = simulate(tracking_rhs, START, table)
        err = max(math.hypot(s[0] - r[0], s[1] - r[1]) for (_, s), (_, r) in zip(closed, table))
        print("closed loop (u = 0, no noise): max position error to reference %.4f" % err)
        for name, (d, t) in min_clearance(closed).items():
            print("closed loop: min clearance to %s = %.3f at t = %.2f" % (name, d, t))


if __name__ == "__main__":
    main()
