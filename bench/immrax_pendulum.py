#!/usr/bin/env python3
"""immrax side of the reachc/immrax comparison on the paper's inverted pendulum (Sec. VIII-B).

System (x = (theta, omega)):
    theta' = omega
    omega' = 10 sin(theta) - 20 theta - 20 omega          (g/L = 10, K = [-20, -20])
analysed in the coordinates y = T x, T = [[1, 0.2], [1, 0]], i.e. y' = T f(T^-1 y), with
immrax's face-pinned embedding system ("InclusionEmbedding": the lower bound of y_i' is the
inclusion function's lower bound on the face y_i = y_lo_i, the upper bound on y_i = y_hi_i),
integrated with explicit Euler, step 0.01, horizon 4 (400 steps), in float64.

Variants (each measured in its own fresh Python process, one after the other):
  form       composed    immrax.LinearTransformedSystem(PendulumX(), T): y' = T f(T^-1 y) as
                         written (matrix products; no simplification), T^-1 = jnp.linalg.inv(T)
             simplified  the same field simplified by hand:
                         y1' = -15 y1 + 11 y2 + 2 sin(y2),  y2' = 5 y1 - 5 y2
  inclusion  natif (natural), jacif (Jacobian-based), mjacif (mixed Jacobian-based), applied as
             immrax.natemb / jacemb / mjacemb (= TransformEmbedding(sys, if_transform=...))
  driver     scan        jax.lax.scan of x <- x + dt * embsys.E(t, x) (as immrax's own
                         examples/pendulum/example.py rolls its embedding system out)
             diffrax     embsys.compute_trajectory(0., 4., x0, dt=0.01, solver="euler")
                         (immrax's System API; diffrax Euler, 4096-row padded output)
  box        hull        the interval hull of T X0, X0 = [-pi/10, pi/10] x [-0.2, 0.2],
                         rounded outward by one ulp: y1 in +-(pi/10 + 0.04), y2 in +-pi/10
             paper       the paper's Y0 = +-(pi/10) (1.04, 1)

Usage (see bench/README.md):
    /work/venvs/immrax/bin/python bench/immrax_pendulum.py            # everything, ~4 min
    /work/venvs/immrax/bin/python bench/immrax_pendulum.py --quick    # fewer repetitions
    /work/venvs/immrax/bin/python bench/immrax_pendulum.py --child composed jacif scan
        # one variant in this process; prints one JSON object (used by the parent run)
"""

import time

_MONO_AT_SCRIPT = time.monotonic()  # before any heavy import
_PERF_AT_SCRIPT = time.perf_counter()

import argparse  # noqa: E402
import json  # noqa: E402
import math  # noqa: E402
import os  # noqa: E402
import platform  # noqa: E402
import statistics  # noqa: E402
import subprocess  # noqa: E402
import sys  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))
DEFAULT_OUT = os.path.join(HERE, "results", "immrax_pendulum.json")

G_OVER_L = 10.0
K1, K2 = -20.0, -20.0
T_MATRIX = [[1.0, 0.2], [1.0, 0.0]]
DT = 0.01
HORIZON = 4.0
NSTEPS = 400
REPORT_TIMES = (1.0, 2.0, 4.0)

FORMS = ("composed", "simplified")
INCLUSIONS = ("natif", "jacif", "mjacif")
DRIVERS = ("scan", "diffrax")


def initial_boxes():
    """The two initial y-boxes as (lo, hi) lists of Python floats."""
    up = lambda v: math.nextafter(v, math.inf)  # noqa: E731
    p10 = up(math.pi / 10)  # math.pi < pi, so pi/10 rounded up once more
    y1 = up(p10 + up(0.2 * 0.2))  # |theta + 0.2 omega| <= pi/10 + 0.04
    hull = ([-y1, -p10], [y1, p10])
    q = math.pi / 10
    paper = ([-q * 1.04, -q], [q * 1.04, q])
    return {"hull": hull, "paper": paper}


# --------------------------------------------------------------------------------------
# process / machine facts (no jax needed)
# --------------------------------------------------------------------------------------


