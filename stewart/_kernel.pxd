# Declarations shared with the other Cython modules (stewart._simulate).
cimport cython
cimport numpy as cnp

cdef extern from "stewart_model.h" nogil:
    ctypedef struct stewart_params:
        double base_points[6][3]
        double platform_points[6][3]
        double platform_mass
        double platform_inertia[3]
        double cylinder_mass
        double cylinder_inertia[3]
        double cylinder_com_distance
        double piston_mass
        double piston_inertia[3]
        double piston_com_distance
        double gravity

    enum:
        STEWART_OK

    const char *stewart_status_message(int status)
    int stewart_leg_lengths(const stewart_params *p, const double *x, double *L)
    int stewart_jacobian(const stewart_params *p, const double *x, double *JC)
    int stewart_mass_matrix(const stewart_params *p, const double *x, double *M)
    int stewart_gravity_vector(const stewart_params *p, const double *x, double *G)
    int stewart_coriolis_matrix(const stewart_params *p, const double *x, const double *xd, double *V)
    int stewart_coriolis_vector(const stewart_params *p, const double *x, const double *xd, double *Vxd)
    int stewart_inverse_dynamics(const stewart_params *p, const double *x, const double *xd,
                                 const double *xdd, double *tau)
    int stewart_forward_dynamics(const stewart_params *p, const double *x, const double *xd,
                                 const double *tau, double *xdd)


@cython.final
cdef class Kernel:
    cdef stewart_params p
    cdef readonly int threads

    cdef object _run(self, str fname, int arity, void *fn, tuple names, tuple values,
                     int width, bint return_mask)
    cdef int _row(self, int arity, void *fn, const double *x0, const double *x1,
                  const double *x2, double *out, int *status, int width) noexcept nogil
    cdef object _failed(self, str fname, tuple names, tuple arrays, cnp.ndarray out,
                        cnp.ndarray status, bint batch, bint return_mask)
    cdef int leg_lengths_c(self, const double *x, double *out) noexcept nogil
    cdef int jacobian_c(self, const double *x, double *out) noexcept nogil
    cdef int inverse_dynamics_c(self, const double *x, const double *xd, const double *xdd,
                                double *out) noexcept nogil
    cdef int forward_dynamics_c(self, const double *x, const double *xd, const double *tau,
                                double *out) noexcept nogil
