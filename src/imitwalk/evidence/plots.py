"""Figures of a run: the paper's Figs. 3, 4, 6, 7 and 8 (learning diagnostics: :mod:`curves`).

Every function takes data and returns a :class:`matplotlib.figure.Figure` drawn on the
Agg canvas (no pyplot, so no global figure state and no GUI backend). Nothing here
imports MuJoCo or simulates: :mod:`imitwalk.evidence.report` runs the robot, renders the images
and hands them in. :func:`png_bytes` encodes a figure.
"""

from __future__ import annotations

import io
from collections.abc import Sequence
from typing import TYPE_CHECKING

import numpy as np
from matplotlib import colormaps
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from mpl_toolkits.mplot3d.axes3d import Axes3D

    from imitwalk.mocap.motion import Motion
    from imitwalk.paper.gait import GaitModel

__all__ = [
    "example_ticks",
    "fig3_subspace",
    "fig4_embedding",
    "fig6_optimized",
    "fig7_schedule",
    "film_strip",
    "png_bytes",
    "skeleton_strip",
]

TWO_PI = 2.0 * np.pi
#: Stick-figure bones between :data:`imitwalk.mocap.KEYPOINTS`; the side is the first letter.
BONES = (
    ("pelvis", "l_hip"),
    ("l_hip", "l_knee"),
    ("l_knee", "l_ankle"),
    ("l_ankle", "l_toe"),
    ("pelvis", "r_hip"),
    ("r_hip", "r_knee"),
    ("r_knee", "r_ankle"),
    ("r_ankle", "r_toe"),
    ("pelvis", "neck"),
    ("neck", "head"),
    ("neck", "l_shoulder"),
    ("l_shoulder", "l_elbow"),
    ("l_elbow", "l_wrist"),
    ("neck", "r_shoulder"),
    ("r_shoulder", "r_elbow"),
    ("r_elbow", "r_wrist"),
)
SIDE_COLOR = {"l_": "tab:blue", "r_": "tab:red"}
RINGS = {"facecolors": "none", "edgecolors": "red"}


def _figure(width: float, height: float) -> Figure:
    fig = Figure(figsize=(width, height), dpi=100, layout="constrained")
    FigureCanvasAgg(fig)
    return fig


def png_bytes(fig: Figure, dpi: float = 100) -> bytes:
    """The figure as PNG bytes."""
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=dpi)
    return buf.getvalue()


def example_ticks(n_ticks: int, count: int = 6) -> np.ndarray:
    """``(count,)`` evenly spaced loop ticks, the example poses of :func:`fig3_subspace`."""
    return np.linspace(0, n_ticks, count, endpoint=False).astype(int)


def _pcs(gait: GaitModel, scale: float) -> np.ndarray:
    """``(N, 3)`` the reference loop at ``scale`` on the first three PCs."""
    return gait.subspace.transform(gait.ref.at_scale(scale)[1])[:, :3]


def _closed(X: np.ndarray) -> np.ndarray:
    """A loop ``(N, 3)`` with its first point repeated at the end, to draw it closed."""
    return np.vstack([X, X[:1]])


def _split(title: str) -> tuple[Figure, Axes3D, list[Axes]]:
    """A figure with a 3-D axes on the left and r, h against φ on the right."""
    fig = _figure(10.0, 4.6)
    gs = fig.add_gridspec(2, 2, width_ratios=[1.4, 1.0])
    ax = fig.add_subplot(gs[:, 0], projection="3d")
    rh = [fig.add_subplot(gs[i, 1]) for i in range(2)]
    for a, name in zip(rh, ("r", "h"), strict=True):
        a.set_ylabel(name)
        a.set_xlim(0, TWO_PI)
    rh[1].set_xlabel("φ [rad]")
    fig.suptitle(title)
    return fig, ax, rh


def _pc_labels(ax: Axes3D, gait: GaitModel) -> None:
    evr = getattr(gait.subspace, "explained_variance_ratio_", np.full(3, np.nan))
    for i, set_label in enumerate((ax.set_xlabel, ax.set_ylabel, ax.set_zlabel)):
        set_label(f"PC{i + 1} ({100 * evr[i]:.0f} %)")


