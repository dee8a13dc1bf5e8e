"""The stepping gait: a walk that re-plans its footsteps, their timing and the body's path
every control tick from what the robot measures, in the clip's style.

The parts, each a module:

* :mod:`~imitwalk.step.style`: what imitation keeps of a clip (cadence, stride, double
  support, the swing foot's path, the arms' and waist's swing), scaled to the robot's
  legs; :mod:`~imitwalk.step.gait`: a run's style with what judging needs of it;
  :mod:`~imitwalk.step.schedule`: the nominal start-up and step schedule.
* :mod:`~imitwalk.step.lipm`: the linear inverted pendulum and its DCM;
  :mod:`~imitwalk.step.nominal`: the periodic walk the planner aims at, and its limits;
  :mod:`~imitwalk.step.planner`: where and when the next foot lands, and the ankles'
  share (step location, timing and ZMP adaptation).
* :mod:`~imitwalk.step.estimator`: the state from the IMU, encoders and sole forces;
  :mod:`~imitwalk.step.kinematics`: the robot's forward and inverse kinematics;
  :mod:`~imitwalk.step.swing`: the swing foot; :mod:`~imitwalk.step.joints`: joint
  targets and the servos' feedforward; :mod:`~imitwalk.step.controller`: the tick.
* :mod:`~imitwalk.step.gains`: the gains and their ranges; :mod:`~imitwalk.step.episode`:
  one walk and its cost; :mod:`~imitwalk.step.learn`: the gains by CMA-ES on training
  robots; :mod:`~imitwalk.step.pipeline`: a clip to a finished run (``imitwalk learn``).
"""
