"""The compiled core's one door: the only module of the package that imports the extension
``stewart._kernel`` (built from ``stewart/_kernel.pyx`` over the generated C), re-exporting
what the rest of the package uses. ``tests/test_layout.py`` holds every other module to it.

- :class:`Kernel`: the batch model of one platform, every function of the generated
  ``FUNCTIONS`` table (what :class:`~stewart.Platform` calls); :class:`RotaryKernel`, that of a
  rotary rig (what :class:`~stewart.RotaryPlatform` calls).
- :class:`ClosedLoop`, :class:`Mode`, :class:`Outcome`, :func:`status_message`: the
  simulator's compiled loop (:mod:`stewart.motion.simulation`, :mod:`stewart.motion.control`).
- :class:`Peaks`, :func:`box_states`, :data:`PEAK_QUANTITIES`: the envelope's running peaks
  (:mod:`stewart.studies.envelope`); :class:`RotaryPeaks`, :data:`ROTARY_PEAK_QUANTITIES`, a
  rotary rig's.
- :func:`modal_terms`, :data:`UNSTABLE`: the modal analysis (:mod:`stewart.model.stiffness`).
- :class:`CueingStep`, :data:`CUEING_GROUPS`: one MPC cueing step's QP built in C
  (:mod:`stewart.cueing.planner`).
- :func:`build_info`, :func:`set_simd`, :data:`LANES`: the instruction-set path in use.
"""

from .._kernel import (
    LANES,
    PEAK_QUANTITIES,
    ROTARY_PEAK_QUANTITIES,
    UNSTABLE,
    CUEING_GROUPS,
    ClosedLoop,
    CueingStep,
    Kernel,
    Mode,
    Outcome,
    Peaks,
    RotaryKernel,
    RotaryPeaks,
    box_states,
    build_info,
    modal_terms,
    set_simd,
    status_message,
)

__all__ = ["Kernel", "RotaryKernel", "ClosedLoop", "Mode", "Outcome", "status_message", "Peaks", "box_states",
           "PEAK_QUANTITIES", "RotaryPeaks", "ROTARY_PEAK_QUANTITIES", "modal_terms", "UNSTABLE", "CueingStep", "CUEING_GROUPS", "build_info", "set_simd",
           "LANES"]
