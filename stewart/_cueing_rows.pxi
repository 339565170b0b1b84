# The constraint rows of MPC cueing's step and their bounds (included by stewart/_kernel.pyx after
# stewart/_cueing.pxi, whose CueingStep.condense calls them): the leg lengths, leg speeds and joint
# cosines at the next log sample and over the horizon, the actuator forces, the roll and pitch
# rates, the pose box and the rest at the horizon's end, each row affine in the inputs about the
# linearization point, then DAQP's scaled copy.

cdef inline void _bounds(CueingStep self, int row, double value, double low, double high) noexcept:
    """Row ``row``'s bounds, ``low <= M u + value <= high`` as ``lo <= M u <= hi``."""
    self.plo[row] = low - value
    self.phi[row] = high - value


cdef void _leg_rows(CueingStep self) except *:
    """The leg lengths, speeds and joint cosines at the next log sample (the first input held
    over dt) and at s_1..s_N, affine in u about the linearization point."""
    cdef int n = self.n, ns = self.ns, nu = self.nu, points = self.n + 1
    cdef int k, p, r, j, c, i, width, row
    cdef double dt = self.dt, hk, s
    cdef double sp0[36]
    cdef double sv0[36]
    cdef double dp[6]
    cdef double dv[6]
    cdef const double *sp
    cdef const double *sv
    cdef const double *jl
    cdef const double *cg
    cdef double hl[36]
    cdef double jlt[36]
    cdef int sp_stride
    for r in range(6):
        self.xbar[r] = self.x0[r] + dt * self.v0[r] + 0.5 * dt * dt * self.us[r]
        self.vbar[r] = self.v0[r] + dt * self.us[r]
    for k in range(n):
        hk = self.h[k]
        for r in range(6):
            self.xbar[6 * (k + 1) + r] = self.xs[6 * k + r] + hk * self.vs[6 * k + r] + 0.5 * hk * hk * self.us[6 * k + r]
            self.vbar[6 * (k + 1) + r] = self.vs[6 * k + r] + hk * self.us[6 * k + r]
    for p in range(points):
        for j in range(6):
            for r in range(6):
                self.rate_x[36 * p + 6 * j + r] = self.xbar[6 * p + r]
                self.acc_x[72 * p + 6 * j + r] = self.xbar[6 * p + r]
                self.acc_x[72 * p + 36 + 6 * j + r] = self.xbar[6 * p + r]
                self.acc_v[72 * p + 6 * j + r] = self.vbar[6 * p + r] + (1.0 if r == j else 0.0)
                self.acc_v[72 * p + 36 + 6 * j + r] = self.vbar[6 * p + r] - (1.0 if r == j else 0.0)
    T.batch_leg_rates(&self.dynamics.p, 6 * points, self.rate_x, self.rate_v, self.rates, self.status)
    if self._failed(6 * points):
        self._raise(self.dynamics, "leg_rates", (self._array(self.rate_x, 6 * points),
                                                         self._array(self.rate_v, 6 * points)))
    T.batch_leg_accelerations(&self.dynamics.p, 12 * points, self.acc_x, self.acc_v, self.acc_zero, self.acc,
                              self.status)
    if self._failed(12 * points):
        self._raise(self.dynamics, "leg_accelerations",
                    (self._array(self.acc_x, 12 * points), self._array(self.acc_v, 12 * points),
                     self._array(self.acc_zero, 12 * points)))
    T.batch_joint_cosines(&self.dynamics.p, points, self.xbar, self.axes, self.axes + 6 * points,
                          self.axes + 12 * points, self.cos, self.cos_grad, self.status)
    if self._failed(points):
        self._raise(self.dynamics, "joint_cosines",
                    (self._array(self.xbar, points), self._array(self.axes, points),
                     self._array(self.axes + 6 * points, points), self._array(self.axes + 12 * points, points)))
    for r in range(36):
        sp0[r], sv0[r] = 0.0, 0.0
    for r in range(6):
        sp0[7 * r], sv0[7 * r] = 0.5 * dt * dt, dt
    for p in range(points):
        # dL/dx (column j: Ldot at e_j) and dLdot/dx along v (polarization of the quadratic form)
        for i in range(6):
            for j in range(6):
                jlt[6 * i + j] = self.rates[72 * p + 12 * j + 6 + i]
                hl[6 * i + j] = 0.25 * (self.acc[72 * p + 6 * j + i] - self.acc[72 * p + 36 + 6 * j + i])
        cg = self.cos_grad + 72 * p
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
            # the length
            row = self.starts[1] + i if p == 0 else self.starts[4] + 6 * (p - 1) + i
            for c in range(width):
                s = 0.0
                for j in range(6):
                    s += jlt[6 * i + j] * sp[j * sp_stride + c]
                self.pM[row * nu + c] = s
            s = self.rates[72 * p + 12 * i + i]  # L_i (the lengths at every probe)
            for j in range(6):
                s += jlt[6 * i + j] * dp[j]
            if p == 0:
                self.plegs[i] = s
                _bounds(self, row, s, self.next_low[i], self.next_high[i])
            else:
                _bounds(self, row, s, self.stroke_low, self.stroke_high)
            # the speed
            row = self.starts[1] + 6 + i if p == 0 else self.starts[5] + 6 * (p - 1) + i
            for c in range(width):
                s = 0.0
                for j in range(6):
                    s += hl[6 * i + j] * sp[j * sp_stride + c] + jlt[6 * i + j] * sv[j * sp_stride + c]
                self.pM[row * nu + c] = s
            s = 0.0
            for j in range(6):
                s += jlt[6 * i + j] * dv[j] + hl[6 * i + j] * dp[j]
            if p == 0:
                self.plegs[6 + i] = s
                _bounds(self, row, s, self.next_low[6 + i], self.next_high[6 + i])
            else:
                _bounds(self, row, s, -self.motor[12 + i], self.motor[12 + i])
        for i in range(12):
            row = self.starts[1] + 12 + i if p == 0 else self.starts[6] + 12 * (p - 1) + i
            for c in range(width):
                s = 0.0
                for j in range(6):
                    s += cg[6 * i + j] * sp[j * sp_stride + c]
                self.pM[row * nu + c] = s
            s = self.cos[12 * p + i]
            for j in range(6):
                s += cg[6 * i + j] * dp[j]
            if p == 0:
                self.plegs[12 + i] = s
                _bounds(self, row, s, self.next_low[12 + i], self.next_high[12 + i])
            else:
                _bounds(self, row, s, self.cone[i], INFINITY)


