"""Learning diagnostics of a run: learning curves, gyro traces, paths, push recovery.

Like :mod:`imitwalk.evidence.plots`, each function takes data and returns a Figure drawn on the
Agg canvas; nothing here imports MuJoCo.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from matplotlib.figure import Figure
from matplotlib.projections.polar import PolarAxes
from matplotlib.ticker import MaxNLocator

from imitwalk.balance.ticklog import ScheduleEntry, entry_from_dict
from imitwalk.evidence.plots import _figure
from imitwalk.judge.records import PushVerdict

__all__ = ["gyro_traces", "learning_curves", "push_polar", "tick_curves", "torso_paths"]


def _ratio(entry: dict) -> float:
    """The gyro model's prediction RMSE over the no-action baseline's at one iteration
    (NaN before there is a model)."""
    pred = entry.get("prediction") or {}
    if "overall_ratio" in pred:
        return float(pred["overall_ratio"])
    return float(np.mean(pred["ratio"])) if "ratio" in pred else np.nan


def learning_curves(log: Sequence[dict]) -> Figure:
    """Per learning iteration: measured and predicted cost (eq. 6), prediction error as a
    ratio of the no-action baseline's (below 1: the model beats it), and falls; dotted
    lines mark where the scale changes."""
    fig = _figure(8.0, 6.5)
    axes = fig.subplots(3, 1, sharex=True)
    if not log:
        axes[0].set_title("no learning iterations logged")
        return fig
    it = np.arange(len(log))
    val = lambda k: np.array([np.nan if e.get(k) is None else e[k] for e in log], float)  # noqa: E731
    ax = axes[0]
    ax.plot(it, val("cost_measured"), "o-", label="measured")
    if np.isfinite(val("cost_predicted")).any():
        ax.plot(it, val("cost_predicted"), "s--", label="predicted (gyro model)")
    ax.set_ylabel("cost Γ(ω)")
    ax.legend(fontsize=8)
    ax = axes[1]
    ax.plot(it, [_ratio(e) for e in log], "o-", label="gyro model")
    ax.axhline(1.0, color="k", ls="--", lw=0.8, label="no-action baseline")
    ax.set_ylabel("RMSE / baseline")
    ax.legend(fontsize=8)
    ax = axes[2]
    ax.bar(it, val("falls"), color="tab:red", label="falls")
    ax.plot(it, val("robots"), "k_", ms=14, label="robots")
    ax.set_ylabel("falls")
    ax.set_xlabel("learning iteration")
    ax.xaxis.set_major_locator(MaxNLocator(integer=True))
    ax.legend(fontsize=8)
    scales = [e.get("scale") for e in log]
    for i, s in enumerate(scales):
        if i == 0 or s != scales[i - 1]:
            for a in axes:
                a.axvline(i - 0.5, color="0.6", ls=":", lw=1.0)
            where = axes[0].get_xaxis_transform()  # x: data, y: axes fraction
            axes[0].text(i - 0.4, 1.01, f"scale {s:g}", transform=where, fontsize=8)
    return fig


def gyro_traces(
    before: np.ndarray,
    after: np.ndarray,
    dt: float,
    labels: tuple[str, str] = ("before: open loop", "after: learned"),
    fall_times: tuple[float | None, float | None] = (None, None),
) -> Figure:
    """Torso gyro ω_x, ω_y, ω_z [rad/s] of two ``(N, 3)`` runs sampled every ``dt`` [s];
    a run's fall, if given [s], is marked."""
    fig = _figure(8.0, 6.0)
    axes = fig.subplots(3, 1, sharex=True)
    for w, name, color, tf in zip(
        (before, after), labels, ("tab:gray", "tab:green"), fall_times, strict=True
    ):
        w = np.asarray(w, dtype=float).reshape(-1, 3)
        t = np.arange(len(w)) * dt
        for i, ax in enumerate(axes):
            rms = float(np.sqrt(np.mean(w[:, i] ** 2))) if len(w) else np.nan
            ax.plot(t, w[:, i], color=color, lw=0.8, label=f"{name} (RMS {rms:.2f})")
            if tf is not None:
                ax.axvline(tf, color=color, ls="--", lw=1.0)
    for i, ax in enumerate(axes):
        ax.set_ylabel(f"ω_{'xyz'[i]} [rad/s]")
        ax.legend(fontsize=7, loc="upper right")
    axes[-1].set_xlabel("time [s]")
    return fig


