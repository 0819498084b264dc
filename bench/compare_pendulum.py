#!/usr/bin/env python3
"""Side-by-side markdown tables: immrax vs reachc on the paper's pendulum (y = T x boxes).

    python3 bench/compare_pendulum.py IMMRAX_JSON [REACHC_JSON ...] [options]

IMMRAX_JSON  bench/results/immrax_pendulum.json (from bench/immrax_pendulum.py)
REACHC_JSON  DIR/<name>.json from `reachc run specs/pendulum.sde --analysis <name> -o DIR`;
             `steps[k].t` and `steps[k].det_set.lo/hi` are read (y-boxes for analyses with a
             `transform`; x-boxes otherwise, flagged). A contraction analysis (P-ball) is shown
             by its radius.

reachc timings are not in its result JSON; pass them with
    --reachc-timings FILE   JSON {"<label, analysis name or file stem>": {"first_result_s": ..,
                            "compile_s": .., "per_reach_s": .., "per_reach_min_s": ..,
                            "per_reach_cpu_s": .., "startup_s": .., "note": ".."}, ...}
    --set LABEL.KEY=VALUE   the same, one value at a time (repeatable), e.g.
                            --set interval.first_result_s=0.9 --set interval.per_reach_s=2.1e-4
Any `timing`, `timings` or `timing_s` object at the top of a reachc JSON is used as well.
Missing files, entries, times or values print as "—"; the script never fails on them.

Needs only the Python standard library (no immrax, no jax).
"""

import argparse
import json
import math
import os
import sys

REPORT_TIMES = ("1", "2", "4")
DASH = "—"
INCLUSION_TO_IMMRAX = {
    "natural": "natif",
    "natif": "natif",
    "jacobian": "jacif",
    "jacif": "jacif",
    "mixed": "mjacif",
    "mixed_jacobian": "mjacif",
    "mjacif": "mjacif",
}


def load_json(path, what):
    try:
        with open(path) as f:
            return json.load(f)
    except (OSError, ValueError) as e:
        print(f"> warning: cannot read {what} {path}: {e}", file=sys.stderr)
        return None


def num(v):
    return isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v)


def fmt(v, digits=4):
    return f"{v:.{digits}g}" if num(v) else DASH


def fmt_vec(vs, digits=4):
    if not isinstance(vs, list) or not vs:
        return DASH
    return "(" + ", ".join(fmt(v, digits) for v in vs) + ")"


def fmt_time(s):
    if not num(s):
        return DASH
    if s >= 1.0:
        return f"{s:.2f} s"
    if s >= 1e-3:
        return f"{s * 1e3:.3g} ms"
    return f"{s * 1e6:.3g} us"


def dig(d, *keys):
    for k in keys:
        if not isinstance(d, dict) or k not in d:
            return None
        d = d[k]
    return d


# ------------------------------------------------------------------------------------------
# immrax side
# ------------------------------------------------------------------------------------------


def immrax_rows(doc, box, forms, driver):
    rows = []
    if not isinstance(doc, dict):
        return rows
    for r in doc.get("results", []):
        if not isinstance(r, dict) or r.get("driver") != driver or r.get("form") not in forms:
            continue
        label = f"immrax {r.get('inclusion', '?')} ({r.get('form', '?')})"
        if "error" in r:
            rows.append({"label": label, "error": r["error"]})
            continue
        at = dig(r, "boxes", box, "at") or {}
        hw = {k: dig(at, k, "half_width") for k in REPORT_TIMES}
        tm = r.get("timing_s") or {}
        rows.append(
            {
                "label": label,
                "inclusion": r.get("inclusion"),
                "form": r.get("form"),
                "hw": hw,
                "coords": "y",
                "initial": None,
                "timing": {
                    "startup_s": tm.get("import_total"),
                    "first_result_s": tm.get("process_start_to_first_result"),
                    "compile_s": tm.get("jit_overhead"),
                    "per_reach_s": dig(tm, "steady_per_reach", "median"),
                    "per_reach_min_s": dig(tm, "steady_per_reach", "min"),
                    "per_reach_cpu_s": dig(tm, "steady_per_reach", "cpu_time_of_back_to_back_batch"),
                },
            }
        )
    return rows


# ------------------------------------------------------------------------------------------
# reachc side
# ------------------------------------------------------------------------------------------


def pick_step(steps, tq, tol):
    best, best_d = None, None
    for st in steps:
        t = st.get("t") if isinstance(st, dict) else None
        if not num(t):
            continue
        d = abs(t - tq)
        if best_d is None or d < best_d:
            best, best_d = st, d
    if best is None or best_d > tol:
        return None
    return best