def process_age_s():
    """Seconds since this process was started (kernel accounting, 10 ms resolution)."""
    try:
        with open("/proc/self/stat") as f:
            fields = f.read().rsplit(")", 1)[1].split()
        start_ticks = int(fields[19])  # field 22 of stat(5); fields[0] is field 3
        boot_now = time.clock_gettime(time.CLOCK_BOOTTIME)
        return boot_now - start_ticks / os.sysconf("SC_CLK_TCK")
    except (OSError, ValueError, IndexError, AttributeError):
        return None


def machine_facts():
    facts = {
        "platform": platform.platform(),
        "python": platform.python_version(),
        "nproc": os.cpu_count(),
    }
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("model name"):
                    facts["cpu"] = line.split(":", 1)[1].strip()
                    break
    except OSError:
        pass
    try:
        with open("/proc/meminfo") as f:
            for line in f:
                if line.startswith("MemTotal"):
                    facts["mem_total_kib"] = int(line.split()[1])
                    break
    except OSError:
        pass
    try:
        facts["loadavg"] = list(os.getloadavg())
    except OSError:
        pass
    for var in ("OPENBLAS_CORETYPE", "XLA_FLAGS", "JAX_PLATFORMS", "JAX_COMPILATION_CACHE_DIR"):
        if os.environ.get(var):
            facts[var] = os.environ[var]
    return facts


# --------------------------------------------------------------------------------------
# child: one variant, measured in this (fresh) process
# --------------------------------------------------------------------------------------


