# The stiffness and modes of the platform on preloaded leg springs, per state in C (included by
# stewart/_kernel.pyx: stewart._kernel.modal_terms; the equations are those of
# stewart.model.stiffness).
#
# A few dozen rows at a time, the model's batch function modal_stiffness gives, into buffers on
# the stack, the twist-space stiffness K_t = J_C^T (diag(k) J_C + dtau_s/dx T^-1), J_C and the
# twist-space mass matrix M_t (all derived in codegen/); per row LAPACK's dsygv
# (scipy.linalg.cython_lapack) solves K_t phi = w^2 M_t phi for the symmetric part of K_t.
# Nothing is allocated per state, and the rows run without the GIL, on the kernel's threads.

from libc.math cimport M_PI
from scipy.linalg.cython_lapack cimport dsygv

cdef enum:
    # The status of a row whose stiffness is not positive definite: the legs cannot hold the pose.
    MODAL_UNSTABLE = -1
    # Rows per call of the batch function.
    MODAL_ROWS = 32
    # The workspace of dsygv (at least 3 n - 1 = 17).
    MODAL_WORK = 64

#: The status :func:`modal_terms` gives a row whose stiffness is not positive definite.
UNSTABLE = MODAL_UNSTABLE


cdef int _modal_row(const double *stiff, const double *mass, double *frequencies, double *shapes) noexcept nogil:
    """One state of ``K_t`` (``stiff``) and ``M_t`` (``mass``), row-major: ``frequencies`` = ``w / 2 pi``
    ascending and ``shapes`` (row-major, mode j in column j) mass-normalized; the status."""
    cdef double a[36]
    cdef double b[36]
    cdef double work[MODAL_WORK]
    cdef double values[6]
    cdef int i, j, itype = 1, order = 6, lwork = MODAL_WORK, info = 0
    cdef char jobz = b'V', uplo = b'L'
    for i in range(6):
        for j in range(6):
            a[6 * i + j] = 0.5 * (stiff[6 * i + j] + stiff[6 * j + i])
            b[6 * i + j] = mass[6 * i + j]
    dsygv(&itype, &jobz, &uplo, &order, a, &order, b, &order, values, work, &lwork, &info)
    if info != 0:
        return STEWART_ERR_MASS_SINGULAR
    if not values[0] > 0.0:
        return MODAL_UNSTABLE
    for i in range(6):
        frequencies[i] = sqrt(values[i]) * (0.5 / M_PI)
        for j in range(6):
            shapes[6 * i + j] = a[6 * j + i]  # LAPACK's column j is mode j
    return STEWART_OK


cdef void _modal_rows(const stewart_params *p, const double *x, const double *k, Py_ssize_t n, double *stiff, double *jac,
                      double *mass, double *values, double *shapes, int *status) noexcept nogil:
    """Up to MODAL_ROWS states; a failed row's outputs are NaN but for the stiffness, J_C and M_t
    of an unstable one."""
    cdef double springs[MODAL_ROWS * 6]
    cdef Py_ssize_t r, i
    if n == 1:  # one state: the model's own function, not a batch padded to the vector width
        status[0] = T.modal_stiffness(p, x, k, stiff, jac, mass)
    else:
        for r in range(n):
            for i in range(6):
                springs[6 * r + i] = k[i]
        T.batch_modal_stiffness(p, n, x, springs, stiff, jac, mass, status)
    for r in range(n):
        if status[r] == STEWART_OK:
            status[r] = _modal_row(stiff + 36 * r, mass + 36 * r, values + 6 * r, shapes + 36 * r)
        if status[r] != STEWART_OK:
            for i in range(6):
                values[6 * r + i] = NAN
            for i in range(36):
                shapes[36 * r + i] = NAN


