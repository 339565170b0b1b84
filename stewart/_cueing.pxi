# One step of MPC cueing's QP, linearized and condensed in C (included by stewart/_kernel.pyx:
# stewart._kernel.CueingStep; the formulation is stewart.cueing.planner's).
#
# Per step, from the present state and the last plan: the linearization point (the last plan
# shifted by one sample), the rider's signals and their Jacobians at the intervals' midpoints
# (the model's batch_rider_signals), the condensed prediction S u + d of the states s_1..s_N
# (double integrator and vestibular sections, a lower block-triangular S), the cost's H and q
# (H = G^T G + diag, G the weighted rows of S: BLAS's dsyrk), and every constraint row with
# its bounds: the leg lengths, speeds and joint cosines (batch_leg_rates,
# batch_leg_accelerations by polarization, batch_joint_cosines) and the forces
# (batch_inverse_dynamics_derivatives), each affine in u about the linearization point. Every
# array is allocated once, with the step.

from scipy.linalg.cython_blas cimport dsyrk, dgemv

#: The rows of the constraint groups, in the order of stewart.cueing.planner.GROUPS (on a rotary
#: rig, stewart/_cueing_rotary.pxi: ``legs`` the crank angles, crank rates, reaches and joints
#: at the next sample, ``force`` the motor torques, ``stroke`` the crank angles, ``speed`` the
#: crank rates and ``cones`` the reaches and joints over the horizon).
CUEING_GROUPS = ("actuators", "legs", "next_tilt", "force", "stroke", "speed", "cones", "tilt", "box", "rest")

cdef enum:
    CUE_P = 0          # the state's pose, rates and vestibular states start here
    CUE_V = 6
    CUE_Z = 12
    CUE_LEGS_ROWS = 24  # a sample's leg lengths, leg speeds and joint cosines
    CUE_CRANK_ROWS = 48  # a rotary rig's: crank angles, crank rates, reaches and joints
    CUE_JOINT_ROWS = 30  # a rotary point's joints: rod-crank, crank-joint, platform-joint cosines, heights, pins
    CUE_HORIZON_ROWS = 36  # a rotary horizon point's cones rows: the reaches, then the joints
    CUE_COST_ROWS = 18  # a sample's weighted rows of the cost: pose, rates, perceived channels


cdef inline double *_data(cnp.ndarray a):
    return <double *>cnp.PyArray_DATA(a)


cdef cnp.ndarray _zeros(shape):
    return np.zeros(shape, dtype=np.float64)


