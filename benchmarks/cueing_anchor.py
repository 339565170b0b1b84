"""The anchor of MPC cueing's step (:mod:`benchmarks.cueing`): the receding horizon's step as it
ran in numpy before it was compiled (:class:`stewart.model.compiled.CueingStep`), with the same
constraint design (the playable-plan rows, groups, levels and tightenings of
:mod:`stewart.cueing.planner`). It linearizes and condenses in numpy, with the rider's
signals and the joints' cosines written out by hand (rotation partials entry by entry), the leg
rows by :meth:`stewart.Platform.leg_rates` and :meth:`~stewart.Platform.leg_accelerations`
(polarization) and the forces by :meth:`~stewart.Platform.inverse_dynamics_derivatives`.

``tests/test_cueing_anchor.py`` holds the compiled step to it: the same QP (H, f, rows and
bounds) and the same plans to round-off, on shipped maneuvers."""

from __future__ import annotations

import time

import daqp
import numpy as np
from threadpoolctl import threadpool_limits

from stewart.cueing import horizon, planner, vestibular
from stewart.cueing.planner import GROUPS, HARD, SOLVED, SOLVER_SETTINGS, TIGHTENINGS, Plan
from stewart.model.kinematics import rotation

__all__ = ["AnchorQP", "plan", "rotation_and_partials", "joint_cosines_and_gradients", "signals_and_jacobians"]

#: DAQP's infinite bound.
_INFINITE = 1e30
_P, _V, _NS = slice(0, 6), slice(6, 12), 12  # the state's pose and rate, the vestibular states' start


def _vehicle_at(times, t, y, preview: bool, now: float):
    """The vehicle's signals ``y`` ``(T, 6)`` at ``times``: interpolated from the log with
    ``preview``, else its present value (at ``now``) held."""
    if not preview:
        return np.tile([np.interp(now, t, y[:, j]) for j in range(6)], (len(times), 1))
    return np.column_stack([np.interp(times, t, y[:, j]) for j in range(6)])


def rotation_and_partials(x) -> np.ndarray:
    """``R = Rz(psi) Ry(theta) Rx(phi)`` of poses ``x`` ``(N, 6)`` and its partials in psi,
    theta and phi, entry by entry: ``(4, N, 3, 3)`` (of complex poses too)."""
    cps, sps = np.cos(x[:, 3]), np.sin(x[:, 3])
    cth, sth = np.cos(x[:, 4]), np.sin(x[:, 4])
    cph, sph = np.cos(x[:, 5]), np.sin(x[:, 5])
    r = np.zeros((4, len(x), 3, 3), dtype=x.dtype)
    r[0, :, 0] = np.stack([cps * cth, cps * sth * sph - sps * cph, cps * sth * cph + sps * sph], -1)
    r[0, :, 1] = np.stack([sps * cth, sps * sth * sph + cps * cph, sps * sth * cph - cps * sph], -1)
    r[0, :, 2] = np.stack([-sth, cth * sph, cth * cph], -1)
    r[1, :, 0] = -r[0, :, 1]
    r[1, :, 1] = r[0, :, 0]
    r[2, :, 0] = np.stack([-cps * sth, cps * cth * sph, cps * cth * cph], -1)
    r[2, :, 1] = np.stack([-sps * sth, sps * cth * sph, sps * cth * cph], -1)
    r[2, :, 2] = np.stack([-cth, -sth * sph, -sth * cph], -1)
    r[3, :, :, 1] = r[0, :, :, 2]
    r[3, :, :, 2] = -r[0, :, :, 1]
    return r


