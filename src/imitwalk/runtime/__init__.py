"""A learned controller off the simulator: load an export, feed it sensor readings, send
its joint targets (see :mod:`imitwalk.runtime.controller`).

This package imports NumPy and MuJoCo (kinematics only); no SciPy, Bullet, mink,
matplotlib or PyTorch, and nothing of imitwalk's learning or judging.
"""

from __future__ import annotations

from imitwalk.runtime.bundle import Bundle, read_bundle, write_bundle
from imitwalk.runtime.controller import Controller
from imitwalk.runtime.sensors import SensorLayout

__all__ = ["Bundle", "Controller", "SensorLayout", "read_bundle", "write_bundle"]
