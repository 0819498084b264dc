"""Results equal to the CLI's files: `reachc run --backend interp` on every shipped spec (JSON
byte for byte, each analysis), and `reachc simulate --backend interp` with the same seed."""

from __future__ import annotations

from pathlib import Path
from typing import Dict, List

import pytest

import reachc
from conftest import SPECS, run_cli

# Specs not compared here, each with its reason; every other spec in specs/ is. None at present:
# chain1000.sde too runs in seconds (the CLI's debug build: about 6 s).
EXCLUDED: Dict[str, str] = {}

ALL = sorted(p.name for p in SPECS.glob("*.sde"))


def test_the_spec_list_is_the_directory() -> None:
    assert set(EXCLUDED) <= set(ALL)
    assert len(ALL) >= 10


def _cli_run(cli: Path, spec: Path, out: Path, analysis: str) -> "tuple[int, str]":
    done = run_cli(
        cli,
        ["run", str(spec), "--backend", "interp", "--analysis", analysis, "-o", str(out)],
    )
    return done.returncode, done.stderr


@pytest.mark.parametrize("name", [n for n in ALL if n not in EXCLUDED])
def test_run_equals_the_cli(name: str, cli: Path, tmp_path: Path) -> None:
    spec_path = SPECS / name
    spec = reachc.load(spec_path)
    compared: List[str] = []
    for analysis in spec.analyses:
        out = tmp_path / analysis
        code, err = _cli_run(cli, spec_path, out, analysis)
        written = out / f"{analysis}.json"
        if code in (0, 3) and written.exists():
            res = spec.reach(analysis).run()
            assert res.to_json() == written.read_text(), f"{name} {analysis}"
            assert res.to_csv() == (out / f"{analysis}.csv").read_text()
            compared.append(analysis)
        else:
            # The CLI skipped it or it could not run: Python raises.
            assert "skipped analysis" in err or "error" in err, err
            with pytest.raises(reachc.AnalysisError):
                spec.reach(analysis).run()
    assert compared, f"{name}: no analysis compared"


SIMULATIONS = [
    ("pendulum.sde", "contraction", 2000, 7, []),
    ("pendulum.sde", "paper_interval", 1000, 3, []),
    ("duffing.sde", None, 500, 11, ["--inputs", "corners"]),
]


@pytest.mark.parametrize("name,analysis,paths,seed,extra", SIMULATIONS)
def test_simulate_equals_the_cli(
    name: str, analysis: "str | None", paths: int, seed: int, extra: List[str], cli: Path, tmp_path: Path
) -> None:
    spec_path = SPECS / name
    spec = reachc.load(spec_path)
    if analysis is None:
        analysis = spec.analyses[0]
    args = ["simulate", str(spec_path), "--backend", "interp", "--analysis", analysis]
    args += ["--paths", str(paths), "--seed", str(seed), "-o", str(tmp_path), *extra]
    done = run_cli(cli, args)
    assert done.returncode in (0, 1), done.stderr
    expected = (tmp_path / f"{analysis}.sim.json").read_text()
    inputs = extra[1] if extra else "random"
    sim = spec.simulate(analysis, paths=paths, seed=seed, inputs=inputs, threads=2)
    assert sim.to_json() == expected
    assert sim.passed == (done.returncode == 0)
    j = sim.json()
    assert sim.paths == paths and sim.seed == seed
    assert sim.quantile.shape == sim.times.shape == (len(j["steps"]),)
    n = len(spec.states)
    assert sim.state_quantile.shape == sim.state_prs.shape == sim.state_max.shape == (len(j["steps"]), n)
    last = j["steps"][-1]["states"]
    assert [s["quantile"] for s in last] == list(sim.state_quantile[-1])
    # The PRS holds 1 - delta of the paths per state too: its half-width is not below theirs.
    assert all(s["prs"] >= s["quantile"] for s in last)
    assert sim.outside.dtype.kind == "i"
    assert sim.coverage["passed"] == sim.passed


def test_simulate_probability_equals_the_cli(cli: Path, tmp_path: Path) -> None:
    """``probability=True`` is ``--probability``: the certified probability of safety checked
    against the paths, the same report as the CLI's."""
    spec_path = SPECS / "vanderpol_feedback.sde"
    spec = reachc.load(spec_path)
    args = ["simulate", str(spec_path), "--backend", "interp", "--analysis", "contraction"]
    args += ["--paths", "300", "--probability", "-o", str(tmp_path)]
    done = run_cli(cli, args)
    assert done.returncode == 0, done.stderr
    sim = spec.simulate("contraction", paths=300, threads=2, probability=True)
    assert sim.to_json() == (tmp_path / "contraction.sim.json").read_text()
    safety = sim.json()["safety"]
    assert safety["status"] == "pass" and 0.99 < safety["certified"] <= safety["cp_upper"]