def joint_cosines_and_gradients(x, base_points, platform_points, neutral):
    """The cosines of the universal- and spherical-joint angles at poses ``x`` ``(N, 6)``
    (:func:`stewart.model.reachability.joint_angles`: the leg's unit vector ``u_i`` against
    its neutral axis ``a_i`` fixed in {B}, and against ``R a_i`` for the spherical joint
    fixed in {P}), ``(N, 12)``, and their exact gradients in the pose ``(N, 12, 6)``: with
    ``l_i = p + R p_i - b_i``, ``du/dl = (I - u u^T) / |l|``, ``dl/dp = I``,
    ``dl/dangle = dR/dangle p_i``."""
    x = np.atleast_2d(x)
    n = len(x)
    r = rotation_and_partials(x)
    rp = np.einsum("knab,ib->knia", r, platform_points)                    # R p_i and partials (4, N, 6, 3)
    legs = x[:, None, :3] + rp[0] - base_points
    length = np.linalg.norm(legs, axis=-1)
    u = legs / length[..., None]
    dl = np.zeros((n, 6, 3, 6))
    dl[:, :, :, :3] = np.eye(3)
    dl[:, :, :, 3:] = np.transpose(rp[1:], (1, 2, 3, 0))
    proj = (np.eye(3) - u[..., :, None] * u[..., None, :]) / length[..., None, None]
    du = proj @ dl                                                        # (N, 6, 3, 6)
    spherical_axis = np.einsum("nab,ib->nia", r[0], neutral)              # R a_i
    cos = np.concatenate([np.einsum("nia,ia->ni", u, neutral), np.einsum("nia,nia->ni", u, spherical_axis)], 1)
    grad = np.zeros((n, 12, 6))
    grad[:, :6] = np.einsum("ia,niaj->nij", neutral, du)
    grad[:, 6:] = np.einsum("nia,niaj->nij", spherical_axis, du)
    grad[:, 6:, 3:] += np.einsum("nia,knab,ib->nik", u, r[1:], neutral)
    return cos, grad


def signals_and_jacobians(x, v, u, gravity):
    """The rider's specific force and angular velocity ``y = [f; w]`` ``(N, 6)`` for poses
    ``x``, pose rates ``v`` and pose accelerations ``u`` ``(N, 6)``, and their exact
    Jacobians ``dy/dx``, ``dy/dv``, ``dy/du`` ``(N, 6, 6)``: ``f = R^T (a + g e_z)`` with
    ``R = Rz(psi) Ry(theta) Rx(phi)`` and ``w = E [psi', theta', phi']`` with ``E = R^T J_A``
    (:func:`stewart.cueing.vestibular.platform_signals`)."""
    x, v, u = (np.atleast_2d(np.asarray(a, dtype=float)) for a in (x, v, u))
    n = len(x)
    r = rotation_and_partials(x)
    cth, sth = np.cos(x[:, 4]), np.sin(x[:, 4])
    cph, sph = np.cos(x[:, 5]), np.sin(x[:, 5])
    b = u[:, :3].copy()
    b[:, 2] += gravity
    y = np.empty((n, 6))
    dy_dx = np.zeros((n, 6, 6))
    dy_dv = np.zeros((n, 6, 6))
    dy_du = np.zeros((n, 6, 6))
    rtb = np.einsum("knji,nj->kni", r, b)                  # R^T b and its partials
    y[:, :3] = rtb[0]
    dy_dx[:, :3, 3:] = np.transpose(rtb[1:], (1, 2, 0))
    dy_du[:, :3, :3] = np.transpose(r[0], (0, 2, 1))
    e = np.zeros((3, n, 3, 3))                             # E and its partials in theta, phi
    e[0, :, 0, 0], e[0, :, 0, 2] = -sth, 1.0
    e[0, :, 1, 0], e[0, :, 1, 1] = cth * sph, cph
    e[0, :, 2, 0], e[0, :, 2, 1] = cth * cph, -sph
    e[1, :, 0, 0], e[1, :, 1, 0], e[1, :, 2, 0] = -cth, -sth * sph, -sth * cph
    e[2, :, 1, 0], e[2, :, 1, 1] = cth * cph, -sph
    e[2, :, 2, 0], e[2, :, 2, 1] = -cth * sph, -cph
    er = np.einsum("knij,nj->kni", e, v[:, 3:])
    y[:, 3:] = er[0]
    dy_dx[:, 3:, 4] = er[1]
    dy_dx[:, 3:, 5] = er[2]
    dy_dv[:, 3:, 3:] = e[0]
    return y, dy_dx, dy_dv, dy_du


