"""reachc from Python: delta-probabilistic reachable sets of SDEs from ``.sde`` specs.

A thin typed layer over the native module ``reachc._native`` (Rust, through reachc's IR
interpreter: no cargo or Rust toolchain at run time). It runs exactly what ``reachc check``,
``reachc run --backend interp`` and ``reachc simulate --backend interp`` run: the same
diagnostics, the same JSON, the same Monte Carlo paths for the same seed.

>>> import reachc
>>> spec = reachc.load("specs/pendulum.sde")
>>> res = spec.reach("paper_interval").run()
>>> res.times.shape, res.lo.shape
((401,), (401, 2))

The GIL is released while an analysis runs or paths are simulated. ``KeyboardInterrupt``
(Ctrl-C) stops a simulation between batches of paths and a sweep between runs; a single run
is not interrupted (it ends first).
"""

from __future__ import annotations

import json as _json
import os
from functools import cached_property
from typing import TYPE_CHECKING, Any, Dict, List, Optional, Sequence, Tuple, Union, cast

import numpy as np

from . import _native
from ._native import AnalysisError, Diagnostic, GoalProbability, SafetyProbability, SpecError

__all__ = [
    "AnalysisError",
    "Diagnostic",
    "Reach",
    "Result",
    "GoalProbability",
    "SafetyProbability",
    "Simulation",
    "Spec",
    "SpecError",
    "load",
    "loads",
]

__version__: str = _native.__version__

if TYPE_CHECKING:  # numpy.typing costs import time: for type checkers only
    import numpy.typing as npt

    FloatArray = npt.NDArray[np.float64]

PathLike = Union[str, "os.PathLike[str]"]
InputPlan = Tuple[Sequence[float], Sequence[Sequence[float]]]


def load(path: PathLike) -> "Spec":
    """Load, check and prepare the spec at ``path`` (what ``reachc check`` does).

    Raises :class:`SpecError` (``str()`` is the CLI's diagnostic, ``.diagnostics`` the
    items) or :class:`OSError` if the file cannot be read.
    """
    return Spec(_native.load(os.fspath(path)))


def loads(text: str, name: str = "<string>", dir: PathLike = ".") -> "Spec":
    """Load spec text; ``name`` names it in diagnostics, ``dir`` is where its tables' CSV files
    are looked up."""
    return Spec(_native.loads(text, name, os.fspath(dir)))


def _box(x0: Optional[npt.ArrayLike], n: int) -> Optional[FloatArray]:
    if x0 is None:
        return None
    a = np.ascontiguousarray(x0, dtype=np.float64)
    if a.shape != (n, 2):
        raise ValueError(f"an initial box has shape ({n}, 2) ([lo, hi] per state), not {a.shape}")
    return a


