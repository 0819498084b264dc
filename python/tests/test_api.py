"""The API: loading, errors with spans, inspection, arrays' dtypes and shapes, contains/hull,
a sweep of 100 initial boxes through one handle, input plans, the interrupt."""

from __future__ import annotations

import _thread
import json
import threading
import time
from pathlib import Path

import numpy as np
import pytest

import reachc
from conftest import SPECS, run_cli

PENDULUM = SPECS / "pendulum.sde"

BAD = """model bad

state x in [0, 1]

drift {
    x' = -x +* 2
}
"""


@pytest.fixture(scope="module")
def pendulum() -> reachc.Spec:
    return reachc.load(PENDULUM)


def test_load_and_inspect(pendulum: reachc.Spec) -> None:
    assert pendulum.name == "pendulum"
    assert pendulum.states == ["theta", "omega"]
    assert pendulum.noises == ["w"]
    assert pendulum.inputs == []
    assert "paper_interval" in pendulum.analyses
    assert pendulum.constants["K1"] == -20.0
    assert pendulum.drift[0] == "omega"
    assert "sin(theta)" in pendulum.drift[1]
    assert pendulum.diffusion[1][0] == "0.1"
    assert pendulum.jacobian_x == [["0", "1"], ["10*cos(theta) - 20", "-20"]]
    assert pendulum.jacobian_u == [[], []]
    box = pendulum.initial_box
    assert box.dtype == np.float64 and box.shape == (2, 2)
    assert box[1].tolist() == [-0.2, 0.2]
    a = pendulum.analysis("paper_interval")
    assert a["method"] == "interval" and a["integrator"] == "euler"
    k = a["constants"]
    assert k["certified"] and k["c"] < 0 and k["sigma"] > 0
    assert k["metric"].shape == (2, 2)


def test_spec_error_has_the_cli_diagnostic_and_spans(tmp_path: Path, cli: Path) -> None:
    path = tmp_path / "bad.sde"
    path.write_text(BAD)
    with pytest.raises(reachc.SpecError) as info:
        reachc.load(path)
    e = info.value
    # The same text `reachc check` prints (no colour when not on a terminal).
    checked = run_cli(cli, ["check", str(path)])
    assert checked.returncode == 1
    assert str(e) == checked.stderr
    assert len(e.diagnostics) >= 1
    d = e.diagnostics[0]
    assert d.severity == "error"
    assert (d.line, d.column) == (6, 14)
    assert d.message
    # The same from a string, under the name given.
    with pytest.raises(reachc.SpecError) as info2:
        reachc.loads(BAD, name="bad.sde")
    assert [(x.line, x.column, x.message) for x in info2.value.diagnostics] == [
        (x.line, x.column, x.message) for x in e.diagnostics
    ]
    assert "bad.sde:6:14" in str(info2.value)


def test_check_error_after_parsing_has_its_span() -> None:
    text = "model m\n\nstate x in [0, 1]\n\ndrift {\n    x' = -y\n}\n"
    with pytest.raises(reachc.SpecError) as info:
        reachc.loads(text)
    d = info.value.diagnostics[0]
    assert (d.line, d.column) == (6, 11)
    assert "y" in d.message or "y" in d.label


def test_missing_file_is_an_oserror(tmp_path: Path) -> None:
    with pytest.raises(OSError):
        reachc.load(tmp_path / "nope.sde")


def test_unknown_analysis(pendulum: reachc.Spec) -> None:
    with pytest.raises(ValueError, match="no analysis `nope`"):
        pendulum.reach("nope")


def test_arrays_dtypes_and_shapes(pendulum: reachc.Spec) -> None:
    for name in ("paper_interval", "paper_contraction"):
        res = pendulum.reach(name).run()
        k, n = 401, 2
        for arr, shape in [
            (res.times, (k,)),
            (res.nominal, (k, n)),
            (res.lo, (k, n)),
            (res.hi, (k, n)),
            (res.r, (k,)),
            (res.prs_radius, (k,)),
            (res.det_radius, (k,)),
            (res.rates, (k,)),
            (res.sigmas, (k,)),
            (res.margins, (k, 0)),
            (res.metric, (n, n)),
        ]:
            assert isinstance(arr, np.ndarray)
            assert arr.dtype == np.float64
            assert arr.shape == shape
        assert res.times[0] == 0.0 and res.times[-1] == pytest.approx(4.0)
        assert np.all(res.lo <= res.hi)
        assert res.verdict == "no unsafe sets"
        j = res.json()
        assert j["analysis"] == name


def test_contains_and_hull(pendulum: reachc.Spec) -> None:
    res = pendulum.reach("paper_interval").run()
    h = res.hull(1.0)
    assert h.shape == (2, 2) and h.dtype == np.float64
    k = int(np.argmin(np.abs(res.times - 1.0)))
    assert h[:, 0].tolist() == res.lo[k].tolist()
    assert h[:, 1].tolist() == res.hi[k].tolist()
    assert res.contains(res.nominal[k], 1.0) is True
    assert res.contains([10.0, 10.0], 1.0) is False
    assert res.contains([0.0, 0.0], 1.005) is None
    with pytest.raises(IndexError):
        res.hull(1.005)


