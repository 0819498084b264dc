"""matplotlib pictures of reachc results (the optional extra: ``pip install ./python[plot]``).

The same content as ``reachc run --plot`` / ``reachc plot``: the sets in a 2-D projection with
sample paths, the radii against the Monte Carlo quantiles, the rates.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any, Optional, Sequence, Tuple, cast

import numpy as np
import numpy.typing as npt

from . import Result, Simulation

if TYPE_CHECKING:  # pragma: no cover
    from matplotlib.axes import Axes

__all__ = ["sets", "radii", "rates", "report_times"]


def _axes(ax: Optional["Axes"]) -> "Axes":
    if ax is not None:
        return ax
    import matplotlib.pyplot as plt

    return plt.gca()


def report_times(result: Result, count: int = 9) -> npt.NDArray[np.int64]:
    """Indices of ``count`` report times spread evenly from 0 to the horizon."""
    k = len(result.times)
    return np.unique(np.linspace(0, k - 1, min(count, k)).round().astype(np.int64))


def _ellipse(
    center: npt.NDArray[np.float64], p: npt.NDArray[np.float64], r: float, dims: Tuple[int, int]
) -> npt.NDArray[np.float64]:
    """Boundary of the projection onto ``dims`` of ``{x : (x - c)' P (x - c) <= r^2}``."""
    q = np.linalg.inv(p)[np.ix_(dims, dims)]  # the projection's shape matrix is (P^-1)_SS
    w, v = np.linalg.eigh(q)
    a = np.linspace(0.0, 2.0 * np.pi, 121)
    unit = np.stack([np.cos(a), np.sin(a)])
    pts = v @ (np.sqrt(np.maximum(w, 0.0))[:, None] * unit) * r
    return cast(npt.NDArray[np.float64], pts.T + center[list(dims)])


def sets(
    result: Result,
    ax: Optional["Axes"] = None,
    dims: Tuple[int, int] = (0, 1),
    steps: Optional[Sequence[int]] = None,
    paths: Optional[npt.ArrayLike] = None,
    color: str = "C0",
    label: Optional[str] = None,
    **kwargs: Any,
) -> "Axes":
    """The PRS at some report times (``steps``: indices, default nine spread over the
    horizon) projected onto the states ``dims``: metric balls (ellipses) for the contraction
    method, bounding boxes for the interval method; the nominal trajectory, and ``paths``
    (array ``(paths, k, n)`` from :meth:`reachc.Spec.sample_paths`) in grey."""
    from matplotlib.patches import Polygon, Rectangle

    ax = _axes(ax)
    i, j = dims
    if paths is not None:
        p = np.asarray(paths)
        for path in p:
            ax.plot(path[:, i], path[:, j], color="0.6", lw=0.4, alpha=0.5, zorder=1)
    idx = report_times(result) if steps is None else np.asarray(steps)
    for n, k in enumerate(idx):
        lab = label if n == 0 else None
        if result.method == "contraction":
            pts = _ellipse(result.nominal[k], result.metric, float(result.prs_radius[k]), dims)
            ax.add_patch(
                Polygon(pts, closed=True, fill=False, ec=color, label=lab, zorder=3, **kwargs)
            )
        else:
            lo, hi = result.lo[k], result.hi[k]
            ax.add_patch(
                Rectangle(
                    (lo[i], lo[j]),
                    hi[i] - lo[i],
                    hi[j] - lo[j],
                    fill=False,
                    ec=color,
                    label=lab,
                    zorder=3,
                    **kwargs,
                )
            )
    ax.plot(result.nominal[:, i], result.nominal[:, j], color="k", lw=0.8, zorder=2)
    ax.set_xlabel(result.states[i])
    ax.set_ylabel(result.states[j])
    ax.autoscale_view()
    return ax


def radii(
    result: Result, simulation: Optional[Simulation] = None, ax: Optional["Axes"] = None
) -> "Axes":
    """The PRS radius (metric norm) against time, with the Monte Carlo ``1 - delta`` quantile
    and largest distance of ``simulation`` if given."""
    ax = _axes(ax)
    ax.plot(result.times, result.prs_radius, label="PRS radius")
    ax.plot(result.times, result.r, ls="--", label="stochastic radius r_t")
    if simulation is not None:
        ax.plot(simulation.times, simulation.quantile, label=f"MC quantile (1 - {simulation.delta:g})")
        ax.plot(simulation.times, simulation.max, ls=":", label="MC max")
    ax.set_xlabel("t")
    ax.set_ylabel("radius (metric norm)")
    ax.legend()
    return ax


def rates(result: Result, ax: Optional["Axes"] = None) -> "Axes":
    """The contraction rate ``c`` and noise level ``sigma`` on each step."""
    ax = _axes(ax)
    ax.plot(result.times[1:], result.rates[1:], label="c")
    ax.plot(result.times[1:], result.sigmas[1:], label="sigma")
    ax.set_xlabel("t")
    ax.legend()
    return ax