@cython.final
cdef class CueingStep:
    """The QP of one MPC cueing step (:class:`stewart.cueing.planner.CueingQP`), built in C.

    ``dynamics`` and ``rider``: the compiled models of the platform and of its rider's signals
    (the MPC's gravity); ``h`` ``(n,)`` the intervals; ``dt`` the log's sample; ``home``;
    ``neutral`` ``(6, 3)`` the joints' neutral axes; the vestibular sections discretized per
    interval, ``decay`` and ``gain`` ``(n, nz)`` (the diagonal of A_d and the one nonzero of each
    row of B_d), their ``channel`` ``(nz,)`` and ``output`` ``(nz,)`` (C's one nonzero per
    column); ``weights`` ``(18,)`` the cost per second of the pose, rates and perceived channels,
    ``input_weight`` ``(6 n,)``; ``shift`` ``(n, 2)`` the last plan's knot and weight at each
    interval's start one sample later; ``starts`` the first row of each group
    (:data:`CUEING_GROUPS`) and the rows' count; ``row_scale`` and ``inset`` ``(m,)``;
    ``limits``: ``(force, force_limit, stroke low, stroke high, speed_limit, tilt_rate)``,
    ``cone`` ``(12,)`` the cosines' bounds over the horizon, ``next_low``, ``next_high``
    ``(24,)`` the ``legs`` rows' and ``box`` ``(6,)``; ``decay_dt`` and ``gain_dt`` ``(nz,)`` the
    sections discretized over one log sample (:meth:`advance`). On a rotary rig (``dynamics`` a
    RotaryKernel): ``cone`` ``(72,)`` the ``cones`` rows' lower bounds (36: the reaches, the
    joints), then their upper; ``next_low``, ``next_high`` ``(48,)``; ``motor`` ``(18,)`` the
    torque limits, less their margin, and the speed limits less theirs.

    :meth:`condense` fills ``H``, ``q``, the rows ``M`` and bounds ``lo``, ``hi`` (unscaled),
    DAQP's ``A``, ``upper``, ``lower`` (scaled, inset, infinite bounds at 1e30), the states'
    ``S`` ``(n + 1, ns, 6 n)`` and ``d`` ``(n + 1, ns)`` (s_0 first) and ``legs_constant`` the
    ``legs`` rows' values at u = 0 (the arrays are the step's own, overwritten by the next)."""

    cdef Kernel dynamics, rider
    cdef RotaryKernel crank_model  # a rotary rig's (stewart/_cueing_rotary.pxi), else None
    cdef readonly bint rotary
    cdef readonly int legs_rows    # the legs group's rows: 24, or 48 on a rotary rig
    cdef stewart_call rows_fn, torques_fn
    cdef readonly int n, nz, ns, nu, m
    cdef double dt, force, force_limit, stroke_low, stroke_high, speed_limit, tilt_rate
    cdef int starts[11]
    cdef int *channel
    cdef int *knot
    cdef int *status
    cdef bint has_last
    cdef list _keep  # the arrays the pointers below are into
    cdef double *h
    cdef double *home
    cdef double *axes      # the neutral axes as batch_joint_cosines reads them: (n + 1, 6) per component
    cdef double *decay
    cdef double *gain
    cdef double *output
    cdef double *cost_root  # sqrt(h_k weights) (n, 18)
    cdef double *input_weight
    cdef double *weight
    cdef double *inv_scale
    cdef double *inset
    cdef double *cone
    cdef double *next_low
    cdef double *next_high
    cdef double *box
    cdef double *decay_dt
    cdef double *gain_dt
    # per step
    cdef double *x0
    cdef double *v0
    cdef double *xs
    cdef double *vs
    cdef double *us
    cdef double *xm
    cdef double *vm
    cdef double *y
    cdef double *yx
    cdef double *yv
    cdef double *yu
    cdef double *y0
    cdef double *G
    cdef double *mix
    cdef double *gd
    cdef double *xbar
    cdef double *vbar
    cdef double *rate_x
    cdef double *rate_v
    cdef double *rates
    cdef double *acc_x
    cdef double *acc_v
    cdef double *acc_zero
    cdef double *acc
    cdef double *cos
    cdef double *cos_grad
    cdef double *tau
    cdef double *tdx
    cdef double *tdv
    cdef double *tdu
    cdef double *motor     # per actuator: its force (torque) limit, less its margin, its speed less its margin
    cdef double *crank_out    # rotary: per point alpha, alpha_dot, reach (18), the joints (30)
    cdef double *crank_grads  # rotary: per point J_alpha T, d alpha_dot/dx, d reach/dx (108)
    cdef double *joint_grads  # rotary: per point d joints/dx (180)
    cdef double *refs         # rotary: the pose the joints are centred at (home), once per point
    cdef double *last_x
    cdef double *last_v
    cdef double *last_u
    cdef readonly cnp.ndarray H, q, M, lo, hi, A, upper, lower, S, d, legs_constant
    cdef double *pH
    cdef double *pq
    cdef double *pM
    cdef double *plo
    cdef double *phi
    cdef double *pA
    cdef double *pup
    cdef double *plow
    cdef double *pS
    cdef double *pd
    cdef double *plegs

    def __cinit__(self, dynamics, Kernel rider, h, double dt, home, neutral, decay, gain, channel, output,
                  weights, input_weight, shift, starts, row_scale, inset, limits, cone, next_low, next_high, box,
                  decay_dt, gain_dt, motor=None):
        cdef int k, i, n = len(h), nz = np.shape(decay)[1], ns, nu
        cdef _Function f
        self.rider = rider
        self.rotary = isinstance(dynamics, RotaryKernel)
        if self.rotary:
            self.crank_model = dynamics
            f = _ROTARY["cueing_rows"]
            self.rows_fn = _rotary_table().call[f.index]
            f = _ROTARY["inverse_dynamics_derivatives"]
            self.torques_fn = _rotary_table().call[f.index]
            self.legs_rows = CUE_CRANK_ROWS
        else:
            self.dynamics = dynamics
            self.legs_rows = CUE_LEGS_ROWS
        self.n, self.nz, self.ns, self.nu, self.dt = n, nz, CUE_Z + nz, 6 * n, dt
        if len(starts) != 11:
            raise ValueError("CueingStep: need the first row of each of the 10 groups and the rows' count")
        self.m = int(starts[10])
        if np.shape(decay) != (n, nz) or np.shape(gain) != (n, nz) or len(row_scale) != self.m:
            raise ValueError("CueingStep: inconsistent sizes")
        for k in range(11):
            self.starts[k] = starts[k]
        (self.force, self.force_limit, self.stroke_low, self.stroke_high, self.speed_limit,
         self.tilt_rate) = [float(v) for v in limits]
        self._keep = []
        ns, nu = self.ns, self.nu
        self.h = self._fixed(h, n)
        self.mix = self._buffer(6 * nu)
        self.home = self._fixed(home, 6)
        neutral = np.asarray(neutral, dtype=np.float64).reshape(6, 3)
        self.axes = self._fixed(np.concatenate([np.tile(neutral[:, c], (n + 1, 1)).ravel() for c in range(3)]),
                          3 * 6 * (n + 1))
        self.decay = self._fixed(decay, n * nz)
        self.gain = self._fixed(gain, n * nz)
        self.output = self._fixed(output, nz)
        w = np.asarray(weights, dtype=np.float64).reshape(CUE_COST_ROWS)
        self.cost_root = self._fixed(np.sqrt(np.asarray(h, dtype=np.float64)[:, None] * w), n * CUE_COST_ROWS)
        self.input_weight = self._fixed(input_weight, nu)
        self.inv_scale = self._fixed(1.0 / np.asarray(row_scale, dtype=np.float64), self.m)
        self.inset = self._fixed(inset, self.m)
        self.cone = self._fixed(cone, 2 * CUE_HORIZON_ROWS if self.rotary else 12)
        self.next_low = self._fixed(next_low, self.legs_rows)
        self.next_high = self._fixed(next_high, self.legs_rows)
        if motor is None:
            motor = np.concatenate([np.full(6, self.force), np.full(6, self.force_limit), np.full(6, self.speed_limit)])
        self.motor = self._fixed(motor, 18)
        self.crank_out = self._buffer(CUE_CRANK_ROWS * (n + 1))
        self.crank_grads = self._buffer(108 * (n + 1))
        self.joint_grads = self._buffer(6 * CUE_JOINT_ROWS * (n + 1))
        self.refs = self._fixed(np.tile(np.asarray(home, dtype=np.float64), n + 1), 6 * (n + 1))
        self.box = self._fixed(box, 6)
        self.decay_dt = self._fixed(decay_dt, nz)
        self.gain_dt = self._fixed(gain_dt, nz)
        shift = np.asarray(shift, dtype=np.float64).reshape(n, 2)
        self.weight = self._fixed(shift[:, 1], n)
        knots = np.ascontiguousarray(shift[:, 0], dtype=np.intc)
        chans = np.ascontiguousarray(channel, dtype=np.intc)
        statuses = np.zeros(12 * (n + 1), dtype=np.intc)
        self._keep += [knots, chans, statuses]
        self.knot = <int *>cnp.PyArray_DATA(knots)
        self.channel = <int *>cnp.PyArray_DATA(chans)
        self.status = <int *>cnp.PyArray_DATA(statuses)
        self.x0, self.v0 = self._buffer(6), self._buffer(6)
        self.xs, self.vs, self.us = self._buffer(6 * n), self._buffer(6 * n), self._buffer(6 * n)
        self.xm, self.vm = self._buffer(6 * n), self._buffer(6 * n)
        self.y, self.y0 = self._buffer(6 * n), self._buffer(6 * n)
        self.yx, self.yv, self.yu = self._buffer(36 * n), self._buffer(36 * n), self._buffer(36 * n)
        self.G, self.gd = self._buffer(CUE_COST_ROWS * n * nu), self._buffer(CUE_COST_ROWS * n)
        self.xbar, self.vbar = self._buffer(6 * (n + 1)), self._buffer(6 * (n + 1))
        self.rate_x, self.rates = self._buffer(36 * (n + 1)), self._buffer(72 * (n + 1))
        self.rate_v = self._fixed(np.tile(np.eye(6), (n + 1, 1)), 36 * (n + 1))  # the unit probes
        self.acc_x, self.acc_v = self._buffer(72 * (n + 1)), self._buffer(72 * (n + 1))
        self.acc_zero, self.acc = self._buffer(72 * (n + 1)), self._buffer(72 * (n + 1))
        self.cos, self.cos_grad = self._buffer(12 * (n + 1)), self._buffer(72 * (n + 1))
        self.tau, self.tdx = self._buffer(6 * n), self._buffer(36 * n)
        self.tdv, self.tdu = self._buffer(36 * n), self._buffer(36 * n)
        self.last_x, self.last_v, self.last_u = self._buffer(6 * (n + 1)), self._buffer(6 * (n + 1)), self._buffer(6 * n)
        self.H, self.q = _zeros((nu, nu)), _zeros(nu)
        self.M, self.lo, self.hi = _zeros((self.m, nu)), _zeros(self.m), _zeros(self.m)
        self.A, self.upper, self.lower = _zeros((self.m, nu)), _zeros(self.m), _zeros(self.m)
        self.S, self.d = _zeros((n + 1, ns, nu)), _zeros((n + 1, ns))
        self.legs_constant = _zeros(self.legs_rows)
        self.pH, self.pq, self.pM, self.plo, self.phi = _data(self.H), _data(self.q), _data(self.M), _data(self.lo), \
            _data(self.hi)
        self.pA, self.pup, self.plow = _data(self.A), _data(self.upper), _data(self.lower)
        self.pS, self.pd, self.plegs = _data(self.S), _data(self.d), _data(self.legs_constant)
        self.has_last = False

    cdef double *_fixed(self, values, Py_ssize_t size) except NULL:
        """A copy of ``values`` (``size`` of them), kept with the step."""
        cdef cnp.ndarray arr = np.array(values, dtype=np.float64).reshape(-1)
        if arr.shape[0] != size:
            raise ValueError(f"CueingStep: {size} values expected, got {arr.shape[0]}")
        self._keep.append(arr)
        return _data(arr)

    cdef double *_buffer(self, Py_ssize_t size) except NULL:
        """``size`` zeros, kept with the step."""
        cdef cnp.ndarray arr = np.zeros(size)
        self._keep.append(arr)
        return _data(arr)

    def forget(self):
        """Linearize the next step about the present state held (no last plan)."""
        self.has_last = False

    def keep(self, u, x, v):
        """Linearize the next step about the plan ``u`` ``(n, 6)`` and its states ``x``, ``v``
        ``(n + 1, 6)`` (from :meth:`states`)."""
        cdef cnp.ndarray cu = np.ascontiguousarray(u, dtype=np.float64)
        cdef cnp.ndarray cx = np.ascontiguousarray(x, dtype=np.float64)
        cdef cnp.ndarray cv = np.ascontiguousarray(v, dtype=np.float64)
        if cu.size != 6 * self.n or cx.size != 6 * (self.n + 1) or cv.size != 6 * (self.n + 1):
            raise ValueError(f"u, x, v: expected ({self.n}, 6), ({self.n + 1}, 6) and ({self.n + 1}, 6)")
        memcpy(self.last_u, _data(cu), 6 * self.n * sizeof(double))
        memcpy(self.last_x, _data(cx), 6 * (self.n + 1) * sizeof(double))
        memcpy(self.last_v, _data(cv), 6 * (self.n + 1) * sizeof(double))
        self.has_last = True

    def states(self, u):
        """The poses and rates ``(n + 1, 6)`` each of the plan ``u`` ``(6 n,)``: ``s = S u + d``,
        the pose from home, after the present state."""
        cdef cnp.ndarray cu = np.ascontiguousarray(u, dtype=np.float64).reshape(-1)
        if cu.shape[0] != self.nu:
            raise ValueError(f"u: expected {self.nu} inputs, got {cu.shape[0]}")
        cdef cnp.npy_intp dims[2]
        dims[0], dims[1] = self.n + 1, 6
        cdef cnp.ndarray x = cnp.PyArray_EMPTY(2, dims, cnp.NPY_DOUBLE, 0)
        cdef cnp.ndarray v = cnp.PyArray_EMPTY(2, dims, cnp.NPY_DOUBLE, 0)
        cdef double *px = _data(x)
        cdef double *pv = _data(v)
        cdef const double *pu = _data(cu)
        cdef int k, r, c, ns = self.ns, nu = self.nu
        cdef double sx, sv
        cdef const double *row
        for r in range(6):
            px[r], pv[r] = self.x0[r], self.v0[r]
        for k in range(1, self.n + 1):
            for r in range(6):
                sx, sv = 0.0, 0.0
                row = self.pS + (k * ns + CUE_P + r) * nu
                for c in range(6 * k):
                    sx += row[c] * pu[c]
                row = self.pS + (k * ns + CUE_V + r) * nu
                for c in range(6 * k):
                    sv += row[c] * pu[c]
                px[6 * k + r] = sx + self.pd[k * ns + CUE_P + r] + self.home[r]
                pv[6 * k + r] = sv + self.pd[k * ns + CUE_V + r]
        return x, v

    def advance(self, x, v, applied, y_now, y_next, cnp.ndarray z_platform, cnp.ndarray z_vehicle):
        """The vestibular states one log sample on, in place: the platform's ``z_platform`` under
        the rider's signals at the sample's midpoint from pose ``x`` and rates ``v`` under the
        input ``applied`` held, the vehicle's ``z_vehicle`` under the mean of its signals ``y_now``
        and ``y_next`` (the sections discretized with the signal held, ``decay_dt``, ``gain_dt``)."""
        cdef double xm[6]
        cdef double vm[6]
        cdef double um[6]
        cdef double y[6]
        cdef double jac[108]
        cdef double dt = self.dt
        cdef int r, i, ch
        if (z_platform.dtype != np.float64 or z_vehicle.dtype != np.float64 or not z_platform.flags.c_contiguous
                or not z_vehicle.flags.c_contiguous or z_platform.size != self.nz or z_vehicle.size != self.nz):
            raise ValueError(f"z_platform, z_vehicle: need ({self.nz},) C-contiguous float64 arrays")
        cdef double *zp = _data(z_platform)
        cdef double *zv = _data(z_vehicle)
        for r in range(6):
            um[r] = applied[r]
            xm[r] = x[r] + 0.5 * dt * v[r] + 0.125 * dt * dt * um[r]
            vm[r] = v[r] + 0.5 * dt * um[r]
        if T.rider_signals(&self.rider.p, xm, vm, um, y, jac, jac + 36, jac + 72) != STEWART_OK:
            self.rider.call("rider_signals", (np.array([xm[r] for r in range(6)]), np.array([vm[r] for r in range(6)]),
                                                 np.array([um[r] for r in range(6)])))
        for i in range(self.nz):
            ch = self.channel[i]
            zp[i] = self.decay_dt[i] * zp[i] + self.gain_dt[i] * y[ch]
            zv[i] = self.decay_dt[i] * zv[i] + self.gain_dt[i] * (0.5 * (y_now[ch] + y_next[ch]))

    def next_values(self, x0, v0, u0):
        """The leg lengths, leg speeds and joint cosines ``(24,)`` at the next log sample after
        ``u0`` held from pose ``x0`` and rates ``v0``, by the exact kinematics (on a rotary rig,
        ``(18,)``: the crank angles, crank rates and reaches)."""
        if self.rotary:
            return _crank_next_values(self, x0, v0, u0)
        cdef double x1[6]
        cdef double v1[6]
        cdef double out[CUE_LEGS_ROWS]
        cdef double grad[72]
        cdef double axes[18]
        cdef int r, s1, s2
        cdef double dt = self.dt
        for r in range(6):
            x1[r] = x0[r] + dt * v0[r] + 0.5 * dt ** 2 * u0[r]
            v1[r] = v0[r] + dt * u0[r]
            axes[r], axes[6 + r], axes[12 + r] = self.axes[r], self.axes[6 * (self.n + 1) + r], \
                self.axes[12 * (self.n + 1) + r]
        s1 = T.leg_rates(&self.dynamics.p, x1, v1, out)
        s2 = T.joint_cosines(&self.dynamics.p, x1, axes, axes + 6, axes + 12, out + 12, grad)
        if s1 != STEWART_OK or s2 != STEWART_OK:
            xa, va = np.array([x1[r] for r in range(6)]), np.array([v1[r] for r in range(6)])
            self.dynamics.call("leg_rates", (xa, va))
            self.dynamics.call("joint_cosines", (xa, np.array([axes[r] for r in range(6)]),
                                                 np.array([axes[6 + r] for r in range(6)]),
                                                 np.array([axes[12 + r] for r in range(6)])))
        return np.array([out[r] for r in range(CUE_LEGS_ROWS)])

    cdef bint _failed(self, int rows) noexcept:
        """Whether a row of the last batch call failed."""
        cdef int r
        for r in range(rows):
            if self.status[r] != STEWART_OK:
                return True
        return False

    cdef int _raise(self, kernel, str name, tuple arrays) except -1:
        """Raise the model's error for a failed batch: its Python call on the same rows."""
        kernel.call(name, arrays)
        raise SingularityError(f"{name}: failed in the cueing step")  # (the call raised already)

    def condense(self, x0, v0, z0, vehicle):
        """The QP of the step from pose ``x0``, rates ``v0`` and vestibular error states ``z0``
        for the vehicle's signals ``vehicle`` ``(n, 6)`` at the intervals' midpoints."""
        cdef int n = self.n, nz = self.nz, ns = self.ns, nu = self.nu
        cdef int k, r, j, c, i, p, row, width
        cdef double a, s, half, eighth, hk
        cdef cnp.ndarray cveh = np.ascontiguousarray(vehicle, dtype=np.float64)
        cdef cnp.ndarray cz = np.ascontiguousarray(z0, dtype=np.float64)
        if cveh.size != 6 * n or cz.size != nz:
            raise ValueError(f"vehicle, z0: expected ({n}, 6) and ({nz},), got {np.shape(vehicle)}, {np.shape(z0)}")
        cdef const double *veh = _data(cveh)
        cdef const double *pz = _data(cz)
        for r in range(6):
            self.x0[r], self.v0[r] = x0[r], v0[r]
        self._linearization_point()
        if self.rotary:
            _crank_starts(self)
            _crank_points(self)
        # the rider's signals at the midpoints and their Jacobians in the start's state and input
        for k in range(n):
            hk = self.h[k]
            for r in range(6):
                self.xm[6 * k + r] = self.xs[6 * k + r] + 0.5 * hk * self.vs[6 * k + r] \
                    + 0.125 * hk * hk * self.us[6 * k + r]
                self.vm[6 * k + r] = self.vs[6 * k + r] + 0.5 * hk * self.us[6 * k + r]
        T.batch_rider_signals(&self.rider.p, n, self.xm, self.vm, self.us, self.y, self.yx, self.yv, self.yu,
                              self.status)
        if self._failed(n):
            self._raise(self.rider, "rider_signals", (self._array(self.xm, n), self._array(self.vm, n),
                                                       self._array(self.us, n)))
        for k in range(n):
            half, eighth = 0.5 * self.h[k], 0.125 * self.h[k] * self.h[k]
            for i in range(36):  # y_p = y_x, y_v = y_x h/2 + y_v, y_u = y_x h^2/8 + y_v h/2 + y_u
                a = self.yx[36 * k + i]
                self.yu[36 * k + i] = a * eighth + self.yv[36 * k + i] * half + self.yu[36 * k + i]
                self.yv[36 * k + i] = a * half + self.yv[36 * k + i]
            for r in range(6):
                s = self.y[6 * k + r]
                for j in range(6):
                    s -= self.yx[36 * k + 6 * r + j] * (self.xs[6 * k + j] - self.home[j]) \
                        + self.yv[36 * k + 6 * r + j] * self.vs[6 * k + j] + self.yu[36 * k + 6 * r + j] * self.us[6 * k + j]
                self.y0[6 * k + r] = s - veh[6 * k + r]
        self._prediction(pz)
        self._cost()
        if self.rotary:
            _crank_rows(self)
        else:
            _leg_rows(self)
        _force_rows(self)
        _motion_rows(self, veh)
        _scaled(self)

    cdef object _array(self, double *values, int rows):
        return np.array([[values[6 * k + r] for r in range(6)] for k in range(rows)])

    cdef void _linearization_point(self) noexcept:
        """The last plan at the intervals' starts one sample later (linear between its knots),
        or the present state held; the first at the present state."""
        cdef int k, r, j
        cdef double w
        for k in range(self.n):
            j, w = self.knot[k], self.weight[k]
            for r in range(6):
                if self.has_last:
                    self.xs[6 * k + r] = self.last_x[6 * j + r] + w * (self.last_x[6 * j + 6 + r] - self.last_x[6 * j + r])
                    self.vs[6 * k + r] = self.last_v[6 * j + r] + w * (self.last_v[6 * j + 6 + r] - self.last_v[6 * j + r])
                    self.us[6 * k + r] = self.last_u[6 * j + r]
                else:
                    self.xs[6 * k + r], self.vs[6 * k + r], self.us[6 * k + r] = self.x0[r], self.v0[r], 0.0
        for r in range(6):
            self.xs[r], self.vs[r] = self.x0[r], self.v0[r]

    cdef void _prediction(self, const double *z0) noexcept:
        """S and d: s_{k+1} = A_k s_k + B_k u_k + c_k from s_0 = [x0 - home, v0, z0]."""
        cdef int n = self.n, nz = self.nz, ns = self.ns, nu = self.nu
        cdef int k, r, j, c, i, ch, width
        cdef double hk, s, a, g
        cdef double *mix = self.mix  # per channel, y_p S_P + y_v S_V + y_u E_k
        cdef double *S0
        cdef double *S1
        cdef double *d0
        cdef double *d1
        cdef double *yp
        cdef double *yv
        cdef double *yu
        cdef double mixd[6]
        for r in range(6):
            self.pd[CUE_P + r] = self.x0[r] - self.home[r]
            self.pd[CUE_V + r] = self.v0[r]
        for i in range(nz):
            self.pd[CUE_Z + i] = z0[i]
        for k in range(n):
            hk = self.h[k]
            S0, S1 = self.pS + k * ns * nu, self.pS + (k + 1) * ns * nu
            d0, d1 = self.pd + k * ns, self.pd + (k + 1) * ns
            yp, yv, yu = self.yx + 36 * k, self.yv + 36 * k, self.yu + 36 * k
            width = 6 * k
            for r in range(6):
                for c in range(width):
                    S1[(CUE_P + r) * nu + c] = S0[(CUE_P + r) * nu + c] + hk * S0[(CUE_V + r) * nu + c]
                    S1[(CUE_V + r) * nu + c] = S0[(CUE_V + r) * nu + c]
                for c in range(6):
                    S1[(CUE_P + r) * nu + width + c] = 0.5 * hk * hk if c == r else 0.0
                    S1[(CUE_V + r) * nu + width + c] = hk if c == r else 0.0
                d1[CUE_P + r] = d0[CUE_P + r] + hk * d0[CUE_V + r]
                d1[CUE_V + r] = d0[CUE_V + r]
            for ch in range(6):
                for c in range(width):
                    s = 0.0
                    for j in range(6):
                        s += yp[6 * ch + j] * S0[(CUE_P + j) * nu + c] + yv[6 * ch + j] * S0[(CUE_V + j) * nu + c]
                    mix[ch * nu + c] = s
                for c in range(6):
                    mix[ch * nu + width + c] = yu[6 * ch + c]
                s = self.y0[6 * k + ch]
                for j in range(6):
                    s += yp[6 * ch + j] * d0[CUE_P + j] + yv[6 * ch + j] * d0[CUE_V + j]
                mixd[ch] = s
            for i in range(nz):
                ch = self.channel[i]
                a, g = self.decay[k * nz + i], self.gain[k * nz + i]
                for c in range(width):
                    S1[(CUE_Z + i) * nu + c] = a * S0[(CUE_Z + i) * nu + c] + g * mix[ch * nu + c]
                for c in range(width, width + 6):
                    S1[(CUE_Z + i) * nu + c] = g * mix[ch * nu + c]
                d1[CUE_Z + i] = a * d0[CUE_Z + i] + g * mixd[ch]

    cdef void _cost(self) noexcept:
        """H = G^T G + diag(input weight) and q = G^T g, G the rows of S weighted by the roots of
        h_k times the cost's weights (pose, rates, the perceived channels C z)."""
        cdef int n = self.n, nz = self.nz, ns = self.ns, nu = self.nu
        cdef int k, r, c, i, ch, rows = CUE_COST_ROWS * n
        cdef double w
        cdef double *S1
        cdef double *d1
        cdef double *g
        for k in range(n):
            S1, d1 = self.pS + (k + 1) * ns * nu, self.pd + (k + 1) * ns
            g = self.G + CUE_COST_ROWS * k * nu
            for r in range(12):
                w = self.cost_root[CUE_COST_ROWS * k + r]
                for c in range(nu):
                    g[r * nu + c] = w * S1[r * nu + c]
                self.gd[CUE_COST_ROWS * k + r] = w * d1[r]
            for ch in range(6):
                for c in range(nu):
                    g[(12 + ch) * nu + c] = 0.0
                self.gd[CUE_COST_ROWS * k + 12 + ch] = 0.0
            for i in range(nz):
                ch = self.channel[i]
                w = self.cost_root[CUE_COST_ROWS * k + 12 + ch] * self.output[i]
                for c in range(nu):
                    g[(12 + ch) * nu + c] += w * S1[(CUE_Z + i) * nu + c]
                self.gd[CUE_COST_ROWS * k + 12 + ch] += w * d1[CUE_Z + i]
        # column-major, G^T is (nu x rows) with leading dimension nu: H = G^T G
        cdef char uplo = b'U', trans = b'N'
        cdef double one = 1.0, zero = 0.0
        cdef int inc = 1
        dsyrk(&uplo, &trans, &nu, &rows, &one, self.G, &nu, &zero, self.pH, &nu)
        dgemv(&trans, &nu, &rows, &one, self.G, &nu, self.gd, &inc, &zero, self.pq, &inc)
        for r in range(nu):  # the upper triangle in column-major is the lower in row-major
            for c in range(r + 1, nu):
                self.pH[r * nu + c] = self.pH[c * nu + r]
            self.pH[r * nu + r] += self.input_weight[r]
