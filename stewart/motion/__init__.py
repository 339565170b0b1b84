"""Motion: trajectories (:mod:`~stewart.motion.trajectory`), controllers and actuators
(:mod:`~stewart.motion.control`), the closed-loop simulator
(:mod:`~stewart.motion.simulation`), and trajectory optimization with the model as CasADi
functions (:mod:`~stewart.motion.casadi_functions`, :mod:`~stewart.motion.optimize`)."""

from .._modules import on_first_use

__getattr__ = on_first_use(__name__, __path__)
