# The rotary rig's rows of MPC cueing's step (included by stewart/_kernel.pyx after
# stewart/_cueing_rows.pxi; CueingStep.condense calls them when its model is a RotaryKernel):
# the crank angles, crank rates, reaches and joints (the rod-crank and ball-joint cosines, the
# platform joints' heights, the crank pins' tilt sines) at the next log sample and over the horizon, from the generated
# rotary function cueing_rows (codegen/rotary_joints.py rotary_cueing_rows_kernel: the values and
# their exact pose gradients), each affine in the inputs about the linearization point; the
# motor torques are _force_rows' (the rotary inverse_dynamics_derivatives).

cdef void _rows_call(CueingStep self, int rows, const double *x, const double *v, double *out, int points, int p,
                     double *grads, double *joint_grads, int *status) noexcept:
    """The generated cueing_rows on ``rows`` states (the joints centred at home), written from
    point ``p`` on into ``out``, laid out as ``crank_out`` for ``points`` points (alpha,
    alpha_dot and reach blocks of 6 ``points``, then the joints, CUE_JOINT_ROWS a point), and
    into ``grads`` (108 a point) and ``joint_grads`` (6 CUE_JOINT_ROWS a point)."""
    cdef const double *ins[3]
    cdef double *outs[6]
    ins[0], ins[1], ins[2] = x, v, self.refs
    outs[0], outs[1], outs[2] = out + 6 * p, out + 6 * points + 6 * p, out + 12 * points + 6 * p
    outs[3], outs[4], outs[5] = grads + 108 * p, out + 18 * points + CUE_JOINT_ROWS * p, \
        joint_grads + 6 * CUE_JOINT_ROWS * p
    self.rows_fn(<const stewart_params *>&self.crank_model.p, rows, ins, 0.0, outs, status)


cdef void _crank_call(CueingStep self, int rows, const double *x, const double *v, double *out,
                      double *grads, double *joint_grads) except *:
    """The generated rotary cueing_rows on ``rows`` states (:func:`_rows_call`, one point of
    ``rows`` rows), raising where it fails."""
    _rows_call(self, rows, x, v, out, rows, 0, grads, joint_grads, self.status)
    if self._failed(rows):
        self._raise(self.crank_model, "cueing_rows", (self._array(<double *>x, rows), self._array(<double *>v, rows),
                                                      self._array(self.refs, rows)))


cdef bint _crank_points(CueingStep self) noexcept:
    """The linearization point at the next sample and the intervals' ends (xbar, vbar) and the
    generated cueing_rows there (into crank_out, crank_grads). A point where a crank is beyond
    its reach or below the reach REACH_MIN (``next_low[12:]``; a last plan may end there) is moved
    along the segment from the present pose to it, by bisection, to the last pose every crank
    reaches (the rows are then linearized about it: still the exact values and gradients there)."""
    cdef int n = self.n, k, r, p, it, points = self.n + 1
    cdef double dt = self.dt, hk, lo, hi, mid
    cdef double trial[6]
    for r in range(6):
        self.xbar[r] = self.x0[r] + dt * self.v0[r] + 0.5 * dt * dt * self.us[r]
        self.vbar[r] = self.v0[r] + dt * self.us[r]
    for k in range(n):
        hk = self.h[k]
        for r in range(6):
            self.xbar[6 * (k + 1) + r] = self.xs[6 * k + r] + hk * self.vs[6 * k + r] + 0.5 * hk * hk * self.us[6 * k + r]
            self.vbar[6 * (k + 1) + r] = self.vs[6 * k + r] + hk * self.us[6 * k + r]
    _rows_call(self, points, self.xbar, self.vbar, self.crank_out, points, 0, self.crank_grads, self.joint_grads,
               self.status)
    for p in range(points):
        if self.status[p] == STEWART_OK and _reaches(self, self.crank_out + 12 * points + 6 * p):
            continue
        lo, hi = 0.0, 1.0
        for it in range(40):
            mid = 0.5 * (lo + hi)
            if _crank_point(self, p, mid, trial):
                lo = mid
            else:
                hi = mid
        if not _crank_point(self, p, lo, trial):
            return False
        for r in range(6):
            self.xbar[6 * p + r] = trial[r]
    return True


