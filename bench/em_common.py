"""What the numpy Euler-Maruyama peers share: the command line, the result they read, and the
line they print (bench/numpy_em_pendulum.py, bench/numpy_em_linear.py)."""

import argparse
import json

import numpy as np


def setup(doc, default_paths):
    """Parses `RESULT_JSON [--paths N] [--seed S]` and reads the result.

    Returns `(paths, result, metric, steps, dt, rng)`: the number of paths, the result's JSON,
    its metric `P` as an array, its steps, its report step and numpy's default generator
    seeded with `--seed`.
    """
    ap = argparse.ArgumentParser(description=doc.splitlines()[0])
    ap.add_argument("result")
    ap.add_argument("--paths", type=int, default=default_paths)
    ap.add_argument("--seed", type=int, default=0)
    args = ap.parse_args()
    with open(args.result) as f:
        res = json.load(f)
    p = np.array(res["constants"]["metric"], dtype=float)
    rng = np.random.default_rng(args.seed)
    return args.paths, res, p, res["steps"], res["step"], rng


def report(path_steps, secs, counts):
    """Prints the loop's path-steps per second and the counts (`name: value` pairs)."""
    tail = ", ".join(f"{name} {value}" for name, value in counts)
    print(
        f"numpy {np.__version__}: {path_steps:.3e} path-steps in {secs:.3f} s "
        f"({path_steps / secs:.3e}/s); {tail}"
    )
