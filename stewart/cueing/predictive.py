"""Model-predictive motion cueing: at every log sample, the platform's pose accelerations over
a receding horizon that minimize the rider's perceived-motion error within the platform's
limits, one dense QP solved exactly by DAQP's dual active-set method (Arnström, Bemporad &
Axehill 2022), warm-started from the last step's active set.

The prediction (:mod:`stewart.cueing.prediction`) carries per interval ``k`` the state
``s_k = [p_k, v_k, z_k]``: the pose from home, its rates and the difference of the platform's
and the vehicle's vestibular states, whose output ``C z`` is the perceived error. The input
is the pose acceleration ``u_k``; the states are affine in the inputs, so the QP is
condensed to ``u_0..u_{N-1}``. It minimizes ``sum_k h_k (|W_e C z_k|^2 + |W_p p_k|^2 +
|W_v v_k|^2 + |W_u u_{k-1}|^2)`` (:class:`~stewart.cueing.settings.MPCParams` weights, each
error scaled by its perception threshold or the pose box) subject to

* the pose box ``|p_k| <= box``;
* the leg stroke ``L(x_k)``, linearized with ``dL/dx = J_C T`` (eqs. 5, 8);
* the leg velocity ``Ldot(x_k, v_k)`` within ``(1 - margin) leg_velocity``, linearized with
  ``dLdot/dv = dL/dx`` and ``dLdot/dx``, the legs' second derivatives contracted with the
  predicted rates, from :meth:`~stewart.Platform.leg_accelerations` by polarization (exact:
  a quadratic form);
* the actuator force ``tau(x_k, v_k, u_k)`` of the inverse dynamics within ``(1 - margin)
  force``, linearized with :meth:`~stewart.Platform.inverse_dynamics_derivatives` (exact in
  ``u``: the dynamics are affine in the accelerations);
* the tilt rate: roll and pitch rates differ from the vehicle's by at most ``tilt_rate``;
* the joints' cones (:class:`~stewart.PlatformParams` ``universal_joint_max_angle``,
  ``spherical_joint_max_angle``, less :data:`CONE_MARGIN`), the cosine of each joint angle
  linearized with its exact gradient (:func:`~stewart.cueing.prediction.joint_cosines_and_gradients`);
* the platform at rest at the horizon's end, ``v_N = 0`` (so every plan can stop).

All but the box and the rest are soft (DAQP's soft constraints, which keep the slacks out of
the problem's size): a row's squared violation ``v_i^2`` costs ``SOFT_WEIGHT / 2 v_i^2 / n_i``,
``n_i = a_i H^-1 a_i^T`` for the row ``a_i`` and the cost's Hessian ``H`` (the violation in the
cost's metric), so that a plan that alone would overstep one row by ``delta`` oversteps it by
``delta / (1 + SOFT_WEIGHT)`` whatever the row's units. A QP always has a solution and a
violation (reported by
:func:`stewart.cueing.mpc` from the exact kinematics and dynamics) is paid for far above any
cue. The linearization point is the last plan, shifted by one sample. The intervals are
equal; the first input is applied for one log sample, the state advanced exactly, and the
QP solved again (a short first interval would let the plan buy velocity cheaply for the
long ones).
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import daqp
import numpy as np
from threadpoolctl import threadpool_limits

from ..model.platform import as_platform
from ..model.reachability import neutral_axes
from . import prediction, vestibular
from .settings import MPCParams

__all__ = ["CueingQP", "Plan", "plan"]

#: Weight of a soft constraint's squared violation in the cost's metric (see the module's
#: docstring): a QP always has a solution, and a violation is paid for far above any cue.
SOFT_WEIGHT = 1e6
#: DAQP's settings: its soft constraints' penalty ``1 / (2 rho_soft) s^2`` is :data:`SOFT_WEIGHT`'s,
#: and an iteration cap far above the few iterations a warm-started step takes.
SOLVER_SETTINGS = {"rho_soft": 1.0 / SOFT_WEIGHT, "iter_limit": 2000}
#: DAQP's exit flags of a solution: optimal, and optimal with soft constraints violated.
SOLVED = (1, 2)
#: DAQP's constraint kinds (:attr:`CueingQP.sense`): an inequality, a soft one, an equality
#: (active and immutable).
HARD, SOFT, EQUALITY = 0, 8, 5
#: DAQP's infinite bound.
_INFINITE = 1e30

_P, _V, _NS = slice(0, 6), slice(6, 12), 12  # the state's pose and rate, the vestibular states' start
#: The constraint groups in the order of the QP's rows.
GROUPS = ("box", "tilt", "stroke", "speed", "force", "cones", "rest")
#: Kept from each joint's cone half-angle [rad] (the QP holds it to first order).
CONE_MARGIN = 0.005


@dataclass
class Plan:
    """A receding-horizon run: the applied pose accelerations ``u`` ``(T, 6)``, the pose
    ``x`` and rates ``v`` ``(T, 6)`` at the log's samples, per step the wall time of the whole
    step (linearize, condense, solve) ``step_time`` and the QP solver's own ``solve_time`` [s],
    its ``iterations`` and exit flag ``status`` (:data:`SOLVED`, or DAQP's failure);
    ``failures`` counts steps without a solution."""

    x: np.ndarray
    v: np.ndarray
    u: np.ndarray
    step_time: np.ndarray
    solve_time: np.ndarray
    iterations: np.ndarray
    status: list
    failures: int


class CueingQP:
    """The QP of one MPC step for ``platform`` and ``params`` (:class:`MPCParams`, filled by
    :meth:`~MPCParams.for_platform`) at log samples ``dt`` apart, condensed to the inputs
    ``u_0..u_{N-1}`` (the states are affine in them), its rows scaled to units of their limits.
    :meth:`solve` takes the present state and the vehicle's signals over the horizon."""

    def __init__(self, platform, params: MPCParams, dt: float):
        self.platform = as_platform(platform)
        self.params = params = params.for_platform_of(self.platform)
        self.dt = float(dt)
        self.h = params.intervals(self.dt)
        self.home = self.platform.home_pose
        self.vestibular = prediction.VestibularStates()
        self.ns = _NS + self.vestibular.n
        self.n = n = params.steps
        discrete = {h: self.vestibular.discrete(h) for h in np.unique(self.h)}
        self.ad = np.stack([discrete[h][0] for h in self.h])
        self.bd = np.stack([discrete[h][1] for h in self.h])
        self.ad_dt, self.bd_dt = self.vestibular.discrete(self.dt)
        lo, hi = self.platform.params.leg_length_limits
        self.stroke = (lo + params.stroke_margin, hi - params.stroke_margin)
        self.force_limit = (1.0 - params.margin) * params.force
        self.speed_limit = (1.0 - params.margin) * params.leg_velocity
        pp = self.platform.params
        # the joints' cones as a lower bound on the cosine of each joint angle (none: -inf)
        self.cone_cosines = np.array([np.cos(limit - CONE_MARGIN) if limit is not None else -np.inf
                                      for limit in (pp.universal_joint_max_angle, pp.spherical_joint_max_angle)
                                      for _ in range(6)])
        self.neutral = neutral_axes(self.platform)
        box = np.asarray(params.box)
        sizes = {"box": 6 * n, "tilt": 2 * n, "stroke": 6 * n, "speed": 6 * n, "force": 6 * n, "cones": 12 * n,
                 "rest": 6}
        scales = {"box": np.tile(box, n), "tilt": np.full(2 * n, params.tilt_rate),
                  "stroke": np.full(6 * n, hi - lo), "speed": np.full(6 * n, params.leg_velocity),
                  "force": np.full(6 * n, params.force), "cones": np.ones(12 * n), "rest": np.ones(6)}
        edges = np.cumsum([0] + [sizes[g] for g in GROUPS])
        self.rows = {g: slice(edges[i], edges[i + 1]) for i, g in enumerate(GROUPS)}
        self.m = int(edges[-1])
        self.row_scale = np.concatenate([scales[g] for g in GROUPS])
        # every row but the pose box (linear in the inputs: always met exactly) and v_N = 0 is soft
        self.sense = np.full(self.m, SOFT, dtype=np.intc)
        self.sense[self.rows["box"]] = HARD
        self.sense[self.rows["rest"]] = EQUALITY
        self.Q, self.R = self._weights()
        self._starts = np.concatenate([[0.0], np.cumsum(self.h)[:-1]])
        self._weight = self.h[:, None, None] * self.Q
        self._input_weight = np.repeat(self.h, 6) * np.tile(self.R, n)
        self._inputs = np.zeros((n, 6, 6 * n))
        for k in range(n):
            self._inputs[k, :, 6 * k: 6 * k + 6] = np.eye(6)
        self._unit = np.tile(np.eye(6), (n, 1))
        self.multipliers = None  # the last solution's, whose signs give the next step's active set
        self.last = None

    def _weights(self):
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
        xm, vm = prediction.midpoint(xs, vs, us, h[:, None])
        y, yx, yv, yu = prediction.signals_and_jacobians(xm, vm, us, prm.gravity)
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
        # leg geometry at the predicted states s_1..s_N, forces at s_0..s_{N-1}
        x_next = xs + h[:, None] * vs + (0.5 * h * h)[:, None] * us
        v_next = vs + h[:, None] * us
        lengths, rates = plat.leg_rates(np.repeat(x_next, 6, axis=0), self._unit)
        lengths = lengths[::6]
        jl = np.transpose(rates.reshape(n, 6, 6), (0, 2, 1))                       # dL/dx, column j: Ldot at e_j
        probes = np.concatenate([v_next[:, None, :] + eye, v_next[:, None, :] - eye], axis=1)
        quad = plat.leg_accelerations(np.repeat(x_next, 12, axis=0), probes.reshape(-1, 6),
                                      np.zeros((12 * n, 6))).reshape(n, 12, 6)
        hl = np.transpose(0.25 * (quad[:, :6] - quad[:, 6:]), (0, 2, 1))           # dLdot/dx along v
        deriv = plat.inverse_dynamics_derivatives(xs, vs, us)
        cones, cone_grad = prediction.joint_cosines_and_gradients(x_next, plat.params.base_points,
                                                                  plat.params.platform_points, self.neutral)
        sp, sv, dp, dv = s_mat[1:, _P], s_mat[1:, _V], d[1:, _P], d[1:, _V]
        inputs = self._inputs
        p_bar, box = x_next - self.home, np.asarray(prm.box)
        wv = vehicle[:, [4, 3]]                                    # the vehicle's w_y, w_x: theta', phi'
        t_dx, t_dv = deriv.dtau_dx, deriv.dtau_dxd
        tau_shift = deriv.tau - np.einsum("nij,nj->ni", t_dx, xs - self.home) \
            - np.einsum("nij,nj->ni", t_dv, vs) - np.einsum("nij,nj->ni", deriv.dtau_dxdd, us)
        groups = {
            "box": (sp, dp, -box, box),
            "tilt": (sv[:, 4:6], dv[:, 4:6], wv - prm.tilt_rate, wv + prm.tilt_rate),
            "stroke": (jl @ sp, np.einsum("nij,nj->ni", jl, dp),
                       self.stroke[0] - lengths + np.einsum("nij,nj->ni", jl, p_bar),
                       self.stroke[1] - lengths + np.einsum("nij,nj->ni", jl, p_bar)),
            "speed": (hl @ sp + jl @ sv, np.einsum("nij,nj->ni", hl, dp) + np.einsum("nij,nj->ni", jl, dv),
                      -self.speed_limit + np.einsum("nij,nj->ni", hl, p_bar),
                      self.speed_limit + np.einsum("nij,nj->ni", hl, p_bar)),
            "force": (t_dx @ s_mat[:-1, _P] + t_dv @ s_mat[:-1, _V] + deriv.dtau_dxdd @ inputs,
                      np.einsum("nij,nj->ni", t_dx, d[:-1, _P]) + np.einsum("nij,nj->ni", t_dv, d[:-1, _V])
                      + tau_shift, -self.force_limit, self.force_limit),
            "cones": (cone_grad @ sp, np.einsum("nij,nj->ni", cone_grad, dp),
                      self.cone_cosines - cones + np.einsum("nij,nj->ni", cone_grad, p_bar), np.inf),
            "rest": (sv[-1:], dv[-1:], 0.0, 0.0),
        }
        rows, lo, hi = np.empty((self.m, 6 * n)), np.empty(self.m), np.empty(self.m)
        for g in GROUPS:
            mat, const, low, high = groups[g]
            at = self.rows[g]
            rows[at] = mat.reshape(-1, 6 * n)
            lo[at] = (low - const).reshape(-1)
            hi[at] = (high - const).reshape(-1)
        return H, q, rows, lo, hi, s_mat[1:], d[1:]

    def solve(self, x0, v0, z0, vehicle):
        """The plan from pose ``x0``, rates ``v0`` and vestibular error states ``z0`` for the
        vehicle's signals ``vehicle`` ``(N, 6)`` at the intervals' midpoints: ``(u (N, 6),
        x (N+1, 6), v (N+1, 6), info)`` with ``info`` the solver's (``exitflag``,
        ``iterations``, ``solve_time`` [s]); ``u`` is None when it found no solution."""
        n = self.n
        H, q, M, lo, hi, s_mat, d = self.condensed(x0, v0, z0, vehicle)
        scale = 1.0 / self.row_scale
        u, _, exitflag, info = daqp.solve(H, q, M * scale[:, None], np.minimum(hi * scale, _INFINITE),
                                          np.maximum(lo * scale, -_INFINITE), self.sense,
                                          dual_start=self.multipliers, **SOLVER_SETTINGS)
        info["exitflag"] = exitflag
        if exitflag not in SOLVED:
            self.multipliers = None
            return None, None, None, info
        self.multipliers = info["lam"]
        states = np.einsum("kaj,j->ka", s_mat, u) + d
        x = np.vstack([x0, states[:, _P] + self.home])
        v = np.vstack([v0, states[:, _V]])
        self.last = (np.concatenate([[0.0], np.cumsum(self.h)]), x, v, u.reshape(n, 6))
        return u.reshape(n, 6), x, v, info


def _vehicle_at(times, t, y, preview: bool, now: float):
    """The vehicle's signals ``y`` ``(T, 6)`` at ``times``: interpolated from the log with
    ``preview``, else its present value (at ``now``) held."""
    if not preview:
        return np.tile([np.interp(now, t, y[:, j]) for j in range(6)], (len(times), 1))
    return np.column_stack([np.interp(times, t, y[:, j]) for j in range(6)])


def plan(log, platform, params: MPCParams, progress: bool = False) -> Plan:
    """Run the receding horizon over ``log`` (a :class:`~stewart.cueing.log.VehicleLog`) on
    ``platform`` from rest at home: at every sample one QP (:class:`CueingQP`), its first
    input applied over one sample. The linear algebra runs on one thread (BLAS threads
    only contend on matrices this small)."""
    with threadpool_limits(1):
        return _plan(log, platform, params, progress)


def _plan(log, platform, params, progress):
    qp = CueingQP(platform, params, log.dt)
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
    y_rest = prediction.signals_and_jacobians(qp.home, np.zeros(6), np.zeros(6), prm.gravity)[0][0]
    z_platform = vs.steady_state(y_rest)
    mid_offsets = np.concatenate([[0.0], np.cumsum(h)[:-1]]) + 0.5 * h
    step_time, solve_time, iterations, status = np.zeros(steps - 1), np.zeros(steps - 1), np.zeros(steps - 1, int), []
    failures = 0
    fallback = None
    iterator = range(steps - 1)
    if progress:
        from tqdm import tqdm

        iterator = tqdm(iterator, desc="MPC cueing", unit="step", leave=False)
    for k in iterator:
        start = time.perf_counter()
        vehicle = _vehicle_at(t[k] + mid_offsets, t, y_log, prm.preview, t[k])
        sol, _, _, info = qp.solve(x[k], v[k], z_platform - z_vehicle, vehicle)
        step_time[k] = time.perf_counter() - start
        solve_time[k] = info["solve_time"]
        iterations[k] = info["iterations"]
        status.append(int(info["exitflag"]))
        if sol is None:
            failures += 1
            applied = fallback[0] if fallback is not None and len(fallback) else np.zeros(6)
            fallback = fallback[1:] if fallback is not None else None
        else:
            applied = sol[0]
            fallback = sol[1:]
        u[k] = applied
        x[k + 1] = x[k] + dt * v[k] + 0.5 * dt * dt * applied
        v[k + 1] = v[k] + dt * applied
        xm, vm = prediction.midpoint(x[k], v[k], applied, dt)
        y_mid = prediction.signals_and_jacobians(xm, vm, applied, prm.gravity)[0][0]
        z_platform = qp.ad_dt @ z_platform + qp.bd_dt @ y_mid
        z_vehicle = qp.ad_dt @ z_vehicle + qp.bd_dt @ (0.5 * (y_log[k] + y_log[k + 1]))
    u[-1] = u[-2]
    return Plan(x, v, u, step_time, solve_time, iterations, status, failures)
