"""Offscreen rendering of rollouts to PNG and MP4 on the CPU.

Uses MuJoCo's renderer with fast settings (no shadows, no reflections, no
multisampling): about 100 frames/s at 640×480 with ``MUJOCO_GL=egl``. The
variable must be set before MuJoCo is first imported, so :func:`ensure_gl`
sets it (to ``egl`` unless the user chose another backend) and this module
is imported lazily by the CLI.
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from pathlib import Path
from typing import Any

os.environ.setdefault("MUJOCO_GL", "egl")

import imageio.v3 as iio
import mujoco
import numpy as np

from imitwalk.robots import Robot

__all__ = ["Renderer", "render_frames", "save_png", "write_mp4"]


#: The camera looks at this fraction of the robot's standing height above the floor.
LOOK_AT = 0.45


class Renderer:
    """Renders ``qpos`` states of one robot (its own meshes and materials), following its
    torso with the camera.

    Args:
        robot: the robot to draw.
        width, height: image size [px].
        distance: camera distance, in the robot's standing heights (the camera keeps the
            same framing for a robot of any size); azimuth, elevation: [deg].
        markers: ``(K, 2)`` points on the floor [m] (world frame) drawn as discs of
            ``marker_radius`` [m], e.g. a course's waypoints; ``None``: none.
    """

    def __init__(
        self,
        robot: Robot,
        width: int = 640,
        height: int = 480,
        distance: float = 2.3,
        azimuth: float = 120.0,
        elevation: float = -12.0,
        markers: np.ndarray | None = None,
        marker_radius: float = 0.05,
    ):
        self.model = m = robot.compile()
        self._look = LOOK_AT * robot.height
        distance = distance * robot.height
        m.vis.quality.offsamples = 0
        m.vis.quality.shadowsize = 0
        m.vis.global_.offwidth = max(width, int(m.vis.global_.offwidth))
        m.vis.global_.offheight = max(height, int(m.vis.global_.offheight))
        for i in range(m.nmat):
            m.mat_reflectance[i] = 0.0
        self.data = mujoco.MjData(m)
        self._r = mujoco.Renderer(m, height=height, width=width)
        self._opt = mujoco.MjvOption()
        self._cam = mujoco.MjvCamera()
        self._cam.type = mujoco.mjtCamera.mjCAMERA_FREE
        self._cam.distance, self._cam.azimuth, self._cam.elevation = distance, azimuth, elevation
        scene = self._r.scene
        scene.flags[mujoco.mjtRndFlag.mjRND_SHADOW] = False
        scene.flags[mujoco.mjtRndFlag.mjRND_REFLECTION] = False
        self._torso = m.body(robot.torso).id
        self._markers = np.zeros((0, 2)) if markers is None else np.asarray(markers, float)
        self._marker_radius = marker_radius

    def frame(self, qpos: np.ndarray) -> np.ndarray:
        """One ``(H, W, 3)`` uint8 image of the robot in state ``qpos`` ``(nq,)``."""
        self.data.qpos[:] = qpos
        mujoco.mj_forward(self.model, self.data)
        look = self.data.xpos[self._torso].copy()
        look[2] = self._look
        self._cam.lookat[:] = look
        self._r.update_scene(self.data, camera=self._cam, scene_option=self._opt)
        self._r.scene.flags[mujoco.mjtRndFlag.mjRND_SHADOW] = False
        self._r.scene.flags[mujoco.mjtRndFlag.mjRND_REFLECTION] = False
        self._draw_markers()
        return self._r.render().copy()

    def _draw_markers(self) -> None:
        scene = self._r.scene
        for x, y in self._markers:
            if scene.ngeom >= scene.maxgeom:
                return
            mujoco.mjv_initGeom(
                scene.geoms[scene.ngeom],
                mujoco.mjtGeom.mjGEOM_CYLINDER,
                np.array([self._marker_radius, 0.001, 0.0]),
                np.array([x, y, 0.001]),
                np.eye(3).ravel(),
                np.array([0.1, 0.7, 0.2, 0.6], dtype=np.float32),
            )
            scene.ngeom += 1

    def close(self) -> None:
        """Release the GL context."""
        self._r.close()


def render_frames(
    robot: Robot, qpos: np.ndarray, dt: float, fps: float = 30.0, **kw: Any
) -> list[np.ndarray]:
    """Render ``(N, nq)`` states sampled every ``dt`` [s] at ``fps`` frames per second."""
    if len(qpos) == 0:
        return []
    idx = np.arange(0, len(qpos), max(1, round(1.0 / (fps * dt))))
    r = Renderer(robot, **kw)
    try:
        return [r.frame(qpos[i]) for i in idx]
    finally:
        r.close()


def save_png(image: np.ndarray, path: str | Path) -> Path:
    """Write one image as PNG."""
    path = Path(path)
    iio.imwrite(path, image)
    return path


def write_mp4(frames: Sequence[np.ndarray], path: str | Path, fps: float = 30.0) -> Path:
    """Encode ``frames`` (each ``(H, W, 3)`` uint8, all the same size) as H.264 MP4
    (yuv420p, browser-playable) with imageio-ffmpeg; odd sizes are padded to even."""
    import imageio_ffmpeg

    if len(frames) == 0:
        raise ValueError("no frames to encode")
    path = Path(path)
    tmp = path.with_name(path.stem + ".tmp" + path.suffix)
    h, w = frames[0].shape[:2]
    pad = ((0, h % 2), (0, w % 2), (0, 0))
    writer = imageio_ffmpeg.write_frames(
        str(tmp),
        (w + w % 2, h + h % 2),
        fps=fps,
        codec="libx264",
        pix_fmt_out="yuv420p",
        macro_block_size=2,
        output_params=["-movflags", "+faststart"],
    )
    writer.send(None)
    try:
        for f in frames:
            writer.send(np.ascontiguousarray(np.pad(np.asarray(f, dtype=np.uint8)[..., :3], pad)))
    finally:
        writer.close()
    tmp.replace(path)
    return path
