"""Files and figures: CSV logs (:mod:`~stewart.io.csvfile`), plots
(:mod:`~stewart.io.plots`), the generated C model for C programs (:mod:`~stewart.io.capi`)
and the platform as a MuJoCo model (:mod:`~stewart.io.mjcf`)."""

from .._modules import on_first_use

__getattr__ = on_first_use(__name__, __path__)
