# The peaks of an envelope, reduced in C as the kernel evaluates the states (included by
# stewart/_kernel.pyx: stewart._kernel.Peaks and box_states).
#
# Per state and leg: the actuator force ``|tau_i|``, the leg velocity ``|Ldot_i|``, the power
# ``|tau_i Ldot_i|`` and the magnitudes of the joint forces at B_i and P_i (the kernel's
# ``batch_leg_rates`` and ``batch_joint_reactions``, a few dozen rows at a time into buffers on
# the stack), kept as a running maximum with the state where it occurs. Nothing is allocated
# per state, so the work runs without the GIL and at the same speed in any process, whatever
# its allocator settings (Dask's workers give the heap back after nearly every large free).

from libc.math cimport INFINITY, NAN, fabs, sqrt
from libc.string cimport memcpy

#: The quantities, in the order of their columns (each one column per leg).
PEAK_QUANTITIES = ("force", "velocity", "power", "universal_joint", "spherical_joint")

cdef enum:
    LEGS = 6
    COLUMNS = 30  # LEGS * len(PEAK_QUANTITIES)
    # States per call of the batch functions: their outputs (72 doubles a state) stay in L1/L2.
    ROWS = 64


@cython.final
cdef class Peaks:
    """The running peaks of the :data:`PEAK_QUANTITIES` of each leg over the states added so far
    (:meth:`add`, :meth:`add_box`), for the compiled model ``kernel`` and the stroke ``limits``
    (``(shortest, longest)`` or None): ``value`` ``(30,)`` (quantity-major, leg-minor; ``-inf``
    while no state counted), ``index`` ``(30,)`` the study index of the first state where it
    occurs (-1 for none) and ``state`` ``(30, 18)`` that state ``[x, xdot, xddot]`` (NaN for
    none); ``outside``, the states left out with a leg outside the stroke, and ``singular``,
    those where the model is undefined."""

    cdef Kernel kernel
    cdef double shortest, longest
    cdef double _value[COLUMNS]
    cdef Py_ssize_t _index[COLUMNS]
    cdef double _state[COLUMNS * 18]
    cdef readonly Py_ssize_t outside, singular

    def __cinit__(self, Kernel kernel, limits):
        cdef int k
        self.kernel = kernel
        self.shortest = -INFINITY if limits is None else limits[0]
        self.longest = INFINITY if limits is None else limits[1]
        for k in range(COLUMNS):
            self._value[k] = -INFINITY
            self._index[k] = -1
        for k in range(COLUMNS * 18):
            self._state[k] = NAN

    @property
    def value(self):
        return _copy_of(self._value, COLUMNS, np.float64)

    @property
    def index(self):
        return _copy_of(self._index, COLUMNS, np.intp)

    @property
    def state(self):
        return _copy_of(self._state, (COLUMNS, 18), np.float64)

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
        if n:
            with nogil:
                nonfinite = self._add(<const double *>cnp.PyArray_DATA(cx), <const double *>cnp.PyArray_DATA(cxd),
                                      <const double *>cnp.PyArray_DATA(cxdd), n, start)
        if nonfinite:
            for name, arr in (("x", x), ("xd", xd), ("xdd", xdd)):
                arguments.finite_states(name, arr)

    def add_box(self, u, bits, box, Py_ssize_t start):
        """Take the states of ``box`` (a :class:`stewart.studies.envelope.Box`) drawn as ``u``
        (``(n, 6)`` uniform numbers in [0, 1)) and ``bits`` (``(n,)`` integers, 12 random bits
        each), the states ``start`` to ``start + n - 1`` of the study (:func:`box_states`),
        generated here a few dozen at a time."""
        cdef const double *pu
        cdef const unsigned short *pbits
        cdef _Bounds bounds
        cdef double x[ROWS * 6]
        cdef double xd[ROWS * 6]
        cdef double xdd[ROWS * 6]
        cdef Py_ssize_t n = _box_arguments(u, bits, box, &bounds, &pu, &pbits)
        cdef Py_ssize_t first = 0, count
        with nogil:
            while first < n:
                count = min(<Py_ssize_t>ROWS, n - first)
                _box_rows(pu + 6 * first, pbits + first, count, &bounds, x, xd, xdd)
                self._add(x, xd, xdd, count, start + first)
                first += count

    cdef bint _add(self, const double *x, const double *xd, const double *xdd, Py_ssize_t n,
                   Py_ssize_t start) noexcept nogil:
        """The rows in blocks of ROWS; whether a row was not finite."""
        cdef double LLd[ROWS * 12]
        cdef double tau[ROWS * LEGS]
        cdef double f_base[ROWS * LEGS * 3]
        cdef double f_platform[ROWS * LEGS * 3]
        cdef double n_base[ROWS * LEGS * 3]
        cdef int rates_status[ROWS]
        cdef int forces_status[ROWS]
        cdef Py_ssize_t first = 0, count, r, i
        cdef int leg
        cdef bint nonfinite = False
        cdef double t, v
        while first < n:
            count = min(<Py_ssize_t>ROWS, n - first)
            i = 6 * first
            self.kernel.batch_leg_rates_c(count, x + i, xd + i, LLd, rates_status)
            self.kernel.batch_joint_reactions_c(count, x + i, xd + i, xdd + i, tau, f_base, f_platform, n_base,
                                                forces_status)
            for r in range(count):
                if rates_status[r] != STEWART_OK:
                    self.singular += 1
                    nonfinite = nonfinite or rates_status[r] == STEWART_ERR_NONFINITE
                    continue
                if not _within(&LLd[12 * r], self.shortest, self.longest):
                    self.outside += 1
                    continue
                if forces_status[r] != STEWART_OK:
                    self.singular += 1
                    continue
                i = 6 * (first + r)
                for leg in range(LEGS):
                    t = fabs(tau[LEGS * r + leg])
                    v = fabs(LLd[12 * r + LEGS + leg])
                    self._keep(leg, t, x + i, xd + i, xdd + i, start + first + r)
                    self._keep(LEGS + leg, v, x + i, xd + i, xdd + i, start + first + r)
                    self._keep(2 * LEGS + leg, t * v, x + i, xd + i, xdd + i, start + first + r)
                    self._keep(3 * LEGS + leg, _norm(&f_base[3 * (LEGS * r + leg)]), x + i, xd + i, xdd + i,
                               start + first + r)
                    self._keep(4 * LEGS + leg, _norm(&f_platform[3 * (LEGS * r + leg)]), x + i, xd + i, xdd + i,
                               start + first + r)
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