class Spec:
    """A loaded spec: checked, differentiated, its constants derived, ready to run."""

    def __init__(self, native: _native.Spec) -> None:
        self._native = native

    @property
    def name(self) -> str:
        """``model NAME``."""
        return self._native.name

    @property
    def path(self) -> str:
        """The path given to :func:`load`, or the name given to :func:`loads`."""
        return self._native.path

    @property
    def source(self) -> str:
        return self._native.source

    @property
    def states(self) -> List[str]:
        return self._native.states

    @property
    def inputs(self) -> List[str]:
        return self._native.inputs

    @property
    def noises(self) -> List[str]:
        return self._native.noises

    @property
    def analyses(self) -> List[str]:
        """The analyses' names, in spec order."""
        return self._native.analyses

    @property
    def constants(self) -> Dict[str, float]:
        """The spec's named constants (``const``)."""
        return dict(self._native.constants)

    @property
    def warnings(self) -> List[Diagnostic]:
        """Warnings of checking and preparing (e.g. an analysis whose constants are
        unbounded)."""
        return self._native.warnings

    def render_warnings(self) -> str:
        """The warnings as the CLI prints them."""
        return self._native.render_warnings()

    @cached_property
    def _expressions(
        self,
    ) -> Tuple[
        List[str], List[List[str]], List[List[str]], List[List[str]], List[Tuple[str, str]]
    ]:
        return self._native.expressions()

    @property
    def drift(self) -> List[str]:
        """The drift ``f_i``, one ``.sde`` expression per state, as ``reachc inspect`` prints
        it (shared sub-expressions by the names of :attr:`lets`)."""
        return self._expressions[0]

    @property
    def diffusion(self) -> List[List[str]]:
        """The diffusion ``G`` (state x noise channel) in ``.sde`` syntax."""
        return self._expressions[1]

    @property
    def jacobian_x(self) -> List[List[str]]:
        """The Jacobian ``D_x f`` (equation x state) in ``.sde`` syntax, as ``reachc inspect``
        prints it."""
        return self._expressions[2]

    @property
    def jacobian_u(self) -> List[List[str]]:
        """The Jacobian ``D_u f`` (equation x input) in ``.sde`` syntax."""
        return self._expressions[3]

    @property
    def lets(self) -> List[Tuple[str, str]]:
        """The shared sub-expressions the drift, diffusion and Jacobians use,
        ``(name, expression)``."""
        return self._expressions[4]

    @property
    def initial_box(self) -> FloatArray:
        """The spec's initial box, shape ``(n, 2)`` (NaN rows for states in a ball)."""
        return _native.initial_box(self._native)

    def analysis(self, name: str) -> Dict[str, Any]:
        """The analysis ``name``: its parameters and certified constants (``c``, ``sigma``,
        ``rho``, ``metric``), or ``constants_error`` saying why there are none."""
        return self._native.analysis(name)

    def reach(self, analysis: str) -> "Reach":
        """A handle on ``analysis``: checked once, run many times (:meth:`Reach.run`)."""
        return Reach(self._native.reach(analysis), len(self.states))

    def run(self, analysis: str, x0: Optional[npt.ArrayLike] = None) -> "Result":
        """``spec.reach(analysis).run(x0)``."""
        return self.reach(analysis).run(x0)

    def simulate(
        self,
        analysis: str,
        paths: int,
        seed: int = 0,
        *,
        dt: Optional[float] = None,
        delta: Optional[float] = None,
        inputs: str = "random",
        hold: Optional[float] = None,
        confidence: float = 0.999,
        threads: Optional[int] = None,
        probability: bool = False,
    ) -> "Simulation":
        """Monte Carlo check of ``analysis`` as ``reachc simulate --paths PATHS --seed SEED``:
        the same paths and statistics for the same options (whatever ``threads``). With
        ``probability``, as ``--probability``: the certified probability of safety is checked
        against the paths that entered no unsafe set (``json()["safety"]``)."""
        return Simulation(
            self._native.simulate(
                analysis, paths, seed, dt, delta, inputs, hold, confidence, threads, probability
            )
        )

    def sample_paths(
        self,
        times: npt.ArrayLike,
        paths: int,
        seed: int = 0,
        *,
        dt: Optional[float] = None,
        inputs: str = "random",
        hold: Optional[float] = None,
        center: Optional[Sequence[float]] = None,
    ) -> FloatArray:
        """Euler-Maruyama sample paths at ``times`` (increasing, from 0), shape
        ``(paths, len(times), n)``, with :meth:`simulate`'s random streams and Euler steps of at
        most ``dt`` (default: one report step). :meth:`simulate` chooses its steps from the
        dynamics (its ``dt``); with that ``dt``, a single step per report interval or an
        explicit ``dt`` option, path ``p`` is path ``p`` of :meth:`simulate` when ``center``
        is the result's initial centre."""
        t = [float(v) for v in np.asarray(times, dtype=np.float64)]
        return self._native.sample_paths(
            t, paths, seed, dt, inputs, hold, None if center is None else list(center)
        )

    def __repr__(self) -> str:
        return repr(self._native)