def torso_paths(
    runs: Sequence[tuple[str, np.ndarray]], commanded: np.ndarray | None = None
) -> Figure:
    """Top view of torso paths: ``runs`` of (label, ``(N, 3)`` positions [m]), each drawn
    from its start, and the ``commanded`` ``(N, 2)`` walking-frame path [m] dashed."""
    fig = _figure(6.0, 4.5)
    ax = fig.add_subplot()
    if commanded is not None and len(commanded):
        c = np.asarray(commanded, dtype=float)
        ax.plot(c[:, 0], c[:, 1], "k--", lw=1.0, label="commanded")
    for (name, pos), color in zip(runs, ("tab:gray", "tab:green", "tab:blue"), strict=False):
        p = np.asarray(pos, dtype=float).reshape(-1, 3)
        if len(p):
            ax.plot(p[:, 0] - p[0, 0], p[:, 1] - p[0, 1], color=color, lw=1.0, label=name)
            ax.plot(p[-1, 0] - p[0, 0], p[-1, 1] - p[0, 1], "o", color=color, ms=4)
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.set_title("Torso path, seen from above")
    ax.legend(fontsize=7, loc="best")
    return fig


def tick_curves(log: Sequence[dict]) -> Figure:
    """A per-tick run's learning (its ``log.jsonl`` lines): each schedule iteration's falls,
    measured eq.-6 cost Γ and its model's held-out one-tick error over "nothing changes";
    dotted lines mark where the scale changes."""
    entries = [entry_from_dict(line) for line in log]
    sched = [e for e in entries if isinstance(e, ScheduleEntry)]
    fig = _figure(8.0, 6.0)
    axes = fig.subplots(3, 1, sharex=True)
    if not sched:
        axes[0].set_title("no schedule iterations logged (the model-based law was off)")
        return fig
    it = np.arange(len(sched))
    axes[0].bar(it, [e.walks.falls for e in sched], color="tab:red", label="falls")
    axes[0].plot(it, [e.walks.robots for e in sched], "k_", ms=14, label="robots")
    axes[0].set_ylabel("falls")
    axes[1].plot(it, [e.walks.cost for e in sched], "o-", label="measured Γ")
    axes[1].set_ylabel("cost Γ(ω)")
    ratio = [np.nan if not e.held_out else e.held_out["ratio_to_persistence"] for e in sched]
    axes[2].plot(it, ratio, "o-", label="model / persistence")
    axes[2].axhline(1.0, color="k", ls="--", lw=0.8, label='"nothing changes"')
    axes[2].set_ylabel("held-out MSE ratio")
    axes[2].set_xlabel("schedule iteration")
    axes[2].xaxis.set_major_locator(MaxNLocator(integer=True))
    for ax in axes:
        ax.legend(fontsize=8)
    scales = [e.scale for e in sched]
    for i, s in enumerate(scales):
        if i == 0 or s != scales[i - 1]:
            for a in axes:
                a.axvline(i - 0.5, color="0.6", ls=":", lw=1.0)
            where = axes[0].get_xaxis_transform()
            axes[0].text(i - 0.4, 1.01, f"{s:g}", transform=where, fontsize=8)
    return fig


def push_polar(result: PushVerdict) -> Figure:
    """Push recovery (:func:`imitwalk.judge.pushes.push_recovery`) as a polar plot: for each
    controller, the largest kick survived [m/s] at each direction (the phases of the
    gait cycle spread around it, ±20°)."""
    fig = _figure(6.0, 6.0)
    ax = fig.add_subplot(projection="polar")
    assert isinstance(ax, PolarAxes)  # what projection="polar" makes
    angles = {"forward": 0.0, "left": np.pi / 2, "back": np.pi, "right": -np.pi / 2}
    colors = ("tab:green", "tab:blue", "tab:orange", "tab:gray")
    for (name, side), color in zip(result.controllers.items(), colors, strict=False):
        dirs: list[float] = []  # the direction of each point [rad]
        kicks: list[float] = []  # the largest kick survived there [m/s]
        for d, speeds in side.table.items():
            spread = np.linspace(-np.pi / 9, np.pi / 9, len(speeds))
            dirs.extend(angles[d] + spread)
            kicks.extend(speeds)
        order = np.argsort(np.mod(dirs, 2 * np.pi))
        th, r = np.mod(np.asarray(dirs)[order], 2 * np.pi), np.asarray(kicks)[order]
        ax.plot(np.r_[th, th[:1]], np.r_[r, r[:1]], "o-", color=color, ms=3, lw=1, label=name)
    ax.set_theta_zero_location("N")
    ax.set_xticks(list(angles.values()), list(angles))
    top = result.settings.top_mps
    if top:
        ax.set_ylim(0, top)
    ax.set_title("Largest kick survived for 5 s [m/s], by direction and gait phase", fontsize=9)
    ax.legend(fontsize=7, loc="lower left", bbox_to_anchor=(-0.1, -0.12))
    return fig