class AnchorQP(planner.CueingQP):
    """:class:`stewart.cueing.planner.CueingQP` with the step linearized, condensed and
    solved in numpy, as before it was compiled."""

    def __init__(self, platform, params, dt):
        super().__init__(platform, params, dt)
        n = self.n
        self.Q, self.R = self._state_weights()
        self._starts = np.concatenate([[0.0], np.cumsum(self.h)[:-1]])
        self._weight = self.h[:, None, None] * self.Q
        self._input_weight = np.repeat(self.h, 6) * np.tile(self.R, n)
        self._inputs = np.zeros((n, 6, 6 * n))
        for k in range(n):
            self._inputs[k, :, 6 * k: 6 * k + 6] = np.eye(6)
        self._unit = np.tile(np.eye(6), (n + 1, 1))
        self.last = None

    def _state_weights(self):
        """The state and input weights ``(ns, ns)`` and ``(6,)`` per second of horizon."""
        prm = self.params
        thresholds = np.array([vestibular.THRESHOLDS[c] for c in vestibular.CHANNELS])
        we = np.concatenate([prm.specific_force, prm.angular_velocity]) / thresholds ** 2
        box = np.asarray(prm.box)
        q = np.zeros((self.ns, self.ns))
        q[_NS:, _NS:] = self.vestibular.C.T @ np.diag(we) @ self.vestibular.C
        q[_P, _P] = np.diag(np.asarray(prm.position) / box ** 2)
        q[_V, _V] = np.diag(np.asarray(prm.velocity) / box ** 2)
        return q, np.asarray(prm.acceleration) / box ** 2

    def _linearization_point(self, x0, v0):
        """Predicted ``(x, v, u)`` at the start of each interval: the last plan shifted by one
        sample, or the present state held."""
        n = self.n
        if self.last is None:
            return np.tile(x0, (n, 1)), np.tile(v0, (n, 1)), np.zeros((n, 6))
        t_prev, x_prev, v_prev, u_prev = self.last
        # the plan at the intervals' starts one sample later: linear between its knots
        times = np.minimum(self._starts + self.dt, t_prev[-1])
        k = np.minimum(np.searchsorted(t_prev, times, side="right") - 1, n - 1)
        w = ((times - t_prev[k]) / (t_prev[k + 1] - t_prev[k]))[:, None]
        xs = x_prev[k] + w * (x_prev[k + 1] - x_prev[k])
        vs = v_prev[k] + w * (v_prev[k + 1] - v_prev[k])
        us = u_prev[k]
        xs[0], vs[0] = x0, v0
        return xs, vs, us

    def condensed(self, x0, v0, z0, vehicle):
        """The QP's data for pose ``x0``, rates ``v0``, vestibular error states ``z0`` and the
        vehicle's signals ``vehicle`` ``(N, 6)`` at the intervals' midpoints: ``(H, q, M, lo,
        hi, S, d)`` with the cost ``u^T H u / 2 + q^T u`` (constant dropped), the constraint
        rows ``lo <= M u <= hi`` (unscaled, without slacks) and the states ``s_1..s_N =
        S u + d``."""
        prm, plat, n, h, ns = self.params, self.platform, self.n, self.h, self.ns
        xs, vs, us = self._linearization_point(x0, v0)
        xm, vm = horizon.midpoint(xs, vs, us, h[:, None])
        y, yx, yv, yu = signals_and_jacobians(xm, vm, us, prm.gravity)
        half, eighth = (0.5 * h)[:, None, None], (0.125 * h * h)[:, None, None]
        y_p, y_v, y_u = yx, yx * half + yv, yx * eighth + yv * half + yu
        y0 = y - np.einsum("nij,nj->ni", y_p, xs - self.home) - np.einsum("nij,nj->ni", y_v, vs) \
            - np.einsum("nij,nj->ni", y_u, us)
        eye = np.eye(6)
        a = np.zeros((n, ns, ns))
        a[:, _P, _P] = a[:, _V, _V] = eye
        a[:, _P, _V] = h[:, None, None] * eye
        a[:, _NS:, _P] = self.bd @ y_p
        a[:, _NS:, _V] = self.bd @ y_v
        a[:, _NS:, _NS:] = self.ad
        b = np.zeros((n, ns, 6))
        b[:, _P] = (0.5 * h * h)[:, None, None] * eye
        b[:, _V] = h[:, None, None] * eye
        b[:, _NS:] = self.bd @ y_u
        c = np.zeros((n, ns))
        c[:, _NS:] = np.einsum("nij,nj->ni", self.bd, y0 - vehicle)
        s_mat = np.zeros((n + 1, ns, 6 * n))
        d = np.zeros((n + 1, ns))
        d[0] = np.concatenate([x0 - self.home, v0, z0])
        for k in range(n):
            s_mat[k + 1] = a[k] @ s_mat[k]
            s_mat[k + 1, :, 6 * k: 6 * k + 6] += b[k]
            d[k + 1] = a[k] @ d[k] + c[k]
        sq = (self._weight @ s_mat[1:]).reshape(-1, 6 * n)
        H = s_mat[1:].reshape(-1, 6 * n).T @ sq
        H[np.diag_indices(6 * n)] += self._input_weight
        q = d[1:].reshape(-1) @ sq
        # leg geometry at the next log sample (the first input held over dt) and at the
        # predicted states s_1..s_N, each affine in u about the linearization point: ``A u + c``
        dt = self.dt
        x_bar = np.vstack([x0 + dt * v0 + 0.5 * dt * dt * us[0], xs + h[:, None] * vs + (0.5 * h * h)[:, None] * us])
        v_bar = np.vstack([v0 + dt * us[0], vs + h[:, None] * us])
        sp, sv = np.empty((n + 1, 6, 6 * n)), np.empty((n + 1, 6, 6 * n))
        sp[0], sv[0] = 0.5 * dt * dt * self._inputs[0], dt * self._inputs[0]
        sp[1:], sv[1:] = s_mat[1:, _P], s_mat[1:, _V]
        dp = np.vstack([x0 - self.home + dt * v0, d[1:, _P]]) - (x_bar - self.home)    # from the point
        dv = np.vstack([v0, d[1:, _V]])
        lengths, rates = plat.leg_rates(np.repeat(x_bar, 6, axis=0), self._unit)
        lengths = lengths[::6]
        jl = np.transpose(rates.reshape(n + 1, 6, 6), (0, 2, 1))                   # dL/dx, column j: Ldot at e_j
        probes = np.concatenate([v_bar[:, None, :] + eye, v_bar[:, None, :] - eye], axis=1)
        quad = plat.leg_accelerations(np.repeat(x_bar, 12, axis=0), probes.reshape(-1, 6),
                                      np.zeros((12 * (n + 1), 6))).reshape(n + 1, 12, 6)
        hl = np.transpose(0.25 * (quad[:, :6] - quad[:, 6:]), (0, 2, 1))           # dLdot/dx along v
        cones, cone_grad = joint_cosines_and_gradients(x_bar, plat.params.base_points,
                                                                  plat.params.platform_points, self.neutral)
        mv = lambda m, x: np.einsum("nij,nj->ni", m, x)  # noqa: E731
        legs = (np.concatenate([jl @ sp, hl @ sp + jl @ sv, cone_grad @ sp], axis=1),
                np.concatenate([lengths + mv(jl, dp), mv(jl, dv) + mv(hl, dp), cones + mv(cone_grad, dp)], axis=1))
        deriv = plat.inverse_dynamics_derivatives(xs, vs, us)
        t_dx, t_dv = deriv.dtau_dx, deriv.dtau_dxd
        tau = t_dx @ s_mat[:-1, _P] + t_dv @ s_mat[:-1, _V] + deriv.dtau_dxdd @ self._inputs, \
            deriv.tau + mv(t_dx, d[:-1, _P] - (xs - self.home)) + mv(t_dv, d[:-1, _V] - vs) - mv(deriv.dtau_dxdd, us)
        box, speed, cone = np.asarray(prm.box), self.speed_limit, self.cone_cosines
        # roll and pitch rates between zero and the vehicle's (w_y, w_x: theta', phi'), widened by tilt_rate
        wv = vehicle[:, [4, 3]]
        band = np.minimum(wv, 0.0) - prm.tilt_rate, np.maximum(wv, 0.0) + prm.tilt_rate
        groups = {
            "actuators": (tau[0][0], tau[1][0], -prm.force, prm.force),
            "legs": (legs[0][0], legs[1][0], *self.next_limits),
            "next_tilt": (sv[0, 4:6], dv[0, 4:6], band[0][0], band[1][0]),
            "force": (tau[0], tau[1], -self.force_limit, self.force_limit),
            "stroke": (legs[0][1:, :6], legs[1][1:, :6], self.stroke[0], self.stroke[1]),
            "speed": (legs[0][1:, 6:12], legs[1][1:, 6:12], -speed, speed),
            "cones": (legs[0][1:, 12:], legs[1][1:, 12:], cone, np.inf),
            "tilt": (sv[1:, 4:6], dv[1:, 4:6], band[0], band[1]),
            "box": (s_mat[1:, _P], d[1:, _P], -box, box),
            "rest": (s_mat[-1:, _V], d[-1:, _V], 0.0, 0.0),
        }
        rows, lo, hi = np.empty((self.m, 6 * n)), np.empty(self.m), np.empty(self.m)
        for g in GROUPS:
            mat, const, low, high = groups[g]
            at = self.rows[g]
            rows[at] = mat.reshape(-1, 6 * n)
            lo[at] = (low - const).reshape(-1)
            hi[at] = (high - const).reshape(-1)
        return H, q, rows, lo, hi, s_mat[1:], d[1:]

    def next_values(self, x0, v0, u0):
        """The leg lengths, leg speeds and joint-angle cosines ``(24,)`` at the next log sample
        after ``u0`` held from pose ``x0`` and rates ``v0``, exact: the ``legs`` rows' values,
        within :attr:`next_limits` when the platform's limits hold there."""
        x1, v1 = x0 + self.dt * v0 + 0.5 * self.dt ** 2 * u0, v0 + self.dt * u0
        lengths, speeds = self.platform.leg_rates(x1, v1)
        units = self.platform.jacobian(x1)[:, :3]  # the legs' unit vectors (eq. 5's J_C)
        cones = np.concatenate([np.einsum("ia,ia->i", units, self.neutral),
                                np.einsum("ia,ab,ib->i", units, rotation(x1), self.neutral)])
        return np.concatenate([lengths, speeds, cones])

    def solve(self, x0, v0, z0, vehicle):
        """The plan from pose ``x0``, rates ``v0`` and vestibular error states ``z0`` for the
        vehicle's signals ``vehicle`` ``(N, 6)`` at the intervals' midpoints: ``(u (N, 6),
        x (N+1, 6), v (N+1, 6), info)`` with ``info`` the solver's (``exitflag``,
        ``iterations`` and ``solve_time`` [s] summed over the QPs solved), ``level`` (the first
        of :data:`LEVELS` with a plan) and ``tightened`` (the times the ``legs`` rows were
        tightened); ``u`` is None when no QP had a solution.

        Each level's plan is checked at the next sample with the exact kinematics
        (:meth:`next_values`); where a ``legs`` row's linearization let it pass its bound, the
        row's bound is moved in by the linearization's error there and the excess, and the plan
        solved again (at most :data:`TIGHTENINGS` times). The brake step minimizes the pose
        rates after one sample, in pose boxes, subject to the present forces alone."""
        n = self.n
        H, q, M, lo, hi, s_mat, d = self.condensed(x0, v0, z0, vehicle)
        scale = 1.0 / self.row_scale
        rows = M * scale[:, None]
        legs = self.rows["legs"]
        low, high = self.next_limits
        with np.errstate(invalid="ignore"):  # (a joint without a cone: no bound either side)
            constant = np.where(np.isfinite(low), low - lo[legs], high - hi[legs])  # the legs rows' A u + c
        iterations, solve_time, tightened = 0, 0.0, 0
        for level, sense in self.levels.items():
            upper = np.minimum(hi * scale - self._inset, _INFINITE)
            lower = np.maximum(lo * scale + self._inset, -_INFINITE)
            for attempt in range(TIGHTENINGS + 1):
                u, _, exitflag, info = daqp.solve(H, q, rows, upper, lower, sense, dual_start=self.multipliers,
                                                  **SOLVER_SETTINGS)
                iterations += info["iterations"]
                solve_time += info["solve_time"]
                if exitflag not in SOLVED:
                    break
                values = self.next_values(x0, v0, u[:6])
                above, below = np.maximum(values - high, 0.0), np.maximum(low - values, 0.0)
                if not (np.any(above > 0) or np.any(below > 0)) or attempt == TIGHTENINGS:
                    break  # (what the last attempt leaves, the exact check of the reference reports)
                # a row passed is bounded by its limit less the linearization's error there and the
                # excess (the error grows as the plan moves along the row)
                error = values - (M[legs] @ u + constant)
                upper[legs] = np.where(above > 0, np.minimum(upper[legs], (hi[legs] - error - above) * scale[legs]
                                                             - self._inset[legs]), upper[legs])
                lower[legs] = np.where(below > 0, np.maximum(lower[legs], (lo[legs] - error + below) * scale[legs]
                                                             + self._inset[legs]), lower[legs])
                tightened += 1
            if exitflag in SOLVED:
                break
            self.multipliers = None
        else:
            level = "brake"
            force = self.rows["actuators"]
            brake, _, exitflag, info = daqp.solve(self.dt ** 2 * self._brake_weight, self.dt * self._brake_weight @ v0,
                                                  rows[force, :6], upper[force], lower[force],
                                                  np.full(6, HARD, dtype=np.intc), **SOLVER_SETTINGS)
            iterations += info["iterations"]
            solve_time += info["solve_time"]
            u = np.zeros(6 * n)
            u[:6] = brake
        info.update(exitflag=exitflag, level=level, iterations=iterations, solve_time=solve_time, tightened=tightened)
        if exitflag not in SOLVED:
            return None, None, None, info
        states = np.einsum("kaj,j->ka", s_mat, u) + d
        x = np.vstack([x0, states[:, _P] + self.home])
        v = np.vstack([v0, states[:, _V]])
        # the next step linearizes about this plan (after a brake step: about the state held)
        self.last = None if level == "brake" else (np.concatenate([[0.0], np.cumsum(self.h)]), x, v, u.reshape(n, 6))
        if level != "brake":
            self.multipliers = info["lam"]
        return u.reshape(n, 6), x, v, info




