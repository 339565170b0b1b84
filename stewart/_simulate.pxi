# The simulator's closed loop (included by stewart/_kernel.pyx: stewart._kernel.ClosedLoop):
# the settings of a controller and its actuators moved into the C model's stewart_loop, whose
# equations of motion (stewart_loop_derivative: the control laws, the force saturation and
# the legs' friction) and fixed-step RK4 (stewart_loop_rk4) are in the generated C
# (codegen/templates/control.c).
#
# State ``y = [x (6), xdot (6), integral of the leg-length error (6)]``. The controller,
# force saturation and actuator friction are evaluated at every RK4 stage, so the closed
# loop is one smooth ODE.

cpdef enum Mode:
    # The control law the loop evaluates (each controller of stewart.motion.control names its own).
    OPEN_LOOP = STEWART_OPEN_LOOP
    PID = STEWART_PID
    COMPUTED_TORQUE = STEWART_COMPUTED_TORQUE


cdef int per_leg(double *out, str name, object value, bint finite) except -1:
    """``value``, six numbers (one per leg; finite if ``finite``, else not NaN: a force limit may
    be infinite), into ``out``; a ``ValueError`` naming the argument ``name`` otherwise."""
    cdef cnp.ndarray arr = arguments.reals(name, value)
    cdef int k
    if arr.ndim != 1 or arr.shape[0] != 6:
        raise ValueError(f"{name}: expected 6 values, one per leg, got shape {np.shape(value)}")
    if not (np.all(np.isfinite(arr)) if finite else not np.any(np.isnan(arr))):
        raise ValueError(f"{name}: expected {'finite values' if finite else 'no NaN'}, got {arr.tolist()}")
    for k in range(6):
        out[k] = arr[k]
    return 0


cdef stewart_friction as_friction(str name, law):
    """``(F_v (6,), F_c (6,), v_c)`` as a :c:type:`stewart_friction` (``name``: the argument, in
    the errors)."""
    cdef stewart_friction f
    viscous, coulomb, velocity = law
    per_leg(f.viscous, f"{name} (viscous)", viscous, True)
    per_leg(f.coulomb, f"{name} (coulomb)", coulomb, True)
    f.velocity = velocity
    return f


cpdef enum Outcome:
    # How a run of steps ended (the kernel's own status codes, > 0, are passed on as they are).
    STOP_FINISHED = STEWART_OK
    STOP_LEG_SHORT = STEWART_STOP_LEG_SHORT
    STOP_LEG_LONG = STEWART_STOP_LEG_LONG
    STOP_NONFINITE = STEWART_STOP_NONFINITE