def run_child(form, inclusion, driver, reps, warmup):
    age_at_script = process_age_s()

    # --- import (timed) -------------------------------------------------------------
    t0 = time.perf_counter()
    import jax
    import jax.numpy as jnp

    jax.config.update("jax_enable_x64", True)  # reachc works in f64; immrax defaults to f32
    t_jax = time.perf_counter()
    import immrax as irx

    t_imported = time.perf_counter()
    import numpy as np

    compile_events = {}

    def listener(event, duration, **_kw):
        if event.startswith("/jax/core/compile") or event.startswith("/jax/compilation_cache"):
            compile_events[event] = compile_events.get(event, 0.0) + float(duration)

    jax.monitoring.register_event_duration_secs_listener(listener)

    # --- the systems ----------------------------------------------------------------
    class PendulumX(irx.System):
        """x = (theta, omega): theta' = omega, omega' = g/L sin(theta) + K1 theta + K2 omega."""

        def __init__(self):
            super().__init__("continuous", 2)

        def f(self, t, x):
            theta, omega = x[0], x[1]
            return jnp.array([omega, G_OVER_L * jnp.sin(theta) + K1 * theta + K2 * omega])

    class PendulumYSimplified(irx.System):
        """y = T x with T = [[1, 0.2], [1, 0]]: theta = y2, omega = 5 (y1 - y2), and
        y1' = omega + 0.2 omega' = -15 y1 + 11 y2 + 2 sin(y2),  y2' = omega = 5 y1 - 5 y2."""

        def __init__(self):
            super().__init__("continuous", 2)

        def f(self, t, y):
            return jnp.array(
                [-15.0 * y[0] + 11.0 * y[1] + 2.0 * jnp.sin(y[1]), 5.0 * y[0] - 5.0 * y[1]]
            )

    T = jnp.array(T_MATRIX)
    if form == "composed":
        sys_y = irx.LinearTransformedSystem(PendulumX(), T)
    elif form == "simplified":
        sys_y = PendulumYSimplified()
    else:
        raise SystemExit(f"unknown form {form!r}")

    embed = {"natif": irx.natemb, "jacif": irx.jacemb, "mjacif": irx.mjacemb}[inclusion]
    embsys = embed(sys_y)

    if driver == "scan":

        def reach(x0ut):
            def step(x, k):
                xn = x + DT * embsys.E(k * DT, x)
                return xn, xn

            _, xs = jax.lax.scan(step, x0ut, jnp.arange(NSTEPS))
            ts = jnp.arange(NSTEPS + 1) * DT
            return ts, jnp.concatenate([x0ut[None], xs])

    elif driver == "diffrax":

        def reach(x0ut):
            traj = embsys.compute_trajectory(0.0, HORIZON, x0ut, dt=DT, solver="euler")
            return traj.ts, traj.ys

    else:
        raise SystemExit(f"unknown driver {driver!r}")

    reach_jit = jax.jit(reach)
    boxes = initial_boxes()
    x0 = {
        name: irx.i2ut(irx.interval(jnp.array(lo), jnp.array(hi)))
        for name, (lo, hi) in boxes.items()
    }
    t_setup = time.perf_counter()

    # --- first result: trace + lower + compile + run --------------------------------
    out = reach_jit(x0["hull"])
    jax.block_until_ready(out)
    t_first = time.perf_counter()
    mono_first = time.monotonic()
    age_at_first = process_age_s()
    first_events = dict(compile_events)

    # the paper's box: same shapes, so no new compile (checked through the events)
    n_events = len(compile_events)
    out_paper = reach_jit(x0["paper"])
    jax.block_until_ready(out_paper)
    recompiled = compile_events != first_events or len(compile_events) != n_events

    # --- steady state ---------------------------------------------------------------
    for _ in range(warmup):
        jax.block_until_ready(reach_jit(x0["hull"]))
    samples = []
    for _ in range(reps):
        a = time.perf_counter()
        jax.block_until_ready(reach_jit(x0["hull"]))
        samples.append(time.perf_counter() - a)
    batch_per_reach = cpu_per_reach = None
    if reps > 0:
        # back to back, and the process's CPU time (all threads): less sensitive than wall
        # time to other work on a shared machine
        a, c = time.perf_counter(), time.process_time()
        for _ in range(reps):
            jax.block_until_ready(reach_jit(x0["hull"]))
        batch_per_reach = (time.perf_counter() - a) / reps
        cpu_per_reach = (time.process_time() - c) / reps
    samples.sort()

    def q(p):
        return samples[min(len(samples) - 1, int(p * len(samples)))] if samples else None

    steady = statistics.median(samples) if samples else None

    # --- boxes at the report times --------------------------------------------------
    def extract(res):
        ts, ys = (np.asarray(v) for v in res)
        finite = np.isfinite(ts)
        ts, ys = ts[finite], ys[finite]
        rec = {"n_points": int(ts.size), "t_last": float(ts[-1])}
        at = {}
        for tq in REPORT_TIMES:
            k = int(np.argmin(np.abs(ts - tq)))
            lo, hi = ys[k, :2], ys[k, 2:]
            at[f"{tq:g}"] = {
                "t": float(ts[k]),
                "step": k,
                "lo": [float(v) for v in lo],
                "hi": [float(v) for v in hi],
                "half_width": [float(v) for v in (hi - lo) / 2],
                "center": [float(v) for v in (hi + lo) / 2],
            }
        rec["at"] = at
        rec["finite"] = bool(np.all(np.isfinite(ys)))
        return rec

    result = {
        "form": form,
        "inclusion": inclusion,
        "driver": driver,
        "boxes": {"hull": extract(out), "paper": extract(out_paper)},
        "timing_s": {
            "python_startup_to_script": age_at_script,
            "import_jax": t_jax - t0,
            "import_immrax": t_imported - t_jax,
            "import_total": t_imported - t0,
            "setup_systems": t_setup - t_imported,
            "first_call": t_first - t_setup,
            "first_call_compile_events": first_events,
            "jit_overhead": None if steady is None else (t_first - t_setup) - steady,
            "script_start_to_first_result": t_first - _PERF_AT_SCRIPT,
            "process_start_to_first_result_proc": age_at_first,
            "mono_first_result": mono_first,
            "paper_box_recompiled": recompiled,
            "steady_per_reach": {
                "median": steady,
                "p10": q(0.10),
                "p90": q(0.90),
                "min": q(0.0),
                "max": q(1.0),
                "mean_of_back_to_back_batch": batch_per_reach,
                "cpu_time_of_back_to_back_batch": cpu_per_reach,
                "reps": reps,
                "warmup": warmup,
            },
        },
        "details": {
            "x64": bool(jax.config.jax_enable_x64),
            "dtype": str(np.asarray(out[1]).dtype),
            "compilation_cache_dir": jax.config.jax_compilation_cache_dir,
            "devices": [str(d) for d in jax.devices()],
        },
    }
    if form == "composed":
        result["details"]["Tinv_used"] = np.asarray(sys_y.Tinv).tolist()
    return result


