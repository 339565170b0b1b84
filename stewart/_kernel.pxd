# The declarations of stewart._kernel (its Kernel, whose C-level methods the included loops call).
cimport cython
cimport numpy as cnp

# The generated C model's declarations: generated/stewart_model.pxd, written by the generator
# from the parameter schema and the public functions.
from stewart_model cimport *


@cython.final
cdef class Kernel:
    cdef stewart_params p
    cdef readonly int threads

    cdef object _run(self, str fname, int kind, void *fn, tuple names, tuple values,
                     tuple shapes, bint return_mask, double scalar, void *batch_fn)
    cdef void _batch(self, int kind, void *fn, Py_ssize_t n, Py_ssize_t block, const double *x0,
                     const double *x1, const double *x2, double scalar, int nout, double **outs,
                     const int *widths, int *status) noexcept nogil
    cdef int _threads(self, int kind, void *fn, double scalar, int nout, Py_ssize_t n, Py_ssize_t block,
                      const double *p0, const double *p1, const double *p2, double **po, const int *widths,
                      int *ps) except -1
    cdef int _row(self, int kind, void *fn, const double *x0, const double *x1, const double *x2,
                  double scalar, double **outs, const int *widths, int nout, Py_ssize_t row,
                  int *status) noexcept nogil
    cdef object _failed(self, str fname, tuple names, tuple arrays, object out,
                        cnp.ndarray status, bint batch, bint return_mask)
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
