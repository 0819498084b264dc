#!/usr/bin/env python3
"""reachc from Python on the paper's pendulum (specs/pendulum.sde), in one Python process:
import + first result, then the time per reach of the Euler interval analysis
(`analysis paper_interval`: Jacobian inclusion, y = T x, explicit Euler, step 0.01, horizon 4)
through one `Reach` handle. immrax's figures for the same analysis are read from
bench/results/immrax_pendulum.json (bench/immrax_pendulum.py); with --immrax, and immrax
importable in this interpreter, its jit-compiled reach is also timed here, in this process.

    python bench/python_pendulum.py [--reps 1000] [--json OUT] [--immrax]
"""

import time

_T0 = time.perf_counter()  # before any heavy import

import reachc  # noqa: E402

_T_IMPORT = time.perf_counter()

import argparse  # noqa: E402
import json  # noqa: E402
import math  # noqa: E402
import os  # noqa: E402
import platform  # noqa: E402
import statistics  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))
SPEC = os.path.join(HERE, "..", "specs", "pendulum.sde")
ANALYSIS = "paper_interval"


def first_result():
    spec = reachc.load(SPEC)
    t_load = time.perf_counter()
    reach = spec.reach(ANALYSIS)
    res = reach.run()
    t_first = time.perf_counter()
    return spec, reach, res, t_load, t_first


def per_call(f, reps, warmup):
    for _ in range(warmup):
        f()
    times = []
    for _ in range(reps):
        t = time.perf_counter()
        f()
        times.append(time.perf_counter() - t)
    times.sort()
    return {
        "median": statistics.median(times),
        "p10": times[len(times) // 10],
        "p90": times[(9 * len(times)) // 10],
        "min": times[0],
        "reps": reps,
    }


def immrax_here(reps):
    """immrax's jit-compiled Euler reach (jacif on the hand-simplified system, scan driver),
    timed in this process; None if immrax is not importable."""
    try:
        t = time.perf_counter()
        import jax

        jax.config.update("jax_enable_x64", True)
        import immrax as irx
        import jax.numpy as jnp
    except ImportError:
        return None
    t_import = time.perf_counter() - t

    class Simplified(irx.System):
        """bench/immrax_pendulum.py's hand-simplified y = T x system."""

        def __init__(self):
            super().__init__("continuous", 2)

        def f(self, t, y):
            return jnp.array(
                [-15.0 * y[0] + 11.0 * y[1] + 2.0 * jnp.sin(y[1]), 5.0 * y[0] - 5.0 * y[1]]
            )

    emb = irx.jacemb(Simplified())
    a, b = math.pi / 10 + 0.04, math.pi / 10
    x0 = irx.i2ut(irx.interval(jnp.array([-a, -b]), jnp.array([a, b])))

    @jax.jit
    def reach(x):
        def step(x, k):
            x = x + 0.01 * emb.E(k * 0.01, x)
            return x, x

        return jax.lax.scan(step, x, jnp.arange(400))[1]

    t = time.perf_counter()
    reach(x0).block_until_ready()
    t_first = time.perf_counter() - t
    stats = per_call(lambda: reach(x0).block_until_ready(), reps, 50)
    return {"import_s": t_import, "first_call_s": t_first, "per_reach_s": stats}


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--reps", type=int, default=1000)
    ap.add_argument("--json", help="write the figures here")
    ap.add_argument("--immrax", action="store_true", help="time immrax in this process too")
    args = ap.parse_args()
    spec, reach, res, t_load, t_first = first_result()
    assert res.analysis == ANALYSIS and res.times.shape == (401,)
    out = {
        "reachc": reachc.__version__,
        "python": platform.python_version(),
        "machine": platform.machine(),
        "import_s": _T_IMPORT - _T0,
        "load_s": t_load - _T_IMPORT,
        "import_to_first_result_s": t_first - _T0,
        "per_reach_s": per_call(reach.run, args.reps, 20),
        "per_reach_with_arrays_s": per_call(lambda: reach.run().hi, args.reps // 4, 5),
    }
    box = spec.initial_box
    boxes = [box * s for s in (0.25, 0.5, 1.0)] * 34
    t = time.perf_counter()
    reach.sweep(boxes[:100])
    out["sweep_100_boxes_s"] = time.perf_counter() - t
    ref = os.path.join(HERE, "results", "immrax_pendulum.json")
    if os.path.exists(ref):
        with open(ref) as f:
            d = json.load(f)
        for r in d["results"]:
            if (r["form"], r["inclusion"], r["driver"]) in (
                ("simplified", "jacif", "scan"),
                ("composed", "jacif", "scan"),
            ):
                ts = r["timing_s"]
                out[f"immrax_{r['form']}_jacif_recorded"] = {
                    "import_s": ts["import_total"],
                    "process_start_to_first_result_s": ts["process_start_to_first_result"],
                    "per_reach_median_s": ts["steady_per_reach"]["median"],
                }
    if args.immrax:
        out["immrax_here"] = immrax_here(args.reps)
    print(json.dumps(out, indent=2))
    if args.json:
        with open(args.json, "w") as f:
            json.dump(out, f, indent=2)


if __name__ == "__main__":
    main()