class Reach:
    """One analysis of a spec, checked once: run it from the spec's initial set or from other
    boxes, under any input in the input box or a known input plan."""

    def __init__(self, native: _native.Reach, n: int) -> None:
        self._native = native
        self._n = n

    @property
    def name(self) -> str:
        return self._native.name

    def run(
        self, x0: Optional[npt.ArrayLike] = None, inputs: Optional[InputPlan] = None
    ) -> "Result":
        """The delta-PRS from the spec's initial set, or from the box ``x0`` (shape ``(n, 2)``,
        ``[lo, hi]`` per state, inside the spec's domain), for any input in the input box or
        under ``inputs = (times, values)`` (``values[k]`` from ``times[k]`` on). The GIL is
        released while it runs. Raises :class:`AnalysisError` if it cannot run."""
        plan = None
        if inputs is not None:
            times, values = inputs
            plan = ([float(t) for t in times], [[float(u) for u in v] for v in values])
        return Result(self._native.run(_box(x0, self._n), plan))

    def sweep(self, boxes: npt.ArrayLike) -> List["Result"]:
        """:meth:`run` from each box of ``boxes`` (shape ``(m, n, 2)``); Ctrl-C stops it
        between runs."""
        a = np.ascontiguousarray(boxes, dtype=np.float64)
        if a.ndim != 3 or a.shape[1:] != (self._n, 2):
            raise ValueError(f"boxes have shape (m, {self._n}, 2), not {a.shape}")
        return [Result(r) for r in self._native.sweep(a)]

    def safety_probability(self) -> SafetyProbability:
        """A certified lower bound of the probability that no unsafe set is entered on
        ``[0, horizon]``, for every start in the spec's initial set and every input: the
        ``safety_probability`` of ``reachc run --probability`` (``lower_bound`` is ``None``
        without a bound; ``limit`` says what stops it: ``resolution``, ``floor``,
        ``stochastic``, ``deterministic`` or ``failed``; ``text`` is the CLI's line). About a
        dozen runs, the GIL released. Raises :class:`AnalysisError` for a pointwise guarantee
        or a model without unsafe sets."""
        return self._native.safety_probability()

    def goal_probability(self, goal: str) -> GoalProbability:
        """A certified lower bound of the probability of reaching the goal set ``goal`` within
        its window, avoiding every unsafe set until then (with ``stay``: and staying in it to
        the horizon), for every start and input: the goal's ``probability`` in ``reachc run
        --probability`` (``t`` the reach time at that bound; ``limit`` what stops it). About a
        dozen runs, the GIL released. Raises :class:`ValueError` for an unknown goal and
        :class:`AnalysisError` for a pointwise guarantee."""
        return self._native.goal_probability(goal)

    def __repr__(self) -> str:
        return repr(self._native)