def test_det_sets_and_members_match_the_json(pendulum: reachc.Spec) -> None:
    # Parallelotopes, a contraction ball cut by its interval box, several metrics.
    for name in ("paper_interval", "contraction", "per_state"):
        res = pendulum.reach(name).run()
        j = res.json()
        also = j.get("also", [])
        assert len(res.members) == len(also)
        assert res.role == "own"
        assert [m.role for m in res.members] == [jm["role"] for jm in also]
        for r, jr in [(res, j)] + list(zip(res.members, also)):
            for k in (0, 100, 400):
                d = r.det_set(float(r.times[k]))
                want = jr["steps"][k]["det_set"]
                assert d["shape"] == want["shape"]
                assert set(d) == set(want) - {"metric"}
                for key, value in want.items():
                    if key not in ("shape", "metric"):
                        assert np.asarray(d[key]).tolist() == value, (name, k, key)
        with pytest.raises(IndexError):
            res.det_set(1.005)
    roles = [m.role for m in pendulum.reach("per_state").run().members]
    assert "metric" in roles and "first_order" in roles, roles
    assert "first_order" in [m.role for m in pendulum.reach("contraction").run().members]


def test_sweep_of_100_initial_boxes(pendulum: reachc.Spec) -> None:
    reach = pendulum.reach("paper_interval")
    base = pendulum.initial_box
    rng = np.random.default_rng(3)
    scale = np.linspace(0.05, 1.0, 100)
    shift = rng.uniform(-0.5, 0.5, size=(100, 2)) * (base[:, 1] - base[:, 0])
    mid = base.mean(axis=1)
    half = (base[:, 1] - base[:, 0]) / 2
    boxes = np.empty((100, 2, 2))
    boxes[:, :, 0] = mid + shift - scale[:, None] * half
    boxes[:, :, 1] = mid + shift + scale[:, None] * half
    results = reach.sweep(boxes)
    assert len(results) == 100
    for b, r in zip(boxes, results):
        # The set at t = 0 holds the initial box.
        assert np.all(r.lo[0] <= b[:, 0]) and np.all(r.hi[0] >= b[:, 1])
    # Wider boxes give wider sets at the horizon (same centre for the first and a scaled one).
    w = [float(np.sum(r.hi[-1] - r.lo[-1])) for r in results]
    assert min(w) > 0
    # A sweep is the runs one by one.
    for i in (0, 57, 99):
        assert results[i].to_json() == reach.run(boxes[i]).to_json()
    # The spec's own box gives the spec's result.
    assert reach.run(base).to_json() == reach.run().to_json()


def test_a_split_result_is_the_union_of_its_pieces() -> None:
    # specs/vanderpol.sde splits its initial box 8 x 8 (method.md 8.11).
    spec = reachc.load(SPECS / "vanderpol.sde")
    res = spec.reach("contraction").run()
    assert len(res.pieces) == 64
    assert res.json()["split"] == [8, 8]
    for t in (0.5, 2.0):
        hull = res.hull(t)
        lo = np.min([p.hull(t)[:, 0] for p in res.pieces], axis=0)
        hi = np.max([p.hull(t)[:, 1] for p in res.pieces], axis=0)
        assert hull[:, 0].tolist() == lo.tolist() and hull[:, 1].tolist() == hi.tolist()
        # A point of some piece is in the union; a point beyond every piece is not.
        centre = res.pieces[5].hull(t).mean(axis=1)
        assert res.pieces[5].contains(centre, t) == res.contains(centre, t)
        assert res.contains(hi + 1.0, t) is False


def test_initial_box_outside_the_domain_is_an_analysis_error() -> None:
    spec = reachc.load(SPECS / "vanderpol.sde")
    a = spec.analyses[0]
    box = np.array([[1e6, 2e6]] * len(spec.states))
    with pytest.raises(reachc.AnalysisError):
        spec.reach(a).run(box)


def test_bad_box_shape(pendulum: reachc.Spec) -> None:
    with pytest.raises(ValueError):
        pendulum.reach("paper_interval").run(np.zeros((3, 2)))


def test_input_plan() -> None:
    spec = reachc.load(SPECS / "duffing.sde")
    assert spec.inputs, "duffing has an input"
    name = next(a for a in spec.analyses if spec.analysis(a)["rate"] != "empirical")
    reach = spec.reach(name)
    box = spec.initial_box
    u = [0.0] * len(spec.inputs)
    planned = reach.run(box, inputs=([0.0], [u]))
    free = reach.run(box)
    # A known input gives a set no larger than any input in the box.
    assert planned.prs_radius[-1] <= free.prs_radius[-1] * (1 + 1e-12)