cdef void _crank_starts(CueingStep self) noexcept:
    """The linearization point at the intervals' starts (xs, where the torque rows are
    linearized): a pose where a crank is beyond or near the edge of its reach (below REACH_MIN)
    is moved along the segment from the present pose to it, by bisection, to the last pose every
    crank reaches."""
    cdef int k, r, it
    cdef double lo, hi, mid
    cdef double trial[6]
    cdef double target[6]
    for k in range(1, self.n):
        for r in range(6):
            target[r] = self.xs[6 * k + r]
        if _pose_reaches(self, 1.0, target, self.vs + 6 * k, trial):
            continue
        lo, hi = 0.0, 1.0
        for it in range(40):
            mid = 0.5 * (lo + hi)
            if _pose_reaches(self, mid, target, self.vs + 6 * k, trial):
                lo = mid
            else:
                hi = mid
        _pose_reaches(self, lo, target, self.vs + 6 * k, trial)
        for r in range(6):
            self.xs[6 * k + r] = trial[r]


cdef bint _pose_reaches(CueingStep self, double share, const double *target, const double *rates,
                        double *pose) noexcept:
    """Whether every crank reaches ``x0 + share (target - x0)`` (written into ``pose``) with
    the reach REACH_MIN."""
    cdef int r, status = 0
    cdef double out[18 + CUE_JOINT_ROWS]
    cdef double grads[108]
    cdef double joint_grads[6 * CUE_JOINT_ROWS]
    for r in range(6):
        pose[r] = self.x0[r] + share * (target[r] - self.x0[r])
    _rows_call(self, 1, pose, rates, out, 1, 0, grads, joint_grads, &status)
    return status == STEWART_OK and _reaches(self, out + 12)


cdef bint _reaches(CueingStep self, const double *reach) noexcept:
    cdef int i
    for i in range(6):
        if not reach[i] >= self.next_low[12 + i]:
            return False
    return True


cdef bint _crank_point(CueingStep self, int p, double share, double *pose) noexcept:
    """cueing_rows at ``x0 + share (xbar_p - x0)`` with the rates vbar_p, written into point p's
    place of crank_out, crank_grads and joint_grads; the pose into ``pose``; whether every crank
    reaches it."""
    cdef int r, points = self.n + 1, status = 0
    for r in range(6):
        pose[r] = self.x0[r] + share * (self.xbar[6 * p + r] - self.x0[r])
    _rows_call(self, 1, pose, self.vbar + 6 * p, self.crank_out, points, p, self.crank_grads, self.joint_grads, &status)
    return status == STEWART_OK and _reaches(self, self.crank_out + 12 * points + 6 * p)


