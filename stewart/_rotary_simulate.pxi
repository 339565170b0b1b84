# The simulator's closed loop for a rotary rig (issue 40; included by stewart/_kernel.pyx after
# _simulate.pxi and _rotary.pxi: stewart._kernel.RotaryLoop). The same loop as the linear
# machines' ClosedLoop (codegen/templates/control.c: stewart_loop_derivative, stewart_loop_rk4),
# with the crank angles and motor torques for the leg lengths and leg forces, and every
# per-state quantity a generated rotary function called through the rotary table of the
# compiled copy in use (stewart_rotary_dispatch.h): crank_angles, crank_rates,
# inverse_dynamics and forward_dynamics. The settings are the linear loop's stewart_loop
# (mode, gains, the torque limit in force_limit, the motors' friction in friction and what
# computed torque adds back in model_friction), the friction law the linear model's
# (stewart_friction_forces, on the crank rates).
#
# State ``y = [x (6), xdot (6), integral of the crank-angle error (6)]``; the controller,
# torque saturation and friction are evaluated at every RK4 stage (one smooth ODE). A reference
# row is ``[x_r, xd_r, xdd_r, alpha_r, alpha_dot_r]`` (REFERENCE_WIDTH): the reference's crank
# angles and rates come with it, evaluated beforehand by the same generated functions on the
# whole batch of reference rows (NaN where a crank cannot reach the reference, whose status the
# loop then asks of crank_angles), so that each stage evaluates them at the state alone.

from libc.math cimport M_PI, isfinite, remainder

# The indices of the rotary functions in the table's ``call`` (stewart._generated_rotary).
cdef int _RCRANK_ANGLES = ROTARY_FUNCTIONS["crank_angles"].index
cdef int _RCRANK_RATES = ROTARY_FUNCTIONS["crank_rates"].index
cdef int _RINVERSE = ROTARY_FUNCTIONS["inverse_dynamics"].index
cdef int _RFORWARD = ROTARY_FUNCTIONS["forward_dynamics"].index
# The columns of a reference row of RotaryLoop: x_r, xd_r, xdd_r, alpha_r, alpha_dot_r.
cdef enum:
    _RWIDTH = 30
#: The columns of a reference row of RotaryLoop: x_r, xd_r, xdd_r, alpha_r, alpha_dot_r.
REFERENCE_WIDTH = _RWIDTH


cdef inline int _rcall(const stewart_rotary_table *table, const stewart_rotary_params *p, int index,
                       const double *a, const double *b, const double *c, double *out) noexcept nogil:
    """The rotary function ``index`` of ``table`` on one state (inputs ``a``, ``b``, ``c``, as many
    as it takes; one output): its status."""
    cdef const double *ins[3]
    cdef double *outs[1]
    cdef int status = STEWART_OK
    ins[0] = a
    ins[1] = b
    ins[2] = c
    outs[0] = out
    table.call[index](<const stewart_params *>p, 1, ins, 0.0, outs, &status)
    return status


cdef inline double _saturated(double torque, double limit) noexcept nogil:
    """The torque within +-limit (control.c's ``saturated``)."""
    if torque > limit:
        return limit
    if torque < -limit:
        return -limit
    return torque


