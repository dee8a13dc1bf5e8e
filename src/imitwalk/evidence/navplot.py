"""The top view of a course walked: waypoints, each robot's true path, and one robot's own
estimate of it (no simulation here; :mod:`imitwalk.navigate.trial` hands the paths in)."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from matplotlib.figure import Figure
from matplotlib.patches import Circle

from imitwalk.evidence.plots import _figure

__all__ = ["course_figure"]


def course_figure(waypoints: np.ndarray, reach: float, results: Sequence, title: str) -> Figure:
    """The course (``(K, 2)`` waypoints [m], each ringed by ``reach`` [m]) and
    ``results`` (:class:`~imitwalk.navigate.trial.NavResult`): every robot's true path
    (a cross where it fell), and the first robot's estimate of its own path, dashed."""
    fig = _figure(6.4, 5.0)
    ax = fig.add_subplot()
    for k, (x, y) in enumerate(waypoints, 1):
        ax.add_patch(Circle((x, y), reach, fill=False, color="tab:green", lw=1.5))
        ax.annotate(str(k), (x, y), ha="center", va="center", color="tab:green", weight="bold")
    ax.plot([0.0, *waypoints[:, 0]], [0.0, *waypoints[:, 1]], ":", color="tab:green", lw=1)
    for i, r in enumerate(results):
        color = "tab:red" if r.fell else ("tab:blue" if r.finished else "tab:orange")
        ax.plot(
            r.path[:, 0],
            r.path[:, 1],
            color=color,
            lw=1,
            alpha=0.7,
            label="true paths" if i == 0 else None,
        )
        if r.fell and len(r.path):
            ax.plot(*r.path[-1], "x", color="tab:red", ms=8)
    if results and len(results[0].estimate):
        est = results[0].estimate
        ax.plot(
            est[:, 0],
            est[:, 1],
            "--",
            color="black",
            lw=1,
            label=f"robot {results[0].seed}'s own estimate",
        )
    ax.plot(0.0, 0.0, "k^", ms=8)
    ax.set_aspect("equal")
    ax.set_xlabel("x [m] (start heading)")
    ax.set_ylabel("y [m]")
    ax.set_title(title, fontsize=10)
    ax.grid(alpha=0.3)
    ax.legend(loc="best", fontsize=8)
    return fig