cdef void _crank_rows(CueingStep self) except *:
    """The crank angles, crank rates, reaches and joints at the next log sample (the first input
    held over dt) and at s_1..s_N, affine in u about the linearization point: alpha(x) ~ alpha +
    J (x - xbar), alpha_dot(x, v) ~ J v + (d alpha_dot/dx) (x - xbar) (alpha_dot = J v, J =
    J_alpha T), reach(x) ~ reach + (d reach/dx) (x - xbar), joints(x) ~ joints + (d joints/dx)
    (x - xbar); the values at the linearization point are :func:`_crank_points`' (condense
    called it). Over the horizon a point's ``cones`` rows are its reaches, then its joints,
    within ``cone`` (their lower bounds, then their upper)."""
    cdef int n = self.n, ns = self.ns, nu = self.nu, points = self.n + 1
    cdef int k, p, r, j, c, i, width, row, sp_stride
    cdef double dt = self.dt, hk, s, value
    cdef double sp0[36]
    cdef double sv0[36]
    cdef double dp[6]
    cdef double dv[6]
    cdef const double *sp
    cdef const double *sv
    cdef const double *jp
    cdef const double *da
    cdef const double *ds
    cdef const double *dj
    cdef double *joints = self.crank_out + 18 * points
    cdef double *alpha = self.crank_out
    cdef double *rate = self.crank_out + 6 * points
    cdef double *reach = self.crank_out + 12 * points
    for r in range(36):
        sp0[r], sv0[r] = 0.0, 0.0
    for r in range(6):
        sp0[7 * r], sv0[7 * r] = 0.5 * dt * dt, dt
    for p in range(points):
        jp = self.crank_grads + 108 * p
        da, ds = jp + 36, jp + 72
        dj = self.joint_grads + 6 * CUE_JOINT_ROWS * p
        if p == 0:
            sp, sv, width, sp_stride = sp0, sv0, 6, 6
            for r in range(6):
                dp[r] = (self.x0[r] - self.home[r] + dt * self.v0[r]) - (self.xbar[r] - self.home[r])
                dv[r] = self.v0[r]
        else:
            sp, sv = self.pS + (p * ns + CUE_P) * nu, self.pS + (p * ns + CUE_V) * nu
            width, sp_stride = 6 * p, nu
            for r in range(6):
                dp[r] = self.pd[p * ns + CUE_P + r] - (self.xbar[6 * p + r] - self.home[r])
                dv[r] = self.pd[p * ns + CUE_V + r]
        for i in range(6):
            # the crank angle
            row = self.starts[1] + i if p == 0 else self.starts[4] + 6 * (p - 1) + i
            _pose_row(self, row, jp + 6 * i, sp, sp_stride, width, alpha[6 * p + i], dp, p, i, self.stroke_low,
                      self.stroke_high)
            # the crank rate
            row = self.starts[1] + 6 + i if p == 0 else self.starts[5] + 6 * (p - 1) + i
            for c in range(width):
                s = 0.0
                for j in range(6):
                    s += da[6 * i + j] * sp[j * sp_stride + c] + jp[6 * i + j] * sv[j * sp_stride + c]
                self.pM[row * nu + c] = s
            value = 0.0
            for j in range(6):
                value += jp[6 * i + j] * dv[j] + da[6 * i + j] * dp[j]
            if p == 0:
                self.plegs[6 + i] = value
                _bounds(self, row, value, self.next_low[6 + i], self.next_high[6 + i])
            else:
                _bounds(self, row, value, -self.motor[12 + i], self.motor[12 + i])
            # the reach
            row = self.starts[1] + 12 + i if p == 0 else self.starts[6] + CUE_HORIZON_ROWS * (p - 1) + i
            _pose_row(self, row, ds + 6 * i, sp, sp_stride, width, reach[6 * p + i], dp, p, 12 + i, self.cone[i],
                      self.cone[CUE_HORIZON_ROWS + i])
        for i in range(CUE_JOINT_ROWS):
            row = self.starts[1] + 18 + i if p == 0 else self.starts[6] + CUE_HORIZON_ROWS * (p - 1) + 6 + i
            _pose_row(self, row, dj + 6 * i, sp, sp_stride, width, joints[CUE_JOINT_ROWS * p + i], dp, p, 18 + i,
                      self.cone[6 + i], self.cone[CUE_HORIZON_ROWS + 6 + i])


cdef inline void _pose_row(CueingStep self, int row, const double *grad, const double *sp, int sp_stride, int width,
                           double value, const double *dp, int p, int next_row, double low, double high) noexcept:
    """Row ``row`` of a quantity of the pose alone, ``value + grad . (x - xbar)``, with ``x - xbar
    = sp u + dp`` (``sp`` the pose's rows of the prediction, ``width`` columns): at the next sample
    (``p`` 0) the ``legs`` row ``next_row``, within ``next_low``/``next_high``; over the horizon
    within ``low`` and ``high``."""
    cdef int c, j, nu = self.nu
    cdef double s
    for c in range(width):
        s = 0.0
        for j in range(6):
            s += grad[j] * sp[j * sp_stride + c]
        self.pM[row * nu + c] = s
    for j in range(6):
        value += grad[j] * dp[j]
    if p == 0:
        self.plegs[next_row] = value
        _bounds(self, row, value, self.next_low[next_row], self.next_high[next_row])
    else:
        _bounds(self, row, value, low, high)


cdef object _crank_next_values(CueingStep self, x0, v0, u0):
    """The crank angles, crank rates, reaches and joints ``(48,)`` at the next log sample after
    ``u0`` held from pose ``x0`` and rates ``v0``, exact (the generated cueing_rows)."""
    cdef double x1[6]
    cdef double v1[6]
    cdef double out[18 + CUE_JOINT_ROWS]
    cdef double grads[108]
    cdef double joint_grads[6 * CUE_JOINT_ROWS]
    cdef int r
    cdef double dt = self.dt
    for r in range(6):
        x1[r] = x0[r] + dt * v0[r] + 0.5 * dt ** 2 * u0[r]
        v1[r] = v0[r] + dt * u0[r]
    _crank_call(self, 1, x1, v1, out, grads, joint_grads)
    return np.array([out[r] for r in range(18 + CUE_JOINT_ROWS)])