@cython.final
cdef class ClosedLoop:
    """Platform, controller and actuators as the right-hand side of one ODE.

    ``friction`` is what the legs lose and ``model_friction`` what the computed-torque law
    adds back at the measured leg rates (its model's, as in
    :meth:`stewart.Platform.actuator_forces`); each is ``(F_v (6,), F_c (6,), v_c)``."""

    cdef Kernel kernel
    cdef stewart_loop loop

    def __cinit__(self, Kernel kernel, int mode, kp, ki, kd, force_limit, friction, model_friction):
        self.kernel = kernel
        self.loop.mode = mode
        per_leg(self.loop.kp, "kp", kp, True)
        per_leg(self.loop.ki, "ki", ki, True)
        per_leg(self.loop.kd, "kd", kd, True)
        per_leg(self.loop.force_limit, "force_limit", force_limit, False)
        self.loop.friction = as_friction("friction", friction)
        self.loop.model_friction = as_friction("model_friction", model_friction)

    def derivative(self, y, ref, feedforward):
        """``(ydot, commanded force, L, Ldot, status)`` at one state (for adaptive integrators);
        the arguments are C-contiguous float64 arrays."""
        cdef cnp.ndarray cy = _c_array("y", y, cnp.NPY_DOUBLE, 1, False)
        cdef cnp.ndarray cref = _c_array("ref", ref, cnp.NPY_DOUBLE, 1, False)
        cdef cnp.ndarray cff = _c_array("feedforward", feedforward, cnp.NPY_DOUBLE, 1, False)
        if cy.shape[0] != 18 or cref.shape[0] != 18 or cff.shape[0] != 6:
            raise ValueError("derivative: need y (18,), ref (18,) and feedforward (6,)")
        cdef cnp.ndarray ydot = np.empty(18)
        cdef cnp.ndarray out = np.empty((3, 6))
        cdef double *o = <double *>cnp.PyArray_DATA(out)
        cdef int status = T.loop_derivative(&self.kernel.p, &self.loop, <const double *>cnp.PyArray_DATA(cy),
                                            <const double *>cnp.PyArray_DATA(cref), <const double *>cnp.PyArray_DATA(cff),
                                            <double *>cnp.PyArray_DATA(ydot), o, o + 6, o + 12)
        return ydot, out[0], out[1], out[2], status

    def rk4(self, y, refs, feedforward, double dt, Py_ssize_t start, Py_ssize_t stop, double min_length,
            double max_length, states, forces, lengths, rates):
        """Advance ``y`` in place from step ``start`` to ``stop`` with classic RK4.

        ``refs`` and ``feedforward`` are sampled on the half-step grid (row ``2k`` at
        ``t_k``, ``2k + 1`` at ``t_k + dt/2``). Row ``k`` of the outputs ``states``, ``forces``,
        ``lengths`` and ``rates`` receives the state, commanded actuator forces (before
        saturation), leg lengths and leg rates at ``t_k``. Every array is C-contiguous float64,
        ``y`` and the outputs writable. Buffers too small for the steps asked for raise
        ``ValueError``. Returns ``(outcome, step, leg)``: the step at which the run stopped
        (``stop`` when it ran through) and, for a stroke limit, the leg; the outcome is
        ``STOP_FINISHED``, a ``STOP_*`` code or the kernel's status code.
        """
        cdef cnp.ndarray cy = _c_array("y", y, cnp.NPY_DOUBLE, 1, True)
        cdef cnp.ndarray crefs = _c_array("refs", refs, cnp.NPY_DOUBLE, 2, False)
        cdef cnp.ndarray cff = _c_array("feedforward", feedforward, cnp.NPY_DOUBLE, 2, False)
        cdef cnp.ndarray cstates = _c_array("states", states, cnp.NPY_DOUBLE, 2, True)
        cdef cnp.ndarray cforces = _c_array("forces", forces, cnp.NPY_DOUBLE, 2, True)
        cdef cnp.ndarray clengths = _c_array("lengths", lengths, cnp.NPY_DOUBLE, 2, True)
        cdef cnp.ndarray crates = _c_array("rates", rates, cnp.NPY_DOUBLE, 2, True)
        if not (0 <= start <= stop and cy.shape[0] == 18 and crefs.shape[0] >= 2 * stop + 1
                and crefs.shape[1] == 18 and cff.shape[0] >= 2 * stop + 1 and cff.shape[1] == 6
                and cstates.shape[0] >= stop and cstates.shape[1] == 18
                and cforces.shape[0] >= stop and cforces.shape[1] == 6 and clengths.shape[0] >= stop
                and clengths.shape[1] == 6 and crates.shape[0] >= stop and crates.shape[1] == 6):
            raise ValueError("rk4: the buffers do not hold the steps asked for")
        # Rows of 18 (y, refs, states) or 6 (feedforward, the other outputs) doubles.
        cdef double *py = <double *>cnp.PyArray_DATA(cy)
        cdef const double *prefs = <const double *>cnp.PyArray_DATA(crefs)
        cdef const double *pff = <const double *>cnp.PyArray_DATA(cff)
        cdef double *pstates = <double *>cnp.PyArray_DATA(cstates)
        cdef double *pforces = <double *>cnp.PyArray_DATA(cforces)
        cdef double *plengths = <double *>cnp.PyArray_DATA(clengths)
        cdef double *prates = <double *>cnp.PyArray_DATA(crates)
        cdef size_t step = start
        cdef int status, leg = -1
        with nogil:
            status = T.loop_rk4(&self.kernel.p, &self.loop, py, prefs, pff, dt, start, stop, min_length, max_length,
                                pstates, pforces, plengths, prates, &step, &leg)
        return status, step, leg