# --------------------------------------------------------------------------------------
# parent: run every variant in a fresh process, aggregate, print, write JSON
# --------------------------------------------------------------------------------------


def versions():
    """Versions from the package metadata, without importing jax in the parent."""
    from importlib import metadata

    out = {}
    for pkg in ("immrax", "jax", "jaxlib", "diffrax", "equinox", "numpy"):
        try:
            out[pkg] = metadata.version(pkg)
        except metadata.PackageNotFoundError:
            out[pkg] = None
    return out


def spawn_child(form, inclusion, driver, reps, warmup):
    cmd = [
        sys.executable,
        os.path.abspath(__file__),
        "--child",
        form,
        inclusion,
        driver,
        "--reps",
        str(reps),
        "--warmup",
        str(warmup),
    ]
    env = dict(os.environ)
    env.pop("JAX_COMPILATION_CACHE_DIR", None)  # every child compiles from scratch
    mono_spawn = time.monotonic()
    proc = subprocess.run(cmd, capture_output=True, text=True, env=env)
    mono_done = time.monotonic()
    if proc.returncode != 0:
        return {
            "form": form,
            "inclusion": inclusion,
            "driver": driver,
            "error": f"exit {proc.returncode}: {proc.stderr.strip()[-2000:]}",
        }
    res = json.loads(proc.stdout.strip().splitlines()[-1])
    tm = res["timing_s"]
    # spawn -> first box ready, measured on the shared monotonic clock: includes exec of the
    # interpreter, its startup, the imports, tracing, compiling and the first run
    tm["process_start_to_first_result"] = tm.pop("mono_first_result") - mono_spawn
    tm["child_wall_total"] = mono_done - mono_spawn
    return res


def _agg(values, key):
    values = [v for v in values if v is not None]
    if not values:
        return None
    if all(isinstance(v, bool) for v in values):
        return any(values)
    if all(isinstance(v, (int, float)) for v in values):
        if key == "min":
            return min(values)
        if key == "max":
            return max(values)
        return statistics.median(values)
    if all(isinstance(v, dict) for v in values):
        keys = set().union(*values)
        return {k: _agg([v[k] for v in values if k in v], k) for k in sorted(keys)}
    return values[0]


def aggregate_rounds(rounds):
    """One record per variant: boxes of the first good round (all rounds must agree), timings
    as the median over rounds (min/max: the extreme), the raw timings of every round kept."""
    good = [r for r in rounds if "error" not in r]
    if not good:
        return rounds[0]
    res = dict(good[0])
    res["rounds"] = len(good)
    res["boxes_identical_across_rounds"] = all(r["boxes"] == good[0]["boxes"] for r in good)
    res["timing_s"] = _agg([r["timing_s"] for r in good], "")
    res["timing_s_per_round"] = [r["timing_s"] for r in good]
    res["failed_rounds"] = [r["error"] for r in rounds if "error" in r]
    return res


def fmt_hw(hw):
    return "(" + ", ".join(f"{v:.6g}" for v in hw) + ")"


def ms(v):
    return "-" if v is None else f"{1e3 * v:.3g} ms"