def fig3_subspace(
    gait: GaitModel,
    scale: float,
    pose_images: Sequence[np.ndarray] | None = None,
    ticks: Sequence[int] | np.ndarray | None = None,
) -> Figure:
    """Fig. 3: the gait loop in (PC1, PC2, PC3), blue diamonds along the fitted loop and
    red circles, numbered, at example poses (``ticks``, default :func:`example_ticks`);
    ``pose_images`` (one ``(H, W, 3)`` image per tick) are shown beside, numbered alike."""
    X = _pcs(gait, scale)  # (N, 3)
    fitted = gait.embedding(scale).loop(200)[:, :3]
    count = len(pose_images) if pose_images else 6
    picked = example_ticks(len(X), count) if ticks is None else np.asarray(ticks, dtype=int)
    cols = min(3, len(pose_images)) if pose_images else 0
    rows = int(np.ceil(len(pose_images) / cols)) if pose_images else 1
    fig = _figure(6.0 + 2.0 * cols, 5.5)
    gs = fig.add_gridspec(rows, 1 + cols, width_ratios=[3.0] + [1.0] * cols, wspace=0.0)
    ax = fig.add_subplot(gs[:, 0], projection="3d")
    ax.plot(*fitted.T, color="tab:blue", lw=1.0)
    every = max(1, len(X) // 24)
    ax.scatter(*X[::every].T, marker="D", s=14, color="tab:blue", label="postures of one cycle")
    P = X[picked]
    ax.scatter(*P.T, s=70, lw=1.8, label="example poses", **RINGS)
    for i, p in enumerate(P):
        ax.text(*p, f" {i + 1}", color="red", fontsize=10, weight="bold")
    _pc_labels(ax, gait)
    ax.set_title(f"Posture subspace, scale {scale:g}")
    ax.legend(loc="upper left", fontsize=8)
    for i, img in enumerate(pose_images or []):
        a = fig.add_subplot(gs[i // cols, 1 + i % cols])
        a.imshow(img)
        a.set_axis_off()
        a.set_title(f"{i + 1}", color="red", weight="bold")
    return fig


def fig4_embedding(gait: GaitModel, scale: float) -> Figure:
    """Fig. 4: training points (blue dots) and the fitted action space g(φ) (red curve) in
    the (x_θ, y_θ, z_θ) frame of eq. 1 centred on μ; beside, r and h against φ (eq. 2)."""
    emb = gait.embedding(scale)
    X = gait.subspace.transform(gait.ref.at_scale(scale)[1])  # (N, k)
    L = (X[:, :3] - emb.mean_) @ emb.basis_.T  # (N, 3) in the (x_θ, y_θ, z_θ) frame
    G = (emb.loop(200)[:, :3] - emb.mean_) @ emb.basis_.T
    fig, ax, rh = _split(f"Embedded action space, scale {scale:g}")
    ax.scatter(*L.T, s=8, color="tab:blue", label="training points")
    ax.plot(*G.T, color="red", lw=2.0, label="embedded action space g(φ)")
    reach = 1.1 * float(np.max(np.abs(L)))
    for v, name in zip(np.eye(3) * reach, ("x_θ", "y_θ", "z_θ"), strict=True):
        ax.quiver(0, 0, 0, *v, color="k", lw=0.8, arrow_length_ratio=0.08)
        ax.text(*(1.05 * v), name)
    ax.set_xlabel("x_θ")
    ax.set_ylabel("y_θ")
    ax.set_zlabel("z_θ")
    ax.legend(loc="upper left", fontsize=8)
    cyl = emb.to_cylinder(X)  # (N, 3) φ, r, h
    phi = np.linspace(0.0, TWO_PI, 200)
    g = emb.g(phi)  # (200, 2)
    for i, a in enumerate(rh):
        a.plot(cyl[:, 0], cyl[:, 1 + i], ".", ms=3, color="tab:blue")
        a.plot(phi, g[:, i], color="red")
    return fig


def fig6_optimized(
    gait: GaitModel, scale: float, actions: np.ndarray, postures: np.ndarray | None = None
) -> Figure:
    """Fig. 6: executed actions ``(T, 3)`` (φ, r, h), mapped by g into the subspace, against
    the reference loop; beside, r and h of the actions against φ with g(φ). ``postures``
    ``(T', 3)``, if given, are the executed joint targets projected by C (balance channels
    included), drawn in green."""
    emb = gait.embedding(scale)
    A = np.asarray(actions, dtype=float).reshape(-1, 3)
    fig, ax, rh = _split(f"Optimised walking pattern in the subspace, scale {scale:g}")
    ax.plot(*_closed(_pcs(gait, scale)).T, color="tab:blue", lw=2.0, label="original loop")
    if len(A):
        Y = emb.from_cylinder(A)[:, :3]  # (T, 3)
        ax.plot(*Y.T, color="red", lw=0.5, alpha=0.6)
        ax.scatter(*Y.T, s=6, color="red", label=f"optimised ({len(A)} ticks)")
    else:
        ax.set_title("no loop actions were executed", color="red", fontsize=9)
    if postures is not None and len(postures):
        P = np.asarray(postures, dtype=float)[:, :3]
        ax.plot(*P.T, color="tab:green", lw=0.8, alpha=0.8, label="executed joint targets")
    _pc_labels(ax, gait)
    ax.legend(loc="upper left", fontsize=8)
    phi = np.linspace(0.0, TWO_PI, 200)
    g = emb.g(phi)
    for i, a in enumerate(rh):
        a.plot(phi, g[:, i], color="tab:blue", lw=2.0, label="g(φ)")
        a.plot(np.mod(A[:, 0], TWO_PI), A[:, 1 + i], ".", ms=2, color="red", label="executed")
    rh[1].legend(fontsize=8)
    return fig


def fig7_schedule(
    gait: GaitModel,
    scales_passed: Sequence[float],
    actions: np.ndarray | None = None,
    reached: float | None = None,
) -> Figure:
    """Fig. 7: the pattern at each scale of the schedule in PC space (passed ones coloured,
    the rest grey) and the reference's largest scale (the target) dashed. The scale
    reached (``reached``; default: the last scale passed, lower if the run backed off,
    ``LearnConfig.back_off_to``) is highlighted with red circles: on the last cycle of
    executed ``actions`` ``(T, 3)`` (φ, r, h) at that scale if given (the paper's
    optimisation result), else on its reference loop."""
    passed = [float(s) for s in scales_passed]
    fig = _figure(6.5, 5.2)
    ax = fig.add_subplot(projection="3d")
    colors = iter(colormaps["viridis"](np.linspace(0.15, 0.85, max(1, len(passed)))))
    for s in gait.scales:
        X = _closed(_pcs(gait, s))
        if any(abs(s - p) < 1e-9 for p in passed):
            ax.plot(*X.T, color=next(colors), lw=1.2, label=f"{s:g}")
        else:
            ax.plot(*X.T, color="0.7", lw=0.8, ls=":")
    target = float(np.max(gait.ref.scales))
    if all(abs(target - s) > 1e-9 for s in gait.scales):
        X = _closed(_pcs(gait, target))
        ax.plot(*X.T, color="k", ls="--", lw=1.0, label=f"target {target:g}")
    if passed:
        final = max(passed) if reached is None else float(reached)
        A = np.asarray(actions if actions is not None else [], dtype=float).reshape(-1, 3)
        A = A[-gait.n_ticks :]
        X = gait.embedding(final).from_cylinder(A)[:, :3] if len(A) else _pcs(gait, final)
        X = X[:: max(1, len(X) // 30)]
        ax.scatter(*X.T, s=40, lw=1.5, label=f"reached {final:g}", **RINGS)
        title = f"Motion pattern scaling: reached {final:g} of the schedule"
        if final < max(passed) - 1e-9:
            title += f" (passed {max(passed):g}, backed off)"
        ax.set_title(title)
    else:
        ax.set_title("Motion pattern scaling: no scale of the schedule was passed")
    _pc_labels(ax, gait)
    if ax.get_legend_handles_labels()[0]:
        ax.legend(title="scale", fontsize=7, loc="upper left")
    return fig


def film_strip(images: Sequence[np.ndarray], titles: Sequence[str], label: str = "") -> Figure:
    """One row of ``(H, W, 3)`` images with a title each (Fig. 8's rows)."""
    n = max(1, len(images))
    h, w = images[0].shape[:2] if len(images) else (3, 4)
    fig = _figure(1.9 * n, 1.9 * h / w + 0.5)
    axes = fig.subplots(1, n, squeeze=False)[0]
    for ax, img, title in zip(axes, images, titles, strict=False):
        ax.imshow(img)
        ax.set_title(title, fontsize=8)
    for ax in axes:
        ax.set_axis_off()
    if label:
        fig.suptitle(label, fontsize=10)
    return fig


def skeleton_strip(motion: Motion, frames: Sequence[int], label: str = "") -> Figure:
    """The human stick figure from ``motion.keypoints`` at ``frames``, seen from the side
    (horizontal axis: the walking direction [m], each panel centred on the pelvis; left
    limbs blue, right red)."""
    from imitwalk.mocap.cycles import heading

    kp = motion.keypoints
    fwd = heading(motion)[:, :2]  # (T, 2) walking direction, from the hips
    ground = min(float(np.min(kp[k][:, 2])) for k in ("l_toe", "r_toe", "l_ankle", "r_ankle"))
    top = max(float(np.max(v[:, 2])) for v in kp.values())
    fig = _figure(1.9 * max(1, len(frames)), 3.0)
    axes = fig.subplots(1, max(1, len(frames)), squeeze=False)[0]
    for ax, f in zip(axes, frames, strict=False):
        d = fwd[f]
        u0 = float(kp["pelvis"][f, :2] @ d)
        for a, b in BONES:
            if a in kp and b in kp:
                seg = np.array([kp[a][f], kp[b][f]])  # (2, 3)
                color = SIDE_COLOR.get(b[:2], "k")
                ax.plot(seg[:, :2] @ d - u0, seg[:, 2] - ground, color=color, lw=2.2)
        ax.axhline(0.0, color="0.5", lw=1.0)
        ax.set_xlim(-0.7, 0.7)
        ax.set_ylim(-0.05, top - ground + 0.1)
        ax.set_aspect("equal")
        ax.set_axis_off()
        ax.set_title(f"frame {f} ({f / motion.fps:.2f} s)", fontsize=8)
    if label:
        fig.suptitle(label, fontsize=10)
    return fig
