"""reachc.plot (the `plot` extra, installed in CI) and the example script."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

import reachc
from conftest import REPO, SPECS

matplotlib = pytest.importorskip("matplotlib", reason="the plot extra is not installed")
matplotlib.use("Agg")


def test_plot_helpers(tmp_path: Path) -> None:
    import matplotlib.pyplot as plt

    import reachc.plot

    spec = reachc.load(SPECS / "pendulum.sde")
    con = spec.reach("paper_contraction").run()
    box = spec.reach("paper_interval").run()
    sim = spec.simulate("paper_contraction", paths=200, seed=0)
    paths = spec.sample_paths(con.times, paths=10, seed=0)
    fig, axes = plt.subplots(1, 4, figsize=(12, 3))
    reachc.plot.sets(con, ax=axes[0], paths=paths)
    reachc.plot.sets(box, ax=axes[1], steps=[0, 100, 400])
    reachc.plot.radii(con, sim, ax=axes[2])
    reachc.plot.rates(con, ax=axes[3])
    assert len(axes[0].patches) == 9 and len(axes[1].patches) == 3
    out = tmp_path / "f.png"
    fig.savefig(out)
    plt.close(fig)
    assert out.stat().st_size > 1000


def test_readme_example() -> None:
    spec = reachc.load(SPECS / "pendulum.sde")
    reach = spec.reach("paper_interval")
    res = reach.run(x0=[[-0.1, 0.1], [-0.2, 0.2]])
    assert res.times.shape == (401,) and res.hi[-1].shape == (2,)
    assert res.verdict == "no unsafe sets" and res.contains([0, 0], 4.0) is True


def test_example_script_writes_the_figure(tmp_path: Path) -> None:
    out = tmp_path / "pendulum.png"
    done = subprocess.run(
        [sys.executable, str(REPO / "python" / "examples" / "pendulum.py"), str(out)],
        capture_output=True,
        text=True,
        timeout=600,
    )
    assert done.returncode == 0, done.stderr
    assert out.stat().st_size > 10_000
