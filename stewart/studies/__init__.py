"""Studies over many states, in chunks, locally or on a Dask cluster
(:mod:`~stewart.studies.execution`): workspaces (:mod:`~stewart.studies.workspace`), force
and joint-load envelopes (:mod:`~stewart.studies.envelope`) and design sweeps
(:mod:`~stewart.studies.sweep`)."""