class Result:
    """A delta-PRS at every report time, as numpy float64 arrays (``k`` report times, ``n``
    states), with the CLI's JSON."""

    def __init__(self, native: _native.Result) -> None:
        self._native = native

    @property
    def model(self) -> str:
        return self._native.model

    @property
    def analysis(self) -> str:
        return self._native.analysis

    @property
    def method(self) -> str:
        """``contraction`` or ``interval``."""
        return self._native.method

    @property
    def delta(self) -> float:
        return self._native.delta

    @property
    def states(self) -> List[str]:
        return self._native.states

    @cached_property
    def times(self) -> FloatArray:
        """Report times, shape ``(k,)``."""
        return self._native.times

    @cached_property
    def nominal(self) -> FloatArray:
        """Nominal state (centre of the deterministic set), shape ``(k, n)``."""
        return self._native.nominal

    @cached_property
    def _hull(self) -> Tuple[FloatArray, FloatArray]:
        return self._native.hull_bounds

    @property
    def lo(self) -> FloatArray:
        """Lower corners of a rigorous bounding box of each PRS, shape ``(k, n)``."""
        return self._hull[0]

    @property
    def hi(self) -> FloatArray:
        """Upper corners of a rigorous bounding box of each PRS, shape ``(k, n)``."""
        return self._hull[1]

    @cached_property
    def r(self) -> FloatArray:
        """Stochastic radius ``r_t`` in the metric's norm, shape ``(k,)``."""
        return self._native.r

    @cached_property
    def det_radius(self) -> FloatArray:
        """Radius of the deterministic set around the nominal state, shape ``(k,)``."""
        return self._native.det_radius

    @cached_property
    def prs_radius(self) -> FloatArray:
        """Radius of a metric ball around the nominal state holding the PRS, shape ``(k,)``."""
        return self._native.prs_radius

    @cached_property
    def rates(self) -> FloatArray:
        """Contraction rate ``c`` on the step ending at each report time, shape ``(k,)``."""
        return self._native.rates

    @cached_property
    def sigmas(self) -> FloatArray:
        """Noise level ``sigma`` on the step ending at each report time, shape ``(k,)``."""
        return self._native.sigmas

    @cached_property
    def margins(self) -> FloatArray:
        """Safety margin per unsafe set, shape ``(k, m)`` (``> 0``: shown safe)."""
        return self._native.margins

    @property
    def unsafe_sets(self) -> List[str]:
        return self._native.unsafe_sets

    @cached_property
    def metric(self) -> FloatArray:
        """The metric ``P``, shape ``(n, n)``."""
        return self._native.metric

    @cached_property
    def _verdict(self) -> Dict[str, Any]:
        return self._native.verdict()

    @property
    def verdict(self) -> str:
        """``"safe"``, ``"no unsafe sets"`` or ``"not shown safe"``."""
        return str(self._verdict["verdict"])

    @property
    def goals(self) -> List[Dict[str, Any]]:
        """Per goal set of the model, what the result shows (method.md 8.13): ``name``,
        ``window``, ``stay``, ``status`` (``"reached"`` with the first report time ``t`` and
        its ``margin``; ``"not_shown"`` with ``why``, ``why_t``, ``why_set``;
        ``"needs_uniform"``) and ``margins`` per report time."""
        return self._native.goals

    @property
    def verdict_detail(self) -> Dict[str, Any]:
        """The verdict with, when not shown safe, the first time ``t``, its ``step`` and the
        unsafe ``set``."""
        return dict(self._verdict)

    def contains(self, x: Sequence[float], t: float) -> Optional[bool]:
        """Whether ``x`` certainly lies in the PRS at report time ``t`` (``None`` if ``t`` is
        not a report time)."""
        return self._native.contains([float(v) for v in x], float(t))

    def hull(self, t: float) -> FloatArray:
        """A rigorous bounding box of the PRS at report time ``t``, shape ``(n, 2)``."""
        return self._native.hull(float(t))

    def det_set(self, t: float) -> Dict[str, Any]:
        """The deterministic set at report time ``t``, as the JSON's ``det_set``: ``shape``
        (``"p_ball"``, ``"box"``, ``"parallelotope"`` or ``"zonotope"``), ``center`` and
        ``radius`` (a metric ball around the centre holding it), and by shape ``lo``, ``hi``
        (a box's corners; a parallelotope's in ``y = T x``), ``hull_lo``, ``hull_hi`` (the
        interval hull of a parallelotope, or of a zonotope without its ball), ``generators``
        (a zonotope's, shape ``(k, n)``: the set ``center + sum_j xi_j g_j``, ``|xi_j| <= 1``)
        and ``remainder`` (the metric radius of the ball added to the zonotope; the PRS is the
        zonotope plus the ball of radius ``remainder + r``)."""
        return self._native.det_set(float(t))

    @property
    def members(self) -> List["Result"]:
        """The further sets of an intersection (the PRS is the intersection of this result's
        own set and theirs): further metrics' results, the interval box of a contraction run,
        first-order zonotopes; each a :class:`Result` of its own."""
        return [Result(m) for m in self._native.members]

    @property
    def pieces(self) -> List["Result"]:
        """A split result's pieces (``split = [..]`` or ``split = auto``; empty without a
        split): each piece's :class:`Result`, from its part of the initial box, at the same
        ``delta``. The PRS is their union: this result's hulls, margins and verdict are the
        union's, and :meth:`contains` asks the pieces."""
        return [Result(p) for p in self._native.pieces]

    @property
    def role(self) -> str:
        """What this result is within an intersection: ``"own"`` for an analysis' result,
        ``"metric"`` (a further metric's, at ``delta / K``), ``"box"`` (the interval box of a
        contraction run), ``"first_order"`` (first-order zonotopes) or ``"linearised"`` (first-order
        zonotopes holding the Gaussian part too) for a member."""
        return str(self._native.role)

    def to_json(self) -> str:
        """The CLI's ``ANALYSIS.json`` (``reachc run``), byte for byte."""
        return self._native.to_json()

    def json(self) -> Dict[str, Any]:
        """:meth:`to_json` parsed."""
        return cast(Dict[str, Any], _json.loads(self.to_json()))

    def to_csv(self) -> str:
        """The CLI's ``ANALYSIS.csv``."""
        return self._native.to_csv()

    def summary(self) -> str:
        """The summary ``reachc run`` prints."""
        return self._native.summary()

    def __repr__(self) -> str:
        return repr(self._native)