def print_tables(doc):
    res = [r for r in doc["results"] if "error" not in r]
    print()
    print(f"immrax {doc['versions']['immrax']}, jax {doc['versions']['jax']}, float64, "
          f"Euler dt={DT}, {NSTEPS} steps, face-pinned embedding")
    for box in ("hull", "paper"):
        lo, hi = doc["setup"]["initial_boxes"][box]
        print()
        print(f"Initial box '{box}': y1 in [{lo[0]:.17g}, {hi[0]:.17g}], "
              f"y2 in [{lo[1]:.17g}, {hi[1]:.17g}]")
        print("| form | inclusion | hw t=1 | hw t=2 | hw t=4 |")
        print("|---|---|---|---|---|")
        for r in res:
            if r["driver"] != "scan":
                continue
            at = r["boxes"][box]["at"]
            cells = [fmt_hw(at[k]["half_width"]) for k in ("1", "2", "4")]
            print(f"| {r['form']} | {r['inclusion']} | " + " | ".join(cells) + " |")
    print()
    print(f"Timings (each variant in {doc['setup']['rounds']} fresh process(es), interleaved; medians "
          "over them; steady state = median of repeated reaches)")
    print("| form | inclusion | driver | import | first result (proc start) | first call | "
          "XLA compile | steady/reach (median) | p10-p90 | min | CPU/reach |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    for r in res:
        tm = r["timing_s"]
        st = tm["steady_per_reach"]
        comp = tm["first_call_compile_events"].get("/jax/core/compile/backend_compile_duration")
        print(
            f"| {r['form']} | {r['inclusion']} | {r['driver']} | {tm['import_total']:.2f} s | "
            f"{tm['process_start_to_first_result']:.2f} s | {tm['first_call']:.2f} s | "
            f"{'-' if comp is None else f'{comp:.2f} s'} | {ms(st['median'])} | "
            f"{ms(st['p10'])} - {ms(st['p90'])} | {ms(st['min'])} | "
            f"{ms(st['cpu_time_of_back_to_back_batch'])} |"
        )
    for r in doc["results"]:
        if "error" in r:
            print(f"ERROR {r['form']}/{r['inclusion']}/{r['driver']}: {r['error']}")
    chk = doc.get("checks", {})
    if chk:
        print()
        for k, v in chk.items():
            print(f"check {k}: {v}")


def cross_checks(results):
    """Drivers must agree; forms must agree for jacif/mjacif."""
    ok = [r for r in results if "error" not in r]
    by = {(r["form"], r["inclusion"], r["driver"]): r for r in ok}
    out = {}
    worst = 0.0
    for (form, inc, drv), r in by.items():
        other = by.get((form, inc, "diffrax" if drv == "scan" else "scan"))
        if other is None or drv != "scan":
            continue
        for box in ("hull", "paper"):
            for k, a in r["boxes"][box]["at"].items():
                b = other["boxes"][box]["at"][k]
                for x, y in zip(a["lo"] + a["hi"], b["lo"] + b["hi"]):
                    d = abs(x - y)
                    if math.isfinite(d):
                        worst = max(worst, d / max(1.0, abs(x)))
    out["scan_vs_diffrax_max_rel_diff"] = worst
    t_dev = 0.0
    for r in ok:
        for box in ("hull", "paper"):
            for k, a in r["boxes"][box]["at"].items():
                t_dev = max(t_dev, abs(a["t"] - float(k)))
    out["max_report_time_deviation"] = t_dev
    out["boxes_identical_across_rounds"] = all(
        r.get("boxes_identical_across_rounds", True) for r in ok
    )
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--child", nargs=3, metavar=("FORM", "INCLUSION", "DRIVER"))
    ap.add_argument("--reps", type=int, default=1000, help="timed reaches per process")
    ap.add_argument("--warmup", type=int, default=100, help="untimed reaches first")
    ap.add_argument("--rounds", type=int, default=3, help="fresh processes per variant")
    ap.add_argument("--quick", action="store_true", help="--reps 200 --warmup 20 --rounds 1")
    ap.add_argument("--forms", default=",".join(FORMS))
    ap.add_argument("--inclusions", default=",".join(INCLUSIONS))
    ap.add_argument("--drivers", default=",".join(DRIVERS))
    ap.add_argument("-o", "--out", default=DEFAULT_OUT)
    args = ap.parse_args()
    if args.quick:
        args.reps, args.warmup, args.rounds = 200, 20, 1

    if args.child:
        form, inclusion, driver = args.child
        res = run_child(form, inclusion, driver, args.reps, args.warmup)
        print(json.dumps(res))
        return

    facts_before = machine_facts()
    variants = [
        (form, inclusion, driver)
        for form in args.forms.split(",")
        for inclusion in args.inclusions.split(",")
        for driver in args.drivers.split(",")
    ]
    # rounds are interleaved (every variant once per round) so that a burst of load from
    # other work on the machine hits all variants alike; timings are aggregated over rounds
    runs = {v: [] for v in variants}
    for rnd in range(args.rounds):
        for v in variants:
            print(f"round {rnd + 1}/{args.rounds}: {'/'.join(v)} ...", file=sys.stderr, flush=True)
            runs[v].append(spawn_child(*v, args.reps, args.warmup))
    results = [aggregate_rounds(runs[v]) for v in variants]
    facts = machine_facts()
    facts["loadavg_before"] = facts_before.get("loadavg")

    boxes = initial_boxes()
    doc = {
        "tool": "immrax",
        "system": "inverted pendulum (paper Sec. VIII-B), theta' = omega, omega' = 10 sin(theta)"
        " - 20 theta - 20 omega, in y = T x with T = [[1, 0.2], [1, 0]]",
        "versions": versions(),
        "machine": facts,
        "setup": {
            "T": T_MATRIX,
            "dt": DT,
            "horizon": HORIZON,
            "steps": NSTEPS,
            "report_times": list(REPORT_TIMES),
            "rounds": args.rounds,
            "reps_per_round": args.reps,
            "warmup_per_round": args.warmup,
            "float": "float64 (jax_enable_x64)",
            "initial_boxes": {k: [lo, hi] for k, (lo, hi) in boxes.items()},
            "initial_box_notes": {
                "hull": "interval hull of T X0, X0 = [-pi/10, pi/10] x [-0.2, 0.2], each "
                "operation rounded up one ulp",
                "paper": "the paper's Y0 = [-(pi/10)(1.04, 1), (pi/10)(1.04, 1)] (its T^-1 Y0 "
                "does not contain all of X0: |y1| reaches pi/10 + 0.04 > 1.04 pi/10)",
            },
            "forms": {
                "composed": "immrax.LinearTransformedSystem(PendulumX(), T): y' = T f(T^-1 y),"
                " T^-1 = jnp.linalg.inv(T)",
                "simplified": "y1' = -15 y1 + 11 y2 + 2 sin(y2), y2' = 5 y1 - 5 y2 (by hand)",
            },
            "immrax_calls": {
                "embedding": "immrax.natemb(sys) / immrax.jacemb(sys) / immrax.mjacemb(sys) "
                "== immrax.TransformEmbedding(sys, if_transform=immrax.natif|jacif|mjacif) "
                "(InclusionEmbedding: continuous-time, inclusion evaluated on each face of the "
                "box, default centers = centre of the face box, default permutation for mjacif)",
                "initial_state": "immrax.i2ut(immrax.interval(lo, hi))",
                "scan": "jax.jit: jax.lax.scan over 400 steps of x <- x + 0.01 * embsys.E(k*0.01, x)",
                "diffrax": "jax.jit: embsys.compute_trajectory(0., 4., x0, dt=0.01, "
                "solver='euler') -> diffrax.diffeqsolve(Euler, SaveAt(t0, t1, steps)), "
                "max_steps 4096 (padded output)",
                "timing": "jax.block_until_ready on the (ts, ys) output of each reach",
            },
            "timing_notes": {
                "process_start_to_first_result": "parent's monotonic clock from just before "
                "spawning the child to the child's first box being ready (interpreter start, "
                "import jax + immrax, tracing, XLA compile, first run)",
                "first_call": "the first reach_jit(x0) call: trace + lower + XLA compile + run",
                "jit_overhead": "first_call minus the steady median",
                "steady_per_reach": "one whole 400-step reach (all 401 boxes), after warm-up, "
                "each timed with block_until_ready; median, p10, p90 of --reps samples; "
                "cpu_time_of_back_to_back_batch: process CPU time (all threads) per reach",
            },
        },
        "results": results,
    }
    doc["checks"] = cross_checks(results)
    os.makedirs(os.path.dirname(os.path.abspath(args.out)), exist_ok=True)
    with open(args.out, "w") as f:
        json.dump(doc, f, indent=1)
        f.write("\n")
    print_tables(doc)
    print(f"\nwrote {args.out}")


if __name__ == "__main__":
    main()
