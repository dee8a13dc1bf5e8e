"""Walking to waypoints: the stepping gait steered by the robot's own odometry.

* :mod:`~imitwalk.navigate.course`: a course of waypoints, parsed and checked;
* :mod:`~imitwalk.navigate.navigator`: the policy that steers the stepping gait
  (:class:`~imitwalk.step.controller.SteppingController`) from waypoint to waypoint by
  its leg odometry (:mod:`imitwalk.step.odometry`), with an optional position fix;
* :mod:`~imitwalk.navigate.trial`: a course walked by robots of a protocol, judged by
  the simulator's ground truth (``imitwalk navigate``).
"""

from imitwalk.navigate.course import Course, parse_waypoints
from imitwalk.navigate.navigator import Navigator

__all__ = ["Course", "Navigator", "parse_waypoints"]
