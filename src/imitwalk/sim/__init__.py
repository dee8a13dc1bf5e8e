"""Simulation: the MuJoCo plant (:mod:`imitwalk.sim.mujoco`), the PyBullet plant
(:mod:`imitwalk.sim.bullet`), their shared types (:mod:`imitwalk.sim.types`), the servo
model, rendering, the stand check, the robots a controller learns and is judged on
(perturbed training robots, :mod:`imitwalk.sim.perturb`; the named protocols' robots,
:mod:`imitwalk.sim.protocol`, with their JSON in :mod:`imitwalk.sim.protocols`), and the
walking metrics of a rollout.

Import the modules themselves: this package does not import MuJoCo.
"""