def plan(log, platform, params) -> Plan:
    """:func:`stewart.cueing.planner.plan` with the anchor's step (BLAS on one thread)."""
    with threadpool_limits(1):
        return _plan(log, platform, params)


def _plan(log, platform, params):
    qp = AnchorQP(platform, params, log.dt)
    prm, h, dt = qp.params, qp.h, log.dt
    t = log.t
    y_log = np.column_stack([log.f, log.w])
    steps = len(t)
    x = np.empty((steps, 6))
    v = np.zeros((steps, 6))
    u = np.zeros((steps, 6))
    x[0] = qp.home
    vs = qp.vestibular
    z_vehicle = vs.steady_state(y_log[0])
    y_rest = signals_and_jacobians(qp.home, np.zeros(6), np.zeros(6), prm.gravity)[0][0]
    z_platform = vs.steady_state(y_rest)
    mid_offsets = np.concatenate([[0.0], np.cumsum(h)[:-1]]) + 0.5 * h
    step_time, solve_time, iterations, status, level = np.zeros(steps), np.zeros(steps), np.zeros(steps, int), [], []
    failures = tightened = 0
    remaining = None  # the last plan's inputs after the one applied
    for k in range(steps):
        start = time.perf_counter()
        vehicle = _vehicle_at(t[k] + mid_offsets, t, y_log, prm.preview, t[k])
        sol, _, _, info = qp.solve(x[k], v[k], z_platform - z_vehicle, vehicle)
        step_time[k] = time.perf_counter() - start
        solve_time[k] = info["solve_time"]
        iterations[k] = info["iterations"]
        status.append(int(info["exitflag"]))
        level.append(info["level"] if sol is not None else None)
        tightened += info["tightened"]
        if sol is None:
            failures += 1
            applied = remaining[0] if remaining is not None and len(remaining) else np.zeros(6)
            remaining = remaining[1:] if remaining is not None else None
        else:
            applied = sol[0]
            remaining = sol[1:]
        u[k] = applied
        if k + 1 == steps:  # the last sample's input: planned like the others, not applied
            break
        x[k + 1] = x[k] + dt * v[k] + 0.5 * dt * dt * applied
        v[k + 1] = v[k] + dt * applied
        xm, vm = horizon.midpoint(x[k], v[k], applied, dt)
        y_mid = signals_and_jacobians(xm, vm, applied, prm.gravity)[0][0]
        z_platform = qp.ad_dt @ z_platform + qp.bd_dt @ y_mid
        z_vehicle = qp.ad_dt @ z_vehicle + qp.bd_dt @ (0.5 * (y_log[k] + y_log[k + 1]))
    return Plan(x, v, u, step_time, solve_time, iterations, status, level, tightened, failures)