@cython.final
cdef class RotaryLoop:
    """A rotary rig, its controller and its motors as the right-hand side of one ODE: the
    closed loop of :class:`ClosedLoop` on the crank angles and motor torques.

    ``mode`` PID: ``torque = kp e + ki int(e) + kd (alpha_dot_r - alpha_dot) + feedforward``, ``e =
    alpha_r - alpha`` (wrapped to (-pi, pi]), the reference's crank angles and rates those of the
    generated crank_angles and crank_rates; COMPUTED_TORQUE: ``torque = inverse_dynamics(x, xd,
    xdd_r + kd (xd_r - xd) + kp (x_r - x)) + model_friction(alpha_dot) + feedforward``; OPEN_LOOP:
    ``torque = feedforward``. The cranks receive the torque saturated at ``+-torque_limit`` less
    their ``friction`` at the crank rates (each ``(F_v (6,), F_c (6,), v_c)``); ``xdd`` is the
    generated forward_dynamics of it."""

    cdef RotaryKernel kernel
    cdef const stewart_rotary_table *table
    cdef stewart_loop loop

    def __cinit__(self, RotaryKernel kernel, int mode, kp, ki, kd, torque_limit, friction, model_friction):
        self.kernel = kernel
        self.table = _rotary_table()
        self.loop.mode = mode
        per_leg(self.loop.kp, "kp", kp, True)
        per_leg(self.loop.ki, "ki", ki, True)
        per_leg(self.loop.kd, "kd", kd, True)
        per_leg(self.loop.force_limit, "torque_limit", torque_limit, False)
        self.loop.friction = as_friction("friction", friction)
        self.loop.model_friction = as_friction("model_friction", model_friction)

    cdef int _derivative(self, const double *y, const double *ref, const double *ff, double *ydot,
                         double *torque, double *alpha, double *rate) noexcept nogil:
        """``ydot`` at ``y``, with the commanded torques (before saturation and friction), the
        crank angles and crank rates at ``y``: the status of the first function that fails (the
        outputs then not all set)."""
        cdef const stewart_rotary_params *p = &self.kernel.p
        cdef const double *ar = ref + 18
        cdef const double *adr = ref + 24
        cdef double acc[6]
        cdef double loss[6]
        cdef double applied[6]
        cdef int k
        cdef int status = _rcall(self.table, p, _RCRANK_ANGLES, y, NULL, NULL, alpha)
        if status == STEWART_OK:
            status = _rcall(self.table, p, _RCRANK_RATES, y, y + 6, NULL, rate)
        if status != STEWART_OK:
            return status
        if self.loop.mode == STEWART_PID:
            for k in range(6):
                if not (isfinite(ar[k]) and isfinite(adr[k])):  # a reference out of a crank's reach
                    status = _rcall(self.table, p, _RCRANK_RATES, ref, ref + 6, NULL, acc)
                    return status if status != STEWART_OK else STEWART_ERR_NONFINITE
            for k in range(6):
                ydot[12 + k] = remainder(ar[k] - alpha[k], 2.0 * M_PI)
                torque[k] = (self.loop.kp[k] * ydot[12 + k] + self.loop.ki[k] * y[12 + k]
                             + self.loop.kd[k] * (adr[k] - rate[k]) + ff[k])
        elif self.loop.mode == STEWART_COMPUTED_TORQUE:
            for k in range(6):
                ydot[12 + k] = 0.0
                acc[k] = ref[12 + k] + self.loop.kd[k] * (ref[6 + k] - y[6 + k]) + self.loop.kp[k] * (ref[k] - y[k])
            status = _rcall(self.table, p, _RINVERSE, y, y + 6, acc, torque)
            if status != STEWART_OK:
                return status
            T.friction_forces(&self.loop.model_friction, rate, loss)
            for k in range(6):
                torque[k] += loss[k] + ff[k]
        else:
            for k in range(6):
                ydot[12 + k] = 0.0
                torque[k] = ff[k]
        T.friction_forces(&self.loop.friction, rate, loss)
        for k in range(6):
            applied[k] = _saturated(torque[k], self.loop.force_limit[k]) - loss[k]
            ydot[k] = y[6 + k]
        return _rcall(self.table, p, _RFORWARD, y, y + 6, applied, ydot + 6)

    def derivative(self, y, ref, feedforward):
        """``(ydot, commanded torque, alpha, alpha_dot, status)`` at one state (for adaptive
        integrators); the arguments are C-contiguous float64 arrays (y of 18, ref of
        REFERENCE_WIDTH, feedforward of 6)."""
        cdef cnp.ndarray cy = _c_array("y", y, cnp.NPY_DOUBLE, 1, False)
        cdef cnp.ndarray cref = _c_array("ref", ref, cnp.NPY_DOUBLE, 1, False)
        cdef cnp.ndarray cff = _c_array("feedforward", feedforward, cnp.NPY_DOUBLE, 1, False)
        if cy.shape[0] != 18 or cref.shape[0] != _RWIDTH or cff.shape[0] != 6:
            raise ValueError(f"derivative: need y (18,), ref ({REFERENCE_WIDTH},) and feedforward (6,)")
        self.table = _rotary_table()  # the copy in use (stewart.set_simd may have changed it)
        cdef cnp.ndarray ydot = np.zeros(18)
        cdef cnp.ndarray out = np.zeros((3, 6))
        cdef double *o = <double *>cnp.PyArray_DATA(out)
        cdef int status = self._derivative(<const double *>cnp.PyArray_DATA(cy), <const double *>cnp.PyArray_DATA(cref),
                                           <const double *>cnp.PyArray_DATA(cff), <double *>cnp.PyArray_DATA(ydot),
                                           o, o + 6, o + 12)
        return ydot, out[0], out[1], out[2], status

    cdef int _rk4(self, double *y, const double *refs, const double *ff, double dt, size_t start, size_t stop,
                  double lo, double hi, double *states, double *torques, double *angles, double *rates,
                  size_t *step, int *crank) noexcept nogil:
        """stewart_loop_rk4 (codegen/templates/control.c) on the rotary loop: classic RK4 with
        the stages of vector.c's RK4_STAGE and RK4_UPDATE; a step whose state is not finite, or
        has a crank angle outside [lo, hi] (STOP_LEG_SHORT / STOP_LEG_LONG, *crank that crank) or
        out of a crank's reach (its status), ends the run after it."""
        cdef double k[4][18]
        cdef double t[18]
        cdef double scratch[18]
        cdef double anew[6]
        cdef double h
        cdef int status = STEWART_OK
        cdef int i, j, stage
        cdef size_t n = start, row
        crank[0] = -1
        while n < stop:
            for j in range(18):
                states[18 * n + j] = y[j]
            for stage in range(4):
                row = 2 * n + <size_t>((stage + 1) // 2)
                if stage == 0:
                    status = self._derivative(y, refs + _RWIDTH * row, ff + 6 * row, k[0], torques + 6 * n,
                                              angles + 6 * n, rates + 6 * n)
                else:
                    h = (1.0 if stage == 3 else 0.5) * dt
                    for j in range(18):
                        t[j] = y[j] + h * k[stage - 1][j]
                    status = self._derivative(t, refs + _RWIDTH * row, ff + 6 * row, k[stage], scratch, scratch + 6,
                                              scratch + 12)
                if status != STEWART_OK:
                    break
            if status != STEWART_OK:
                break
            for j in range(18):
                y[j] = y[j] + dt / 6.0 * (k[0][j] + 2.0 * k[1][j] + 2.0 * k[2][j] + k[3][j])
                if not isfinite(y[j]):
                    status = STEWART_STOP_NONFINITE
            if status == STEWART_OK:
                status = _rcall(self.table, &self.kernel.p, _RCRANK_ANGLES, y, NULL, NULL, anew)
            if status == STEWART_OK:
                for i in range(6):
                    if anew[i] < lo:
                        status = STEWART_STOP_LEG_SHORT
                        crank[0] = i
                    elif anew[i] > hi:
                        status = STEWART_STOP_LEG_LONG
                        crank[0] = i
            n += 1
            if status != STEWART_OK:
                break
        step[0] = n
        return status

    def rk4(self, y, refs, feedforward, double dt, Py_ssize_t start, Py_ssize_t stop, double min_angle,
            double max_angle, states, torques, angles, rates):
        """Advance ``y`` in place from step ``start`` to ``stop`` with classic RK4, as
        :meth:`ClosedLoop.rk4` (``refs`` rows of REFERENCE_WIDTH): row ``k`` of ``states``,
        ``torques``, ``angles`` and ``rates`` receives the state, commanded motor torques (before
        saturation), crank angles and crank rates at ``t_k``; ``[min_angle, max_angle]`` are the
        crank-angle limits. Returns ``(outcome, step, crank)``: ``STOP_FINISHED``, ``STOP_LEG_SHORT`` / ``STOP_LEG_LONG`` (a
        crank at its lower / upper angle limit), ``STOP_NONFINITE`` or the kernel's status code
        (a crank out of reach: ``STEWART_ERR_CRANK_REACH_0 + i``)."""
        cdef cnp.ndarray cy = _c_array("y", y, cnp.NPY_DOUBLE, 1, True)
        cdef cnp.ndarray crefs = _c_array("refs", refs, cnp.NPY_DOUBLE, 2, False)
        cdef cnp.ndarray cff = _c_array("feedforward", feedforward, cnp.NPY_DOUBLE, 2, False)
        cdef cnp.ndarray cstates = _c_array("states", states, cnp.NPY_DOUBLE, 2, True)
        cdef cnp.ndarray ctorques = _c_array("torques", torques, cnp.NPY_DOUBLE, 2, True)
        cdef cnp.ndarray cangles = _c_array("angles", angles, cnp.NPY_DOUBLE, 2, True)
        cdef cnp.ndarray crates = _c_array("rates", rates, cnp.NPY_DOUBLE, 2, True)
        if not (0 <= start <= stop and cy.shape[0] == 18 and crefs.shape[0] >= 2 * stop + 1
                and crefs.shape[1] == _RWIDTH and cff.shape[0] >= 2 * stop + 1 and cff.shape[1] == 6
                and cstates.shape[0] >= stop and cstates.shape[1] == 18
                and ctorques.shape[0] >= stop and ctorques.shape[1] == 6 and cangles.shape[0] >= stop
                and cangles.shape[1] == 6 and crates.shape[0] >= stop and crates.shape[1] == 6):
            raise ValueError("rk4: the buffers do not hold the steps asked for")
        cdef double *py = <double *>cnp.PyArray_DATA(cy)
        cdef const double *prefs = <const double *>cnp.PyArray_DATA(crefs)
        cdef const double *pff = <const double *>cnp.PyArray_DATA(cff)
        cdef double *pstates = <double *>cnp.PyArray_DATA(cstates)
        cdef double *ptorques = <double *>cnp.PyArray_DATA(ctorques)
        cdef double *pangles = <double *>cnp.PyArray_DATA(cangles)
        cdef double *prates = <double *>cnp.PyArray_DATA(crates)
        cdef size_t step = start
        cdef int status, crank = -1
        self.table = _rotary_table()  # the copy in use (stewart.set_simd may have changed it)
        with nogil:
            status = self._rk4(py, prefs, pff, dt, start, stop, min_angle, max_angle, pstates, ptorques, pangles,
                               prates, &step, &crank)
        return status, step, crank


def rotary_status_message(int status):
    """The message of a rotary function's status code (a crank out of reach, or the linear
    model's codes)."""
    return stewart_rotary_status_message(status).decode()