def box_states(u, bits, box):
    """The states ``(x, xd, xdd)``, each ``(n, 6)``, of ``box`` (a
    :class:`stewart.studies.envelope.Box`) drawn as ``u`` (``(n, 6)`` uniform numbers in [0, 1)) and
    ``bits`` (``(n,)``, 12 random bits each): the pose ``lower + u (upper - lower)``, and bit
    ``k`` (bit ``6 + k``) set for ``+velocity[k]`` (``+acceleration[k]``), clear for the
    negative bound: a random vertex of each rate box. :meth:`Peaks.add_box` evaluates the
    same states without storing them."""
    cdef const double *pu
    cdef const unsigned short *pbits
    cdef _Bounds bounds
    cdef Py_ssize_t n = _box_arguments(u, bits, box, &bounds, &pu, &pbits)
    cdef cnp.ndarray x = np.empty((n, 6)), xd = np.empty((n, 6)), xdd = np.empty((n, 6))
    _box_rows(pu, pbits, n, &bounds, <double *>cnp.PyArray_DATA(x), <double *>cnp.PyArray_DATA(xd),
              <double *>cnp.PyArray_DATA(xdd))
    return x, xd, xdd


cdef struct _Bounds:
    # A box's bounds, per axis: the poses lower + u width, the rates +-velocity, +-acceleration.
    double lower[6]
    double width[6]
    double velocity[6]
    double acceleration[6]


cdef Py_ssize_t _box_arguments(u, bits, box, _Bounds *bounds, const double **pu,
                               const unsigned short **pbits) except -1:
    """The bounds of ``box``, and the data of the draws ``u`` (C-contiguous float64) and ``bits``
    (C-contiguous uint16), which stay the caller's; the number of draws, checked."""
    cdef int k
    cdef cnp.ndarray cu = _c_array("u", u, cnp.NPY_DOUBLE, 2, False)
    cdef cnp.ndarray cbits = _c_array("bits", bits, cnp.NPY_USHORT, 1, False)
    if cu.shape[1] != 6 or cbits.shape[0] != cu.shape[0]:
        raise ValueError(f"u, bits: need (n, 6) and (n,) arrays, got {np.shape(u)} and {np.shape(bits)}")
    for k in range(6):
        bounds.lower[k] = box.lower[k]
        bounds.width[k] = box.upper[k] - box.lower[k]
        bounds.velocity[k] = box.velocity[k]
        bounds.acceleration[k] = box.acceleration[k]
    pu[0] = <const double *>cnp.PyArray_DATA(cu)
    pbits[0] = <const unsigned short *>cnp.PyArray_DATA(cbits)
    return cu.shape[0]


cdef cnp.ndarray _copy_of(const void *data, shape, dtype):
    """A new array of ``shape`` and ``dtype`` holding a copy of ``data``."""
    cdef cnp.ndarray out = np.empty(shape, dtype)
    memcpy(cnp.PyArray_DATA(out), data, cnp.PyArray_NBYTES(out))
    return out


cdef inline void _box_rows(const double *u, const unsigned short *bits, Py_ssize_t n, const _Bounds *b, double *x,
                           double *xd, double *xdd) noexcept nogil:
    """Rows of :func:`box_states`."""
    cdef Py_ssize_t r
    cdef int k
    for r in range(n):
        for k in range(6):
            x[6 * r + k] = b.lower[k] + u[6 * r + k] * b.width[k]
            xd[6 * r + k] = b.velocity[k] if (bits[r] >> k) & 1 else -b.velocity[k]
            xdd[6 * r + k] = b.acceleration[k] if (bits[r] >> (6 + k)) & 1 else -b.acceleration[k]


cdef inline double _norm(const double *v) noexcept nogil:
    return sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2])


cdef inline bint _within(const double *LLd, double shortest, double longest) noexcept nogil:
    """Every leg length (the first six of [L; Ldot]) within [shortest, longest]."""
    cdef int k
    for k in range(LEGS):
        if not (shortest <= LLd[k] <= longest):
            return False
    return True
