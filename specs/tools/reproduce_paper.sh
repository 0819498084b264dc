#!/usr/bin/env bash
# Regenerates docs/paper/ (figures and Monte Carlo reports of docs/paper-reproduction.md) from
# the shipped specs: the paper's Fig. 4 (linear, 5000 paths), Fig. 6 (pendulum, contraction
# and interval, 2000 paths) and Fig. 7 (unicycle: the paper's empirical rate, and the rigorous
# look-ahead controller next to it, 200 paths). Fig. 5 is `python3 specs/tools/linear_fig5.py`
# (longer).
# Usage: bash specs/tools/reproduce_paper.sh [REACHC]   (default: cargo run --release)
set -euo pipefail
cd "$(dirname "$0")/../.."
out=docs/paper
reachc=${1:-}
if [ -z "$reachc" ]; then
    cargo build --release -q -p reachc
    reachc=target/release/reachc
fi
# Fig. 4: linear, n = 2, delta = 1e-3, both radius rules; the quantile from 5000 paths.
"$reachc" simulate specs/linear.sde --paths 5000 --seed 1 --backend interp -o "$out/linear" -q
"$reachc" run specs/linear.sde --backend interp -o "$out/linear" > /dev/null
for a in paper_rule amgf_rule; do
    "$reachc" plot "$out/linear/$a.json" --spec specs/linear.sde --times 0.5,1,1.5 \
        --paths 50 > /dev/null
done

# Fig. 6: pendulum, contraction (left) and interval in y = T x (right), t = 1, 2, 4, 2000 paths:
# the paper's set-up (paper_*: pointwise, the interval method with the paper's Euler step) and
# reachc's defaults beside it (validated steps, time-uniform tube).
"$reachc" simulate specs/pendulum.sde --paths 2000 --seed 1 --backend interp -o "$out/pendulum" -q
"$reachc" run specs/pendulum.sde --backend interp -o "$out/pendulum" > /dev/null
for a in paper_contraction paper_interval contraction interval per_state; do
    "$reachc" plot "$out/pendulum/$a.json" --spec specs/pendulum.sde --times 1,2,4 \
        --paths 50 > /dev/null
done

# Fig. 7: unicycle with the paper's controller and its empirical c_t (NOT a guarantee), and the
# look-ahead controller, empirical and certified (rigorous). Sets at t = 1, 2.5, 4 and the union
# of the PRS over [0, 5], 200 sample paths; the rigorous PRS only at t = 0.03, 0.06, 0.09 (it is
# vacuous later).
for spec in unicycle unicycle_lookahead; do
    "$reachc" simulate "specs/$spec.sde" --paths 2000 --seed 1 --backend interp -o "$out/$spec" -q
    "$reachc" run "specs/$spec.sde" --backend interp -o "$out/$spec" > /dev/null
    "$reachc" plot "$out/$spec/empirical.json" --spec "specs/$spec.sde" --times 1,2.5,4 \
        --paths 200 --envelope > /dev/null
done
"$reachc" plot "$out/unicycle_lookahead/contraction.json" --spec specs/unicycle_lookahead.sde \
    --times 0.03,0.09,0.2 --paths 200 > /dev/null
echo "wrote $out/linear, $out/pendulum, $out/unicycle and $out/unicycle_lookahead"
