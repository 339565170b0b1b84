"""Studies over many states, in chunks, locally or on a Dask cluster
(:mod:`~stewart.studies.execution`): workspaces (:mod:`~stewart.studies.workspace`), force
and joint-load envelopes (:mod:`~stewart.studies.envelope`), design sweeps
(:mod:`~stewart.studies.sweep`) and a rotary rig's motor sizing
(:mod:`~stewart.studies.motor_sizing`)."""

from .._modules import on_first_use

__getattr__ = on_first_use(__name__, __path__)