def det_cell(st):
    """Half-widths of the box, or the P-ball radius, or None."""
    ds = st.get("det_set") if isinstance(st, dict) else None
    if not isinstance(ds, dict):
        return None
    lo, hi = ds.get("lo"), ds.get("hi")
    if isinstance(lo, list) and isinstance(hi, list) and len(lo) == len(hi) and lo:
        if all(num(a) and num(b) for a, b in zip(lo, hi)):
            return [(b - a) / 2 for a, b in zip(lo, hi)]
        return [None] * len(lo)
    if num(ds.get("radius")):
        return f"{ds.get('shape', 'ball')} R={fmt(ds['radius'])}"
    return None


def reachc_row(path, doc, timings):
    stem = os.path.splitext(os.path.basename(path))[0]
    if not isinstance(doc, dict):
        return {"label": f"reachc {stem}", "error": "unreadable", "timing": timings.get(stem, {})}
    name = doc.get("analysis") or stem
    inclusion = doc.get("inclusion")
    method = doc.get("method", "?")
    label = f"reachc {name} ({inclusion or method})"
    coords = "y" if doc.get("transform") else "x"
    steps = doc.get("steps") if isinstance(doc.get("steps"), list) else []
    step = doc.get("step") if num(doc.get("step")) else 0.01
    tol = max(1e-9, 0.5 * step)
    hw = {}
    for k in REPORT_TIMES:
        st = pick_step(steps, float(k), tol)
        hw[k] = det_cell(st) if st is not None else None
    initial = None
    if steps and isinstance(steps[0], dict):
        ds = steps[0].get("det_set") or {}
        if isinstance(ds.get("lo"), list) and isinstance(ds.get("hi"), list):
            initial = (ds["lo"], ds["hi"])
    tm = {}
    for key in ("timing", "timings", "timing_s"):
        if isinstance(doc.get(key), dict):
            tm.update(doc[key])
    for key in (label, name, stem, path):
        if isinstance(timings.get(key), dict):
            tm.update(timings[key])
    return {
        "label": label,
        "inclusion": inclusion,
        "method": method,
        "hw": hw,
        "coords": coords,
        "initial": initial,
        "timing": tm,
        "meta": {
            "integrator": doc.get("integrator"),
            "step": doc.get("step"),
            "horizon": doc.get("horizon"),
            "transform": dig(doc, "transform", "matrix"),
        },
    }


def parse_sets(items):
    out = {}
    for item in items or []:
        try:
            lhs, value = item.split("=", 1)
            label, key = lhs.rsplit(".", 1)
            v = float(value)
        except ValueError:
            print(f"> warning: ignoring --set {item!r} (want LABEL.KEY=NUMBER)", file=sys.stderr)
            continue
        out.setdefault(label, {})[key] = v
    return out


# ------------------------------------------------------------------------------------------
# output
# ------------------------------------------------------------------------------------------


def hw_cell(v, digits):
    if v is None:
        return DASH
    if isinstance(v, str):
        return v
    return fmt_vec(v, digits)


