"""Identification of a built machine's inertial and friction parameters: the base
parameters the forces determine (:mod:`~stewart.identification.base_parameters`), the
least-squares estimate from measured logs (:mod:`~stewart.identification.identify`) and the
excitation trajectories that make it well conditioned
(:mod:`~stewart.identification.excitation`)."""

from .._modules import on_first_use

__getattr__ = on_first_use(__name__, __path__)
