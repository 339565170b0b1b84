# The peaks of a rotary rig's envelope (issue 40), reduced in C as the rotary functions evaluate
# the states (included by stewart/_kernel.pyx after _envelope.pxi and _rotary.pxi, whose box
# states and rotary table it uses): stewart._kernel.RotaryPeaks.
#
# Per state and motor: the motor torque |tau_i|, the crank speed |alpha_dot_i| and the mechanical
# power |tau_i alpha_dot_i|, from the generated batch functions stewart_rotary_batch_crank_angles,
# _crank_rates and _inverse_dynamics (a few dozen rows at a time into buffers on the stack), kept
# as a running maximum with the state where it occurs; nothing is allocated per state and the
# work runs without the GIL.

#: The rotary quantities, in the order of their columns (each one column per motor).
ROTARY_PEAK_QUANTITIES = ("torque", "speed", "power")

cdef enum:
    ROTARY_COLUMNS = 18  # LEGS * len(ROTARY_PEAK_QUANTITIES)


@cython.final
cdef class RotaryPeaks:
    """The running peaks of the :data:`ROTARY_PEAK_QUANTITIES` of each motor of the rotary rig
    ``kernel`` (a :class:`RotaryKernel`) over the states added so far (:meth:`add`,
    :meth:`add_box`), with the crank angle ``limits`` (``(lowest, highest)`` radians or None):
    ``value`` ``(18,)`` (quantity-major, motor-minor; ``-inf`` while no state counted), ``index``
    ``(18,)`` the study index of the first state where it occurs (-1 for none) and ``state``
    ``(18, 18)`` that state ``[x, xdot, xddot]``; ``outside``, the states left out with a crank
    outside its limits, and ``singular``, those where a crank cannot reach the pose or the model
    is undefined."""

    cdef RotaryKernel kernel
    cdef stewart_call angles_fn, rates_fn, torques_fn
    cdef double lowest, highest
    cdef double _value[ROTARY_COLUMNS]
    cdef Py_ssize_t _index[ROTARY_COLUMNS]
    cdef double _state[ROTARY_COLUMNS * 18]
    cdef readonly Py_ssize_t outside, singular

    def __cinit__(self, RotaryKernel kernel, limits):
        cdef int k
        self.kernel = kernel
        self.lowest = -INFINITY if limits is None else limits[0]
        self.highest = INFINITY if limits is None else limits[1]
        for k in range(ROTARY_COLUMNS):
            self._value[k] = -INFINITY
            self._index[k] = -1
        for k in range(ROTARY_COLUMNS * 18):
            self._state[k] = NAN

    @property
    def value(self):
        return _copy_of(self._value, ROTARY_COLUMNS, np.float64)

    @property
    def index(self):
        return _copy_of(self._index, ROTARY_COLUMNS, np.intp)

    @property
    def state(self):
        return _copy_of(self._state, (ROTARY_COLUMNS, 18), np.float64)

    cdef int _bind(self) except -1:
        """The rotary functions of the compiled copy in use (set_simd may have changed it)."""
        cdef const stewart_rotary_table *table = _rotary_table()
        self.angles_fn = table.call[(<_Function>_ROTARY["crank_angles"]).index]
        self.rates_fn = table.call[(<_Function>_ROTARY["crank_rates"]).index]
        self.torques_fn = table.call[(<_Function>_ROTARY["inverse_dynamics"]).index]
        return 0

    def add(self, x, xd, xdd, Py_ssize_t start):
        """Take the rows of ``x, xd, xdd`` (float64, C-contiguous ``(n, 6)``), the states
        ``start`` to ``start + n - 1`` of the study. ``ValueError`` naming the argument for a
        row that is not finite."""
        cdef cnp.ndarray cx = _c_array("x", x, cnp.NPY_DOUBLE, 2, False)
        cdef cnp.ndarray cxd = _c_array("xd", xd, cnp.NPY_DOUBLE, 2, False)
        cdef cnp.ndarray cxdd = _c_array("xdd", xdd, cnp.NPY_DOUBLE, 2, False)
        cdef Py_ssize_t n = cx.shape[0]
        if cxd.shape[0] != n or cxdd.shape[0] != n or cx.shape[1] != 6 or cxd.shape[1] != 6 or cxdd.shape[1] != 6:
            raise ValueError(f"x, xd, xdd: need three (n, 6) arrays, got {np.shape(x)}, {np.shape(xd)}, "
                             f"{np.shape(xdd)}")
        cdef bint nonfinite = False
        self._bind()
        if n:
            with nogil:
                nonfinite = self._add(<const double *>cnp.PyArray_DATA(cx), <const double *>cnp.PyArray_DATA(cxd),
                                      <const double *>cnp.PyArray_DATA(cxdd), n, start)
        if nonfinite:
            for name, arr in (("x", x), ("xd", xd), ("xdd", xdd)):
                arguments.finite_states(name, arr)

    def add_box(self, u, bits, box, Py_ssize_t start):
        """Take the states of ``box`` drawn as ``u`` and ``bits`` (:func:`box_states`), the
        states ``start`` to ``start + n - 1`` of the study, generated here a few dozen at a time."""
        cdef const double *pu
        cdef const unsigned short *pbits
        cdef _Bounds bounds
        cdef double x[ROWS * 6]
        cdef double xd[ROWS * 6]
        cdef double xdd[ROWS * 6]
        cdef Py_ssize_t n = _box_arguments(u, bits, box, &bounds, &pu, &pbits)
        cdef Py_ssize_t first = 0, count
        self._bind()
        with nogil:
            while first < n:
                count = min(<Py_ssize_t>ROWS, n - first)
                _box_rows(pu + 6 * first, pbits + first, count, &bounds, x, xd, xdd)
                self._add(x, xd, xdd, count, start + first)
                first += count

    cdef bint _add(self, const double *x, const double *xd, const double *xdd, Py_ssize_t n,
                   Py_ssize_t start) noexcept nogil:
        """The rows in blocks of ROWS; whether a row was not finite."""
        cdef double alpha[ROWS * LEGS]
        cdef double rates[ROWS * LEGS]
        cdef double tau[ROWS * LEGS]
        cdef int angles_status[ROWS]
        cdef int rates_status[ROWS]
        cdef int torques_status[ROWS]
        cdef const double *ins[3]
        cdef double *outs[1]
        cdef const stewart_params *p = <const stewart_params *>&self.kernel.p
        cdef Py_ssize_t first = 0, count, r, i
        cdef int motor
        cdef bint nonfinite = False
        cdef double t, v
        while first < n:
            count = min(<Py_ssize_t>ROWS, n - first)
            i = 6 * first
            ins[0], ins[1], ins[2] = x + i, xd + i, xdd + i
            outs[0] = alpha
            self.angles_fn(p, count, ins, 0.0, outs, angles_status)
            outs[0] = rates
            self.rates_fn(p, count, ins, 0.0, outs, rates_status)
            outs[0] = tau
            self.torques_fn(p, count, ins, 0.0, outs, torques_status)
            for r in range(count):
                if angles_status[r] != STEWART_OK or rates_status[r] != STEWART_OK:
                    self.singular += 1
                    nonfinite = nonfinite or angles_status[r] == STEWART_ERR_NONFINITE \
                        or rates_status[r] == STEWART_ERR_NONFINITE
                    continue
                if not _within(&alpha[LEGS * r], self.lowest, self.highest):
                    self.outside += 1
                    continue
                if torques_status[r] != STEWART_OK:
                    self.singular += 1
                    nonfinite = nonfinite or torques_status[r] == STEWART_ERR_NONFINITE
                    continue
                i = 6 * (first + r)
                for motor in range(LEGS):
                    t = fabs(tau[LEGS * r + motor])
                    v = fabs(rates[LEGS * r + motor])
                    self._keep(motor, t, x + i, xd + i, xdd + i, start + first + r)
                    self._keep(LEGS + motor, v, x + i, xd + i, xdd + i, start + first + r)
                    self._keep(2 * LEGS + motor, t * v, x + i, xd + i, xdd + i, start + first + r)
            first += count
        return nonfinite

    cdef inline void _keep(self, int column, double v, const double *x, const double *xd, const double *xdd,
                           Py_ssize_t index) noexcept nogil:
        cdef int k
        if v > self._value[column]:  # a tie keeps the earlier state
            self._value[column] = v
            self._index[column] = index
            for k in range(6):
                self._state[18 * column + k] = x[k]
                self._state[18 * column + 6 + k] = xd[k]
                self._state[18 * column + 12 + k] = xdd[k]
