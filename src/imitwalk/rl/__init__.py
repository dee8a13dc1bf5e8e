"""A policy trained by reinforcement learning, as a controller like any other.

:mod:`imitwalk.rl.observation` says what such a policy sees (only the robot's own
sensors, the gait phase, its previous action and, for a residual policy, the stepping
gait's command); :mod:`imitwalk.rl.actor` plays a trained policy on any
:class:`~imitwalk.sim.mujoco.Plant`, so the judge walks it on the same robots as every
other controller. The environment it is trained in is :mod:`imitwalk.envs`.
"""

from imitwalk.rl.observation import ACTIONS, ObservationLayout, clock_phase

__all__ = ["ACTIONS", "ObservationLayout", "clock_phase"]