def test_keyboard_interrupt_stops_a_simulation(pendulum: reachc.Spec) -> None:
    timer = threading.Timer(0.3, _thread.interrupt_main)
    started = time.monotonic()
    timer.start()
    try:
        with pytest.raises(KeyboardInterrupt):
            pendulum.simulate("contraction", paths=50_000_000, seed=1)
    finally:
        timer.cancel()
    assert time.monotonic() - started < 30.0


def test_sample_paths(pendulum: reachc.Spec) -> None:
    res = pendulum.reach("paper_interval").run()
    p = pendulum.sample_paths(res.times, paths=20, seed=0)
    assert p.shape == (20, len(res.times), 2) and p.dtype == np.float64
    box = pendulum.initial_box
    assert np.all(p[:, 0, :] >= box[:, 0]) and np.all(p[:, 0, :] <= box[:, 1])


def test_gil_is_released_during_runs(pendulum: reachc.Spec) -> None:
    reach = pendulum.reach("interval")
    out = []
    threads = [threading.Thread(target=lambda: out.append(reach.run().to_json())) for _ in range(2)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert len(out) == 2 and out[0] == out[1]


def test_safety_probability_equals_the_cli(cli: Path, tmp_path: Path) -> None:
    spec = reachc.load(SPECS / "vanderpol_feedback.sde")
    p = spec.reach("contraction").safety_probability()
    done = run_cli(
        cli,
        [
            "run",
            str(SPECS / "vanderpol_feedback.sde"),
            "--backend",
            "interp",
            "--analysis",
            "contraction",
            "--probability",
            "-o",
            str(tmp_path),
        ],
    )
    assert done.returncode == 0, done.stderr
    written = json.loads((tmp_path / "contraction.json").read_text())["safety_probability"]
    assert p.lower_bound is not None and 0.999 < p.lower_bound < 1.0
    assert (p.lower_bound, p.delta, p.not_shown_at, p.runs) == (
        written["lower_bound"],
        written["delta"],
        written["not_shown_at"],
        written["runs"],
    )
    # At small deltas the ball's local rates cannot close a region; the linearised set alone
    # (method.md 8.12) is shown safe down to the search's floor, 1e-15.
    assert (p.limit, p.proved) == (written["limit"]["kind"], written["proved"]) == (
        "floor",
        True,
    )
    assert p.delta == 1e-15 and p.lower_bound >= 1.0 - 1.1e-15
    assert p.text in done.stdout


def test_safety_probability_needs_a_uniform_guarantee() -> None:
    text = (
        "model m\nstate x in [0, 0.1]\nnoise w\ndrift { x' = -x }\ndiffusion { x: 0.1 * w }\n"
        "unsafe high halfspace { x >= 1 }\n"
        "analysis a { method = contraction  horizon = 1  step = 0.1  guarantee = pointwise }\n"
    )
    with pytest.raises(reachc.AnalysisError, match="guarantee = uniform"):
        reachc.loads(text).reach("a").safety_probability()


GOALS = (
    "model ou\nstate x = 0\nnoise w\ndrift { x' = 1 - x }\ndiffusion { x: 0.2 * w }\n"
    "unsafe low halfspace { x <= -0.6 }\n"
    "goal up halfspace { x >= 0.3 } within [0.5, 2]\n"
    "goal far box { x in [5, 6] }\n"
    "analysis a { method = contraction  delta = 0.05  horizon = 2  step = 0.01 }\n"
)


def test_goals_and_their_probability_equal_the_cli(cli: Path, tmp_path: Path) -> None:
    spec_path = tmp_path / "ou.sde"
    spec_path.write_text(GOALS)
    reach = reachc.load(spec_path).reach("a")
    goals = reach.run().goals
    assert [g["name"] for g in goals] == ["up", "far"]
    assert goals[0]["status"] == "reached" and 0.5 <= goals[0]["t"] <= 2.0
    assert goals[1]["status"] == "not_shown" and goals[1]["why"] == "not_inside"
    assert goals[0]["margins"].shape == (201,)
    p = reach.goal_probability("up")
    done = run_cli(
        cli,
        ["run", str(spec_path), "--backend", "interp", "--probability", "-o", str(tmp_path)],
    )
    assert done.returncode == 0, done.stderr
    written = json.loads((tmp_path / "a.json").read_text())["goals"]
    assert [g["status"] for g in written] == ["reached", "not_shown"]
    w = written[0]["probability"]
    assert (p.lower_bound, p.delta, p.t, p.runs, p.limit) == (
        w["lower_bound"],
        w["delta"],
        w["t"],
        w["runs"],
        w["limit"]["kind"],
    )
    # The exact P(X_2 >= 0.3) is 0.99997: the certified bound lies below it.
    assert p.lower_bound is not None and 0.99 < p.lower_bound < 0.99997
    assert p.text in done.stdout
    far = reach.goal_probability("far")
    assert (far.lower_bound, far.limit) == (None, "not_inside")
    with pytest.raises(ValueError, match="no goal `nowhere`"):
        reach.goal_probability("nowhere")
