# The declarations of stewart._kernel (its Kernel, whose C-level methods the included loops call).
cimport cython
cimport numpy as cnp

# The generated C model's declarations: generated/stewart_model.pxd, written by the generator
# from the parameter schema and the public functions.
from stewart_model cimport *


@cython.final
cdef class _Function:
    cdef readonly str name
    cdef readonly int index, nin, nout
    cdef readonly str scalar
    cdef readonly tuple inputs, results
    cdef tuple parts  # (output, start, stop, row shape) of each result
    cdef bint whole
    cdef int widths[STEWART_MAX_OUTPUTS]
    cdef int ndims[STEWART_MAX_OUTPUTS]
    cdef cnp.npy_intp dims[STEWART_MAX_OUTPUTS][3]

    cdef object split(self, tuple outputs)


@cython.final
cdef class Kernel:
    cdef stewart_params p
    cdef readonly int threads

    cdef object _run(self, _Function f, tuple values, double scalar, bint return_mask)
    cdef void _batch(self, stewart_call fn, _Function f, Py_ssize_t n, Py_ssize_t block, const double **ins,
                     double scalar, double **outs, int *status) noexcept nogil
    cdef int _threads(self, stewart_call fn, _Function f, Py_ssize_t n, Py_ssize_t block, const double **ins,
                      double scalar, double **outs, int *status) except -1
    cdef object _failed(self, _Function f, tuple arrays, object out, cnp.ndarray status, bint batch,
                        bint return_mask)
    cdef int leg_lengths_c(self, const double *x, double *out) noexcept nogil
    cdef int leg_rates_c(self, const double *x, const double *xd, double *L, double *Ld) noexcept nogil
    cdef int inverse_dynamics_c(self, const double *x, const double *xd, const double *xdd,
                                double *out) noexcept nogil
    cdef int forward_dynamics_c(self, const double *x, const double *xd, const double *tau,
                                double *out) noexcept nogil
    # The batch functions on n rows (row-major arrays, a status per row).
    cdef void batch_leg_rates_c(self, size_t n, const double *x, const double *xd, double *LLd,
                                int *status) noexcept nogil
    cdef void batch_joint_reactions_c(self, size_t n, const double *x, const double *xd, const double *xdd,
                                      double *tau, double *f_base, double *f_platform, double *n_base,
                                      int *status) noexcept nogil