def modal_terms(Kernel kernel, x, k):
    """The stiffness and modes at the states ``x`` (float64, C-contiguous ``(6,)`` or ``(n, 6)``) of the
    platform on preloaded leg springs ``k`` (``(6,)`` N/m, or one float for every leg): ``(K_t, J_C,
    M_t, frequencies [Hz], shapes, status, failures)``, shapes ``(n, 6, 6)``, ``(n, 6, 6)``,
    ``(n, 6, 6)``, ``(n, 6)``, ``(n, 6, 6)``, ``(n,)`` and an int; ``status`` per row ``STEWART_OK``
    (0), a status of the model (its outputs NaN), or :data:`UNSTABLE` (``K_t``, ``J_C`` and ``M_t``
    given, the rest NaN); ``failures`` the rows not OK. See :mod:`stewart.model.stiffness`."""
    cdef int ndim = (<cnp.ndarray>x).ndim if type(x) is cnp.ndarray else np.ndim(x)
    cdef cnp.ndarray cx = _c_array("x", x, cnp.NPY_DOUBLE, 1 if ndim == 1 else 2, False)
    cdef cnp.ndarray ck = None
    cdef double each[6]
    cdef const double *pk = each
    cdef int i
    if type(k) is float:
        for i in range(6):
            each[i] = k
    else:
        ck = _c_array("k", k, cnp.NPY_DOUBLE, 1, False)
        pk = <const double *>cnp.PyArray_DATA(ck)
    cdef Py_ssize_t n = cx.shape[0] if cx.ndim == 2 else 1
    if cx.shape[cx.ndim - 1] != 6 or (ck is not None and ck.shape[0] != 6):
        raise ValueError(f"x, k: need (6,) or (n, 6) states and (6,) stiffnesses, got {np.shape(x)}, {np.shape(k)}")
    # The outputs through numpy's C API (np.empty's Python call costs as much as a kernel here).
    cdef cnp.npy_intp dims[3]
    dims[0], dims[1], dims[2] = n, 6, 6
    cdef cnp.ndarray stiff = cnp.PyArray_EMPTY(3, dims, cnp.NPY_DOUBLE, 0)
    cdef cnp.ndarray jac = cnp.PyArray_EMPTY(3, dims, cnp.NPY_DOUBLE, 0)
    cdef cnp.ndarray mass = cnp.PyArray_EMPTY(3, dims, cnp.NPY_DOUBLE, 0)
    cdef cnp.ndarray shapes = cnp.PyArray_EMPTY(3, dims, cnp.NPY_DOUBLE, 0)
    cdef cnp.ndarray values = cnp.PyArray_EMPTY(2, dims, cnp.NPY_DOUBLE, 0)
    cdef cnp.ndarray status = cnp.PyArray_EMPTY(1, dims, cnp.NPY_INT, 0)
    cdef double *pstiff = <double *>cnp.PyArray_DATA(stiff)
    cdef double *pjac = <double *>cnp.PyArray_DATA(jac)
    cdef double *pmass = <double *>cnp.PyArray_DATA(mass)
    cdef double *pvalues = <double *>cnp.PyArray_DATA(values)
    cdef double *pshapes = <double *>cnp.PyArray_DATA(shapes)
    cdef int *pstatus = <int *>cnp.PyArray_DATA(status)
    cdef const double *px = <const double *>cnp.PyArray_DATA(cx)
    cdef Py_ssize_t b, first, nblocks = (n + MODAL_ROWS - 1) // MODAL_ROWS
    cdef const stewart_params *params = &kernel.p
    cdef int threads = kernel.threads if nblocks > 1 else 1
    with nogil:
        if threads == 1:  # one block, or one thread: no parallel region
            for b in range(nblocks):
                first = b * MODAL_ROWS
                _modal_rows(params, px + 6 * first, pk, min(<Py_ssize_t>MODAL_ROWS, n - first), pstiff + 36 * first,
                            pjac + 36 * first, pmass + 36 * first, pvalues + 6 * first, pshapes + 36 * first,
                            pstatus + first)
        else:
            for b in prange(nblocks, num_threads=threads, schedule="dynamic"):
                first = b * MODAL_ROWS
                _modal_rows(params, px + 6 * first, pk, min(<Py_ssize_t>MODAL_ROWS, n - first), pstiff + 36 * first,
                            pjac + 36 * first, pmass + 36 * first, pvalues + 6 * first, pshapes + 36 * first,
                            pstatus + first)
    cdef Py_ssize_t r, failures = 0
    for r in range(n):
        failures += pstatus[r] != STEWART_OK
    return stiff, jac, mass, values, shapes, status, failures
