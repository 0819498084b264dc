#!/usr/bin/env python3
"""The paper's Figure 5 (Sec. VIII-A) with reachc: r_t^2 at t = 1.5 against log(1/delta) and
against n for dX = -0.4 X dt + sqrt(2) dW, X0 = 0 (specs/linear_n.sde resized), for both radius
rules (paper eps = 1/16, amgf), next to the simulated (1 - delta) quantile of |X_t|^2 from
`reachc simulate` and the exact quantile (X_t is Gaussian: |X_t|^2 / v_t is chi-square(n),
v_t = 2 (1 - e^{-0.8 t}) / 0.8).

Usage: python3 specs/tools/linear_fig5.py [--reachc PATH] [--paths N] [--out CSV]
Standard library only. Writes one CSV row per (n, delta).
"""

import argparse
import csv
import json
import math
import pathlib
import subprocess
import tempfile

ROOT = pathlib.Path(__file__).resolve().parents[2]
T = 1.5


def chi2_cdf(x, k):
    """Regularised lower incomplete gamma P(k/2, x/2) by its series (x moderate)."""
    a, z = k / 2.0, x / 2.0
    if z <= 0:
        return 0.0
    term = 1.0 / a
    total = term
    n = 0
    while term > 1e-17 * total:
        n += 1
        term *= z / (a + n)
        total += term
    return min(1.0, math.exp(-z + a * math.log(z) - math.lgamma(a)) * total)


def chi2_quantile(p, k):
    lo, hi = 0.0, max(10.0, 10.0 * k)
    while chi2_cdf(hi, k) < p:
        hi *= 2
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        if chi2_cdf(mid, k) < p:
            lo = mid
        else:
            hi = mid
    return hi


def spec(n, delta, directory):
    text = (ROOT / "specs" / "linear_n.sde").read_text()
    text = text.replace("const N = 10 ", f"const N = {n} ", 1)
    text = text.replace("delta = 1e-3", f"delta = {delta}")
    path = pathlib.Path(directory) / f"linear_n{n}_d{delta}.sde"
    path.write_text(text)
    return path


def run(cmd):
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--reachc", default=str(ROOT / "target/release/reachc"))
    ap.add_argument("--paths", type=int, default=10**6)
    ap.add_argument("--out", default=str(ROOT / "docs/paper/fig5.csv"))
    args = ap.parse_args()
    v_t = 2.0 * (1.0 - math.exp(-0.8 * T)) / 0.8
    rows = []
    cases = [(2, d) for d in (1e-1, 1e-2, 1e-3, 1e-4, 1e-5)]
    cases += [(n, 1e-3) for n in (1, 4, 8, 16, 32)]
    with tempfile.TemporaryDirectory() as tmp:
        for n, delta in cases:
            path = spec(n, delta, tmp)
            out = pathlib.Path(tmp) / f"out_{n}_{delta}"
            run([args.reachc, "run", str(path), "--backend", "interp", "-o", str(out)])
            r2 = {}
            for rule in ("paper_rule", "amgf_rule"):
                res = json.loads((out / f"{rule}.json").read_text())
                r2[rule] = res["steps"][-1]["r_t"] ** 2
            run([args.reachc, "simulate", str(path), "--analysis", "amgf_rule",
                 "--paths", str(args.paths), "--seed", "1", "--delta", str(delta),
                 "-o", str(out), "-q"])
            sim = json.loads((out / "amgf_rule.sim.json").read_text())
            q = sim["steps"][-1]["quantile"] ** 2
            exact = v_t * chi2_quantile(1.0 - delta, n)
            rows.append({"n": n, "delta": delta,
                         "r2_paper_eps_1_16": r2["paper_rule"], "r2_amgf": r2["amgf_rule"],
                         "simulated_quantile2": q, "exact_quantile2": exact,
                         "paths": args.paths})
            print(f"n = {n:3d}, delta = {delta:g}: r^2 paper {r2['paper_rule']:.3f}, "
                  f"amgf {r2['amgf_rule']:.3f}, simulated {q:.3f}, exact {exact:.3f}")
    out_path = pathlib.Path(args.out)
    out_path.parent.mkdir(parents=True, exist_ok=True)
    with out_path.open("w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    print(f"wrote {out_path}")


if __name__ == "__main__":
    main()
