"""Learning diagnostics of a run: learning curves, gyro traces, the robustness heat map.

Like :mod:`imitwalk.plots`, each function takes data and returns a Figure drawn on the
Agg canvas; nothing here imports MuJoCo.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from matplotlib.figure import Figure
from matplotlib.ticker import MaxNLocator

from imitwalk.plots import _figure

__all__ = ["gyro_traces", "learning_curves", "robustness_heatmap"]


def _ratio(entry: dict, level: str) -> float:
    """A model's prediction RMSE over the no-action baseline's at one iteration."""
    pred = entry.get("prediction", {}).get(level, {})
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
    for key, style, level in (
        ("cost_predicted", "s--", "tick"),
        ("step_cost_predicted", "^:", "step"),
    ):
        if np.isfinite(val(key)).any():
            ax.plot(it, val(key), style, label=f"predicted ({level} model)")
    ax.set_ylabel("cost Γ(ω)")
    ax.legend(fontsize=8)
    ax = axes[1]
    for level in sorted({k for e in log for k in e.get("prediction", {})}):
        ax.plot(it, [_ratio(e, level) for e in log], "o-", label=f"{level} model")
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


def robustness_heatmap(robustness: dict) -> Figure:
    """Survival per perturbation cell (rows) for the learned controller and open loop."""
    cells = robustness.get("cells", {})
    names = list(cells)
    modes = ("learned", "open_loop")
    M = np.array(
        [[cells[c][m]["survived"] / max(1, cells[c][m]["of"]) for m in modes] for c in names]
    ).reshape(-1, 2)
    fig = _figure(5.0, 1.2 + 0.32 * max(1, len(names)))
    ax = fig.add_subplot()
    if not names:
        ax.set_axis_off()
        ax.set_title("Robustness: no cells")
        return fig
    im = ax.imshow(M, cmap="RdYlGn", vmin=0.0, vmax=1.0, aspect="auto")
    for (i, j), _v in np.ndenumerate(M):
        c = cells[names[i]][modes[j]]
        text = f"{c['survived']}/{c['of']}  {c.get('distance_m', np.nan):.2f} m"
        ax.text(j, i, text, ha="center", va="center", fontsize=8)
    ax.set_xticks([0, 1], ["learned", "open loop"])
    ax.set_yticks(range(len(names)), names)
    fig.colorbar(im, ax=ax, label="fraction survived")
    ax.set_title("Robustness: survived / robots, mean distance")
    return fig