class Simulation:
    """A Monte Carlo check of a PRS (``reachc simulate``): per-report-time statistics as numpy
    arrays, the coverage statistics and the CLI's JSON."""

    def __init__(self, native: _native.Simulation) -> None:
        self._native = native

    @property
    def analysis(self) -> str:
        return self._native.analysis

    @property
    def paths(self) -> int:
        return self._native.paths

    @property
    def seed(self) -> int:
        return self._native.seed

    @property
    def dt(self) -> float:
        """The largest Euler-Maruyama step used (the steps may differ between report
        intervals)."""
        return self._native.dt

    @property
    def delta(self) -> float:
        return self._native.delta

    @property
    def passed(self) -> bool:
        """Whether the coverage check passed."""
        return self._native.passed

    @cached_property
    def result(self) -> Result:
        """The PRS that was checked."""
        return Result(self._native.result)

    @cached_property
    def _steps(self) -> Dict[str, Any]:
        return self._native.steps()

    @property
    def times(self) -> FloatArray:
        return cast("FloatArray", self._steps["times"])

    @property
    def quantile(self) -> FloatArray:
        """Empirical ``1 - delta`` quantile of the distance to the nominal state (metric
        norm), shape ``(k,)``."""
        return cast("FloatArray", self._steps["quantile"])

    @property
    def state_quantile(self) -> FloatArray:
        """Per state, the half-width of the smallest interval about the nominal state holding
        ``1 - delta`` of the paths, shape ``(k, n)``."""
        return cast("FloatArray", self._steps["state_quantile"])

    @property
    def state_max(self) -> FloatArray:
        """Per state, the largest deviation from the nominal state, shape ``(k, n)``."""
        return cast("FloatArray", self._steps["state_max"])

    @property
    def state_prs(self) -> FloatArray:
        """Per state, the half-width of the PRS's bounding box about the nominal state, shape
        ``(k, n)``: ``state_prs / state_quantile`` is how many times the sample's spread the
        PRS is in each coordinate."""
        return cast("FloatArray", self._steps["state_prs"])

    @property
    def max(self) -> FloatArray:
        """Largest distance to the nominal state, shape ``(k,)``."""
        return cast("FloatArray", self._steps["max"])

    @property
    def prs_radius(self) -> FloatArray:
        return cast("FloatArray", self._steps["prs_radius"])

    @property
    def r(self) -> FloatArray:
        return cast("FloatArray", self._steps["r"])

    @property
    def outside(self) -> npt.NDArray[np.int64]:
        """Paths outside the PRS at each report time, shape ``(k,)``."""
        return cast("npt.NDArray[np.int64]", self._steps["outside"])

    @property
    def fraction(self) -> FloatArray:
        return cast("FloatArray", self._steps["fraction"])

    @property
    def cp_upper(self) -> FloatArray:
        """Clopper-Pearson upper bound of the violation probability, shape ``(k,)``."""
        return cast("FloatArray", self._steps["cp_upper"])

    @cached_property
    def coverage(self) -> Dict[str, Any]:
        """The coverage statistics (horizon, tube, check)."""
        return self._native.coverage()

    def to_json(self) -> str:
        """The CLI's ``ANALYSIS.sim.json``, byte for byte."""
        return self._native.to_json()

    def json(self) -> Dict[str, Any]:
        return cast(Dict[str, Any], _json.loads(self.to_json()))

    def summary(self) -> str:
        return self._native.summary()

    def __repr__(self) -> str:
        return repr(self._native)
