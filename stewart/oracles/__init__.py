"""The independent models and checks the compiled model is tested against: their own numpy
kinematics (:mod:`~stewart.oracles.frames`), the numeric
reference (:mod:`~stewart.oracles.reference`, the paper's equations body by body), the
Newton–Euler formulation (:mod:`~stewart.oracles.newton_euler`), the physics checks
(:mod:`~stewart.oracles.physics`: energy, power balance, complex-step derivatives, statics),
how much the complete model changes the forces (:mod:`~stewart.oracles.exactness`) and the
report of ``stewart validate`` (:mod:`~stewart.oracles.validation`). Only ``validate`` and
the tests import them."""

from .._modules import on_first_use

__getattr__ = on_first_use(__name__, __path__)