def box_mismatch(a, b):
    """Largest |difference| between two (lo, hi) boxes, or None if not comparable."""
    try:
        diffs = [abs(x - y) for u, v in zip(a, b) for x, y in zip(u, v)]
        if len(diffs) != sum(len(u) for u in a):
            return None
        return max(diffs)
    except TypeError:
        return None


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("immrax_json")
    ap.add_argument("reachc_json", nargs="*")
    ap.add_argument("--box", choices=("hull", "paper"), default="hull",
                    help="immrax initial box to show (reachc uses its spec's X0: hull)")
    ap.add_argument("--forms", default="composed,simplified",
                    help="immrax forms to show (composed: T f(T^-1 y) as is; simplified)")
    ap.add_argument("--driver", choices=("scan", "diffrax"), default="scan")
    ap.add_argument("--digits", type=int, default=6, help="significant digits of half-widths")
    ap.add_argument("--reachc-timings", help="JSON file of reachc timings per label")
    ap.add_argument("--set", action="append", metavar="LABEL.KEY=VALUE")
    args = ap.parse_args()

    imx = load_json(args.immrax_json, "immrax results")
    timings = {}
    if args.reachc_timings:
        timings.update(load_json(args.reachc_timings, "reachc timings") or {})
    for label, kv in parse_sets(args.set).items():
        timings.setdefault(label, {}).update(kv)

    forms = tuple(f.strip() for f in args.forms.split(",") if f.strip())
    rows_i = immrax_rows(imx, args.box, forms, args.driver)
    rows_r = [reachc_row(p, load_json(p, "reachc result"), timings) for p in args.reachc_json]

    # header facts
    vers = dig(imx, "versions") or {}
    lo_hi = dig(imx, "setup", "initial_boxes", args.box)
    print("## Pendulum, y = T x, T = [[1, 0.2], [1, 0]]: box half-widths (y1, y2)")
    print()
    print(f"immrax {vers.get('immrax', '?')} (jax {vers.get('jax', '?')}), float64, Euler "
          f"dt = {dig(imx, 'setup', 'dt') or '?'}, driver `{args.driver}`, initial box "
          f"`{args.box}`" + (f": lo {fmt_vec(lo_hi[0], 17)}, hi {fmt_vec(lo_hi[1], 17)}"
                             if isinstance(lo_hi, list) and len(lo_hi) == 2 else ""))
    for r in rows_r:
        if r.get("initial"):
            lo, hi = r["initial"]
            print(f"{r['label']}: initial box lo {fmt_vec(lo, 17)}, hi {fmt_vec(hi, 17)} "
                  f"({r['coords']}); integrator {dig(r, 'meta', 'integrator') or '?'}, "
                  f"step {dig(r, 'meta', 'step') or '?'}")
            d = box_mismatch(r["initial"], lo_hi) if r["coords"] == "y" else None
            if d is not None and d > 1e-12:
                print(f"> note: this initial box differs from immrax's `{args.box}` box by up "
                      f"to {d:.3g}: the half-widths are not like for like.")
    print()
    print("| tool / variant | coords | t = 1 | t = 2 | t = 4 |")
    print("|---|---|---|---|---|")
    for r in rows_i + rows_r:
        if "error" in r:
            print(f"| {r['label']} | {DASH} | error: {str(r['error'])[:60]} | {DASH} | {DASH} |")
            continue
        cells = [hw_cell(r["hw"].get(k), args.digits) for k in REPORT_TIMES]
        print(f"| {r['label']} | {r.get('coords', DASH)} | " + " | ".join(cells) + " |")

    # reachc / immrax ratios at matching inclusions (immrax simplified form: reachc simplifies
    # the transformed drift symbolically; composed shown too where present)
    pairs = []
    for r in rows_r:
        if "error" in r or r.get("coords") != "y":
            continue
        inc = INCLUSION_TO_IMMRAX.get(str(r.get("inclusion")).lower())
        for ri in rows_i:
            if "error" not in ri and ri.get("inclusion") == inc:
                pairs.append((r, ri))
    if pairs:
        print()
        print("Ratio of half-widths reachc / immrax (1 = same box; > 1 = reachc wider), t = 4:")
        print()
        print("| reachc | immrax | y1 | y2 |")
        print("|---|---|---|---|")
        for r, ri in pairs:
            a, b = r["hw"].get("4"), ri["hw"].get("4")
            cells = []
            for i in range(2):
                try:
                    cells.append(fmt(a[i] / b[i], 6))
                except (TypeError, IndexError, ZeroDivisionError):
                    cells.append(DASH)
            print(f"| {r['label']} | {ri['label']} | {cells[0]} | {cells[1]} |")

    print()
    print("## Timings")
    print()
    print("| tool / variant | startup (imports) | first result (process start) | "
          "JIT / compile | per reach (steady, median) | per reach (min) | per reach (CPU) |")
    print("|---|---|---|---|---|---|---|")
    for r in rows_i + rows_r:
        tm = r.get("timing") or {}
        print(
            f"| {r['label']} | {fmt_time(tm.get('startup_s'))} | "
            f"{fmt_time(tm.get('first_result_s'))} | {fmt_time(tm.get('compile_s'))} | "
            f"{fmt_time(tm.get('per_reach_s'))} | {fmt_time(tm.get('per_reach_min_s'))} | "
            f"{fmt_time(tm.get('per_reach_cpu_s'))} |"
        )
    notes = [(r["label"], (r.get("timing") or {}).get("note")) for r in rows_r]
    notes = [(lbl, n) for lbl, n in notes if n]
    if notes:
        print()
        for lbl, n in notes:
            print(f"- {lbl}: {n}")
    print()
    print("immrax: first result = interpreter start + `import jax, immrax` + trace + XLA "
          "compile + first reach, fresh process; JIT = first call minus the steady median; "
          "per reach = one whole 400-step reach with `block_until_ready`. immrax arithmetic is "
          "float64 round-to-nearest (no outward rounding).")


if __name__ == "__main__":
    main()
