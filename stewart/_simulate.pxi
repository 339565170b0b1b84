# The closed-loop equations of motion and a fixed-step RK4 loop, with no Python per step
# (included by stewart/_kernel.pyx: stewart._kernel.ClosedLoop).
#
# State ``y = [x (6), xdot (6), integral of the leg-length error (6)]``. The controller
# (joint-space PID or task-space computed torque, which also cancels the model's friction),
# force saturation and actuator friction are evaluated at every RK4 stage, so the closed
# loop is one smooth ODE. All model evaluations go to the compiled kernel (``Kernel``).

from libc.math cimport isfinite, tanh

cpdef enum Mode:
    # The control law the loop evaluates (each controller of stewart.motion.control names its own).
    OPEN_LOOP = 0
    PID = 1
    COMPUTED_TORQUE = 2

cdef struct Friction:
    # Each leg's friction law, F_v Ldot + F_c tanh(Ldot / v_c) (stewart.Platform.friction_forces).
    double viscous[6]
    double coulomb[6]
    double velocity


cdef inline double friction_force(const Friction *f, int k, double rate) noexcept nogil:
    """The force leg ``k`` loses to friction at leg rate ``rate``."""
    if f.coulomb[k] == 0.0:
        return f.viscous[k] * rate
    return f.viscous[k] * rate + f.coulomb[k] * tanh(rate / f.velocity)


cdef Friction as_friction(law):
    """``(F_v (6,), F_c (6,), v_c)`` as a :c:type:`Friction`."""
    cdef Friction f
    cdef int k
    viscous, coulomb, velocity = law
    for k in range(6):
        f.viscous[k] = viscous[k]
        f.coulomb[k] = coulomb[k]
    f.velocity = velocity
    return f


cpdef enum Outcome:
    # How a run of steps ended (the kernel's own status codes, > 0, are passed on as they are).
    STOP_FINISHED = 0
    STOP_LEG_SHORT = -1
    STOP_LEG_LONG = -2
    STOP_NONFINITE = -3