cdef void _force_rows(CueingStep self) except *:
    """The actuator forces at the intervals' starts (the present sample's twice: within the
    force, and within the force less its margin), affine in u: exact in u_k."""
    cdef int n = self.n, ns = self.ns, nu = self.nu
    cdef int k, i, j, c, row, width
    cdef double s
    cdef const double *Sp
    cdef const double *Sv
    cdef const double *ins[3]
    cdef double *outs[4]
    if self.rotary:
        ins[0], ins[1], ins[2] = self.xs, self.vs, self.us
        outs[0], outs[1], outs[2], outs[3] = self.tau, self.tdx, self.tdv, self.tdu
        self.torques_fn(<const stewart_params *>&self.crank_model.p, n, ins, 0.0, outs, self.status)
    else:
        T.batch_inverse_dynamics_derivatives(&self.dynamics.p, n, self.xs, self.vs, self.us, self.tau, self.tdx,
                                             self.tdv, self.tdu, self.status)
    if self._failed(n):
        self._raise(self.crank_model if self.rotary else self.dynamics, "inverse_dynamics_derivatives",
                    (self._array(self.xs, n), self._array(self.vs, n), self._array(self.us, n)))
    for k in range(n):
        width = 6 * k
        Sp, Sv = self.pS + (k * ns + CUE_P) * nu, self.pS + (k * ns + CUE_V) * nu
        for i in range(6):
            row = self.starts[3] + 6 * k + i
            for c in range(width):
                s = 0.0
                for j in range(6):
                    s += self.tdx[36 * k + 6 * i + j] * Sp[j * nu + c] + self.tdv[36 * k + 6 * i + j] * Sv[j * nu + c]
                self.pM[row * nu + c] = s
            for c in range(6):
                self.pM[row * nu + width + c] = self.tdu[36 * k + 6 * i + c]
            s = self.tau[6 * k + i]
            for j in range(6):
                s += self.tdx[36 * k + 6 * i + j] * (self.pd[k * ns + CUE_P + j] - (self.xs[6 * k + j] - self.home[j])) \
                    + self.tdv[36 * k + 6 * i + j] * (self.pd[k * ns + CUE_V + j] - self.vs[6 * k + j]) \
                    - self.tdu[36 * k + 6 * i + j] * self.us[6 * k + j]
            _bounds(self, row, s, -self.motor[6 + i], self.motor[6 + i])
            if k == 0:
                memcpy(self.pM + (self.starts[0] + i) * nu, self.pM + row * nu, nu * sizeof(double))
                _bounds(self, self.starts[0] + i, s, -self.motor[i], self.motor[i])


cdef void _motion_rows(CueingStep self, const double *veh) noexcept:
    """The roll and pitch rates at the next sample and at s_1..s_N within the vehicle's band,
    the pose box and the rest at the horizon's end."""
    cdef int n = self.n, ns = self.ns, nu = self.nu
    cdef int k, i, r, c, row
    cdef double w, low, high
    for i in range(2):  # theta' against the vehicle's w_y, phi' against its w_x
        for k in range(n + 1):
            w = veh[6 * max(k - 1, 0) + 4 - i]
            low, high = min(w, 0.0) - self.tilt_rate, max(w, 0.0) + self.tilt_rate
            if k == 0:
                row = self.starts[2] + i
                self.pM[row * nu + 4 + i] = self.dt
                _bounds(self, row, self.v0[4 + i], low, high)
            else:
                row = self.starts[7] + 2 * (k - 1) + i
                memcpy(self.pM + row * nu, self.pS + (k * ns + CUE_V + 4 + i) * nu, 6 * k * sizeof(double))
                _bounds(self, row, self.pd[k * ns + CUE_V + 4 + i], low, high)
    for k in range(1, n + 1):
        for r in range(6):
            row = self.starts[8] + 6 * (k - 1) + r
            memcpy(self.pM + row * nu, self.pS + (k * ns + CUE_P + r) * nu, 6 * k * sizeof(double))
            _bounds(self, row, self.pd[k * ns + CUE_P + r], -self.box[r], self.box[r])
    for r in range(6):
        row = self.starts[9] + r
        memcpy(self.pM + row * nu, self.pS + (n * ns + CUE_V + r) * nu, nu * sizeof(double))
        _bounds(self, row, self.pd[n * ns + CUE_V + r], 0.0, 0.0)


cdef void _scaled(CueingStep self) noexcept:
    """DAQP's rows and bounds: in units of each row's limit, the inset rows moved in, the
    infinite bounds at 1e30."""
    cdef int r, c, nu = self.nu
    cdef double f
    for r in range(self.m):
        f = self.inv_scale[r]
        for c in range(nu):
            self.pA[r * nu + c] = self.pM[r * nu + c] * f
        self.pup[r] = min(self.phi[r] * f - self.inset[r], 1e30)
        self.plow[r] = max(self.plo[r] * f + self.inset[r], -1e30)