@cython.final
cdef class ClosedLoop:
    """Platform, controller and actuators as the right-hand side of one ODE.

    ``friction`` is what the legs lose and ``model_friction`` what the computed-torque law
    adds back at the measured leg rates (its model's, as in
    :meth:`stewart.Platform.actuator_forces`); each is ``(F_v (6,), F_c (6,), v_c)``."""

    cdef Kernel kernel
    cdef int mode
    cdef double kp[6]
    cdef double ki[6]
    cdef double kd[6]
    cdef double force_limit[6]
    cdef Friction friction
    cdef Friction model_friction

    def __cinit__(self, Kernel kernel, int mode, kp, ki, kd, force_limit, friction, model_friction):
        cdef int k
        self.kernel = kernel
        self.mode = mode
        for k in range(6):
            self.kp[k] = kp[k]
            self.ki[k] = ki[k]
            self.kd[k] = kd[k]
            self.force_limit[k] = force_limit[k]
        self.friction = as_friction(friction)
        self.model_friction = as_friction(model_friction)

    cdef int rhs(self, const double *y, const double *ref, const double *feedforward,
                 double *ydot, double *force, double *L, double *Ld) noexcept nogil:
        """``ydot`` at ``y`` for the reference ``ref = [x_r, xdot_r, xddot_r]``; also the
        commanded actuator forces (before saturation and friction) and the leg lengths and rates."""
        cdef double Lr[6]
        cdef double Ldr[6]
        cdef double acc[6]
        cdef double applied[6]
        cdef int k, status
        status = self.kernel.leg_rates_c(y, y + 6, L, Ld)
        if status != STEWART_OK:
            return status
        if self.mode == PID:
            status = self.kernel.leg_rates_c(ref, ref + 6, Lr, Ldr)
            if status != STEWART_OK:
                return status
            for k in range(6):
                ydot[12 + k] = Lr[k] - L[k]
                force[k] = (self.kp[k] * (Lr[k] - L[k]) + self.ki[k] * y[12 + k]
                            + self.kd[k] * (Ldr[k] - Ld[k]) + feedforward[k])
        elif self.mode == COMPUTED_TORQUE:
            for k in range(6):
                ydot[12 + k] = 0.0
                acc[k] = ref[12 + k] + self.kd[k] * (ref[6 + k] - y[6 + k]) + self.kp[k] * (ref[k] - y[k])
            status = self.kernel.inverse_dynamics_c(y, y + 6, acc, force)
            if status != STEWART_OK:
                return status
            for k in range(6):
                force[k] += friction_force(&self.model_friction, k, Ld[k]) + feedforward[k]
        else:
            for k in range(6):
                ydot[12 + k] = 0.0
                force[k] = feedforward[k]
        for k in range(6):
            applied[k] = force[k]
            if applied[k] > self.force_limit[k]:
                applied[k] = self.force_limit[k]
            elif applied[k] < -self.force_limit[k]:
                applied[k] = -self.force_limit[k]
            applied[k] -= friction_force(&self.friction, k, Ld[k])
        for k in range(6):
            ydot[k] = y[6 + k]
        return self.kernel.forward_dynamics_c(y, y + 6, applied, ydot + 6)

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
        cdef int status = self.rhs(<const double *>cnp.PyArray_DATA(cy), <const double *>cnp.PyArray_DATA(cref),
                                   <const double *>cnp.PyArray_DATA(cff), <double *>cnp.PyArray_DATA(ydot),
                                   o, o + 6, o + 12)
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
        cdef double k1[18]
        cdef double k2[18]
        cdef double k3[18]
        cdef double k4[18]
        cdef double tmp[18]
        cdef double scratch[18]
        cdef double Lnew[6]
        cdef Py_ssize_t n, i, j
        cdef int status = 0, leg = -1
        with nogil:
            for n in range(start, stop):
                for j in range(18):
                    pstates[18 * n + j] = py[j]
                status = self.rhs(py, prefs + 18 * (2 * n), pff + 6 * (2 * n), k1,
                                  pforces + 6 * n, plengths + 6 * n, prates + 6 * n)
                if status != STEWART_OK:
                    break
                for j in range(18):
                    tmp[j] = py[j] + 0.5 * dt * k1[j]
                status = self.rhs(tmp, prefs + 18 * (2 * n + 1), pff + 6 * (2 * n + 1), k2,
                                  scratch, scratch + 6, scratch + 12)
                if status != STEWART_OK:
                    break
                for j in range(18):
                    tmp[j] = py[j] + 0.5 * dt * k2[j]
                status = self.rhs(tmp, prefs + 18 * (2 * n + 1), pff + 6 * (2 * n + 1), k3,
                                  scratch, scratch + 6, scratch + 12)
                if status != STEWART_OK:
                    break
                for j in range(18):
                    tmp[j] = py[j] + dt * k3[j]
                status = self.rhs(tmp, prefs + 18 * (2 * n + 2), pff + 6 * (2 * n + 2), k4,
                                  scratch, scratch + 6, scratch + 12)
                if status != STEWART_OK:
                    break
                for j in range(18):
                    py[j] += dt / 6.0 * (k1[j] + 2.0 * k2[j] + 2.0 * k3[j] + k4[j])
                    if not isfinite(py[j]):
                        status = STOP_NONFINITE
                if status != STEWART_OK:
                    n += 1
                    break
                self.kernel.leg_lengths_c(py, Lnew)
                for i in range(6):
                    if Lnew[i] < min_length:
                        status, leg = STOP_LEG_SHORT, i
                    elif Lnew[i] > max_length:
                        status, leg = STOP_LEG_LONG, i
                if status != STEWART_OK:
                    n += 1
                    break
            else:
                n = stop
        return status, n, leg
