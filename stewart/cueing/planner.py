"""Model-predictive motion cueing: at every log sample, the platform's pose accelerations over
a receding horizon that minimize the rider's perceived-motion error within the platform's
limits, one dense QP solved exactly by DAQP's dual active-set method (Arnström, Bemporad &
Axehill 2022), warm-started from the last step's active set.

The prediction (:mod:`stewart.cueing.horizon`) carries per interval ``k`` the state
``s_k = [p_k, v_k, z_k]``: the pose from home, its rates and the difference of the platform's
and the vehicle's vestibular states, whose output ``C z`` is the perceived error. The input
is the pose acceleration ``u_k``; the states are affine in the inputs, so the QP is
condensed to ``u_0..u_{N-1}``. It minimizes ``sum_k h_k (|W_e C z_k|^2 + |W_p p_k|^2 +
|W_v v_k|^2 + |W_u u_{k-1}|^2)`` (:class:`~stewart.cueing.settings.MPCParams` weights, each
error scaled by its perception threshold or the pose box) subject to

* the leg stroke ``L(x_k)``, linearized with ``dL/dx = J_C T`` (eqs. 5, 8);
* the leg velocity ``Ldot(x_k, v_k)``, linearized with ``dLdot/dv = dL/dx`` and ``dLdot/dx``,
  the legs' second derivatives contracted with the predicted rates, from
  :meth:`~stewart.Platform.leg_accelerations` by polarization (exact: a quadratic form);
* the actuator force ``tau(x_k, v_k, u_k)`` of the inverse dynamics, linearized with
  :meth:`~stewart.Platform.inverse_dynamics_derivatives` (exact in ``u``: the dynamics are
  affine in the accelerations, so the row at the present sample, whose state is known, is
  exact);
* the joints' cones (:class:`~stewart.PlatformParams` ``universal_joint_max_angle``,
  ``spherical_joint_max_angle``), the cosine of each joint angle linearized with its exact
  gradient (:meth:`~stewart.Platform.joint_cosines`);
* the tilt rate: roll and pitch rates between zero and the vehicle's, widened by
  ``tilt_rate`` (no rotation the vehicle does not have, beyond ``tilt_rate``);
* the pose box ``|p_k| <= box``;
* the platform at rest at the horizon's end, ``v_N = 0`` (so every plan can stop).

The rows come in two kinds (:data:`GROUPS`). The samples a step writes, the present one and
the next, are held to the platform's own limits: the forces at the present sample
(``actuators``, exact) within ``force``, and the leg lengths, leg speeds and joint cones at
the next sample (``legs``; the first input held for one sample ``dt``, linearized about the
last plan's, an error of second order in ``dt^2/2`` times the change of input) within the
stroke, ``leg_velocity`` and the cones; the roll and pitch rates there (``next_tilt``, exact)
within the tilt band. Over the horizon (at the intervals' ends, the forces at their starts)
the same limits less their margins (``(1 - margin)`` of force and leg speed,
``stroke_margin``, :data:`CONE_MARGIN`), the tilt band, the box and the rest.

The platform's own limits at the written samples are hard at every level; what yields when
not everything can hold is ordered (:data:`HARD_GROUPS`, tried in turn): first the box and
the rest, then the tilt rate; the margins over the horizon are always soft. If no level has
a plan, the step brakes: the input that brings the pose rates closest to zero after one
sample within the present sample's forces (:data:`LEVELS` ``brake``, counted in the result).
Each plan is checked at the next sample with the exact kinematics (:meth:`CueingQP.next_values`)
and, where the linearization let a ``legs`` row pass its limit, solved again with that row
tightened (:data:`TIGHTENINGS`). So every sample written holds the stroke, leg speed,
actuator forces and cones whenever any input can, and the tilt rate whenever the vehicle's
rotation leaves the platform time to follow; :func:`stewart.cueing.mpc` checks the written
reference again with the exact kinematics and dynamics.

Soft rows are DAQP's soft constraints, which keep the slacks out of the problem's size: a
row's squared violation ``v_i^2`` costs ``SOFT_WEIGHT / 2 v_i^2 / n_i``, ``n_i = a_i H^-1
a_i^T`` for the row ``a_i`` and the cost's Hessian ``H`` (the violation in the cost's metric),
so that a plan that alone would overstep one row by ``delta`` oversteps it by ``delta / (1 +
SOFT_WEIGHT)`` whatever the row's units: a margin is given up only where the hard rows leave
no other plan, and is paid for far above any cue. The linearization point is the last plan,
shifted by one sample. The intervals are equal; the first input is applied for one log
sample, the state advanced exactly, and the QP solved again (a short first interval would
let the plan buy velocity cheaply for the long ones); at the last sample the plan's first
input is written without being applied.

The step's linearization, prediction, cost and rows run in C, next to the model
(:class:`~stewart.model.compiled.CueingStep`, with the model's generated functions: the rider's
signals, the leg rates and accelerations, the joints' cosines, the inverse dynamics' derivatives,
each with its exact derivatives); DAQP solves the QP.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import daqp
import numpy as np
from threadpoolctl import threadpool_limits

from ..model.compiled import CUEING_GROUPS, CueingStep
from ..model.params import PlatformParams
from ..model.platform import Platform, as_platform
from ..model.reachability import neutral_axes
from ..model.rotary_reachability import base_plane
from . import horizon, rotary, vestibular
from .settings import MPCParams

__all__ = ["CueingQP", "Plan", "plan"]

#: Weight of a soft constraint's squared violation in the cost's metric (see the module's
#: docstring): a QP always has a solution, and a violation is paid for far above any cue.
SOFT_WEIGHT = 1e6
#: DAQP's primal feasibility tolerance, in the rows' units (their limits): the rows at the
#: platform's own limits (``actuators``, ``legs``) are bounded twice this far inside them.
PRIMAL_TOLERANCE = 1e-6
#: DAQP's settings: its soft constraints' penalty ``1 / (2 rho_soft) s^2`` is :data:`SOFT_WEIGHT`'s,
#: :data:`PRIMAL_TOLERANCE`, and an iteration cap far above the few iterations a warm-started
#: step takes.
SOLVER_SETTINGS = {"rho_soft": 1.0 / SOFT_WEIGHT, "primal_tol": PRIMAL_TOLERANCE, "iter_limit": 2000}
#: DAQP's exit flags of a solution: optimal, and optimal with soft constraints violated.
SOLVED = (1, 2)
#: DAQP's constraint kinds (:attr:`CueingQP.levels`): an inequality, a soft one.
HARD, SOFT = 0, 8
#: The vestibular states' start in the state ``[p, v, z]``.
_NS = 12
#: The constraint groups in the order of the QP's rows: the machine's limits at the samples
#: the step writes (``actuators``: the forces at the present sample; ``legs``: the leg lengths,
#: leg speeds and joint cones at the next; ``next_tilt``: the roll and pitch rates there), then
#: over the horizon the same limits less their margins, the tilt rate, the pose box and the
#: rest at the horizon's end.
GROUPS = CUEING_GROUPS
#: The groups held hard at each level of :meth:`CueingQP.solve` (the others soft), tried in
#: turn until one has a plan: ``plan``; ``box`` when the box and the rest must yield to the
#: machine's limits; ``tilt`` when the tilt rate must yield too (the vehicle's rotation
#: changed faster than the platform can follow).
HARD_GROUPS = {"plan": ("actuators", "legs", "next_tilt", "box", "rest"),
               "box": ("actuators", "legs", "next_tilt"),
               "tilt": ("actuators", "legs")}
#: The levels of :meth:`CueingQP.solve`: :data:`HARD_GROUPS`, then ``brake``, one step that
#: slows the pose rates within the present sample's actuator forces when no plan holds the
#: machine's limits at the next sample.
LEVELS = (*HARD_GROUPS, "brake")
#: The times a step's plan is solved again with the ``legs`` rows the exact kinematics find
#: passed at the next sample bounded by their limits less their linearization's error there
#: and the excess.
TIGHTENINGS = 3
#: Kept from each joint's cone half-angle [rad] over the horizon (the QP holds it to first order).
CONE_MARGIN = 0.005
#: On a rotary rig: kept from each end of ``crank_angle_limits`` [rad] over the horizon.
ANGLE_MARGIN = 0.02
#: On a rotary rig: kept above the base plane and ``base_clearance`` [m] over the horizon (the
#: rod-crank angle limits and the ball-joint cones keep :data:`CONE_MARGIN`).
CLEARANCE_MARGIN = 0.001


@dataclass
class Plan:
    """A receding-horizon run: the applied pose accelerations ``u`` ``(T, 6)``, the pose
    ``x`` and rates ``v`` ``(T, 6)`` at the log's samples, per step (one at each sample) the
    wall time of the whole step (linearize, condense, solve) ``step_time`` and the QP
    solver's own ``solve_time`` [s], its ``iterations``, exit flag ``status`` (:data:`SOLVED`,
    or DAQP's failure) and the :data:`LEVELS` name ``level`` of the plan applied (None
    without one); ``tightened`` counts the tightenings of :meth:`CueingQP.solve`, ``failures``
    the steps without a solution."""

    x: np.ndarray
    v: np.ndarray
    u: np.ndarray
    step_time: np.ndarray
    solve_time: np.ndarray
    iterations: np.ndarray
    status: list
    level: list
    tightened: int
    failures: int


class CueingQP:
    """The QP of one MPC step for ``platform`` and ``params`` (:class:`MPCParams`, filled by
    :meth:`~MPCParams.for_platform`) at log samples ``dt`` apart, condensed to the inputs
    ``u_0..u_{N-1}`` (the states are affine in them), its rows scaled to units of their limits.
    :meth:`solve` takes the present state and the vehicle's signals over the horizon."""

    def __init__(self, platform, params: MPCParams, dt: float):
        rig = rotary.rotary_rig(platform)
        self.platform = as_platform(platform) if rig is None else rig
        self.rotary = rotary.is_rotary(self.platform)
        self.params = params = params.for_platform_of(self.platform)
        self.dt = float(dt)
        self.h = params.intervals(self.dt)
        self.home = rotary.home(self.platform)
        self.vestibular = horizon.VestibularStates()
        self.ns = _NS + self.vestibular.n
        self.n = n = params.steps
        discrete = {h: self.vestibular.discrete(h) for h in np.unique(self.h)}
        self.ad = np.stack([discrete[h][0] for h in self.h])
        self.bd = np.stack([discrete[h][1] for h in self.h])
        self.ad_dt, self.bd_dt = self.vestibular.discrete(self.dt)
        self.multipliers = None  # the last solution's, whose signs give the next step's active set
        if self.rotary:
            self._rotary_rows(params)
            return
        # the rider's signals with the MPC's gravity
        rider = self.platform.params.replace(gravity=params.gravity)
        self.rider = self.platform if rider == self.platform.params else Platform(rider)
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
        # the platform's own stroke, leg speed and cones: the bounds of next_values
        cone_limits = [np.cos(limit) if limit is not None else -np.inf
                       for limit in (pp.universal_joint_max_angle, pp.spherical_joint_max_angle) for _ in range(6)]
        self.next_limits = (np.concatenate([np.full(6, lo), np.full(6, -params.leg_velocity), cone_limits]),
                            np.concatenate([np.full(6, hi), np.full(6, params.leg_velocity), np.full(12, np.inf)]))
        sizes = {"actuators": 6, "legs": 24, "next_tilt": 2, "force": 6 * n, "stroke": 6 * n, "speed": 6 * n,
                 "cones": 12 * n, "tilt": 2 * n, "box": 6 * n, "rest": 6}
        scales = {"actuators": np.full(6, params.force),
                  "legs": np.concatenate([np.full(6, hi - lo), np.full(6, params.leg_velocity), np.ones(12)]),
                  "next_tilt": np.full(2, params.tilt_rate), "force": np.full(6 * n, params.force),
                  "stroke": np.full(6 * n, hi - lo), "speed": np.full(6 * n, params.leg_velocity),
                  "cones": np.ones(12 * n), "tilt": np.full(2 * n, params.tilt_rate), "box": np.tile(box, n),
                  "rest": np.ones(6)}
        edges = self._finish(sizes, scales)
        self.step = self._compiled_step(edges, cone_limits)

    def _finish(self, sizes, scales):
        """The rows' slices, count, scales, insets and the levels' senses from the groups' sizes
        and scales; returns the groups' first rows."""
        edges = np.cumsum([0] + [sizes[g] for g in GROUPS])
        self.rows = {g: slice(edges[i], edges[i + 1]) for i, g in enumerate(GROUPS)}
        self.m = int(edges[-1])
        self.row_scale = np.concatenate([scales[g] for g in GROUPS])
        self._inset = np.zeros(self.m)
        for g in ("actuators", "legs"):
            self._inset[self.rows[g]] = 2.0 * PRIMAL_TOLERANCE
        self.levels = {}
        for level, hard in HARD_GROUPS.items():
            self.levels[level] = np.full(self.m, SOFT, dtype=np.intc)
            for g in hard:
                self.levels[level][self.rows[g]] = HARD
        # the brake step's weight on the pose rates after one sample: per axis, in pose boxes
        self._brake_weight = np.diag(1.0 / np.asarray(self.params.box) ** 2)
        return edges

    def _rotary_rows(self, prm):
        """A rotary rig's rows (stewart/_cueing_rotary.pxi): ``actuators`` and ``force`` the
        motor torques within ``min(force, motor_torque_limit)`` (less ``margin`` over the
        horizon); at the next sample (``legs``) and over the horizon the crank angles within
        ``crank_angle_limits`` (:data:`ANGLE_MARGIN` in from them over the horizon, ``stroke``),
        the crank rates within ``min(leg_velocity, motor_speed_limit)`` (less ``margin``,
        ``speed``), and (``cones`` over the horizon) the reaches above
        :data:`~stewart.cueing.rotary.REACH_MIN` (:data:`~stewart.cueing.rotary.REACH_MARGIN`)
        and the joints (:meth:`_joint_bounds`)."""
        n, rig = self.n, self.platform
        # the rider's signals depend on the pose and gravity alone: a linear platform's kernel serves
        self.rider = Platform(PlatformParams.preset("motion_simulator").replace(gravity=prm.gravity))
        torque, speed = rotary.motor_limits(rig)
        self.torque = np.minimum(torque, prm.force)
        self.speed = np.minimum(speed, prm.leg_velocity)
        lo, hi = rig.params.crank_angle_limits or (-np.pi, np.pi)
        self.angle_limits = (lo, hi)
        self.stroke = (lo + ANGLE_MARGIN, hi - ANGLE_MARGIN)
        self.force_limit = (1.0 - prm.margin) * self.torque
        self.speed_limit = (1.0 - prm.margin) * self.speed
        joints_low, joints_high = self._joint_bounds(0.0, 0.0)
        margin_low, margin_high = self._joint_bounds(CONE_MARGIN, CLEARANCE_MARGIN)
        self.cone_cosines = np.concatenate([np.full(6, rotary.REACH_MARGIN), margin_low, np.full(6, np.inf),
                                            margin_high])
        self.neutral = np.zeros((6, 3))
        self.next_limits = (np.concatenate([np.full(6, lo), -self.speed, np.full(6, rotary.REACH_MIN), joints_low]),
                            np.concatenate([np.full(6, hi), self.speed, np.full(6, np.inf), joints_high]))
        box = np.asarray(prm.box)
        joints_scale = np.concatenate([np.ones(18), np.full(6, rig.params.crank_length), np.ones(6)])
        sizes = {"actuators": 6, "legs": 48, "next_tilt": 2, "force": 6 * n, "stroke": 6 * n, "speed": 6 * n,
                 "cones": 36 * n, "tilt": 2 * n, "box": 6 * n, "rest": 6}
        scales = {"actuators": self.torque,
                  "legs": np.concatenate([np.full(6, hi - lo), self.speed, np.ones(6), joints_scale]),
                  "next_tilt": np.full(2, prm.tilt_rate), "force": np.tile(self.torque, n),
                  "stroke": np.full(6 * n, hi - lo), "speed": np.tile(self.speed, n),
                  "cones": np.tile(np.concatenate([np.ones(6), joints_scale]), n),
                  "tilt": np.full(2 * n, prm.tilt_rate), "box": np.tile(box, n), "rest": np.ones(6)}
        edges = self._finish(sizes, scales)
        motor = np.concatenate([self.torque, self.force_limit, self.speed_limit])
        self.step = self._compiled_step(edges, None, motor)

    def _joint_bounds(self, angle_margin, height_margin):
        """The bounds ``(30,)`` each, low and high, of a rotary rig's joints (the generated
        :meth:`~stewart.RotaryPlatform.cueing_rows` ``joints``, centred at home as
        :func:`~stewart.cueing.rotary.check_poses` centres them): the rod-crank cosines within
        ``rod_crank_angle_limits``, the crank and platform joints' cosines above the cosines of
        their cones, the sines of the rods' tilts out of the cranks' planes within
        ``+-sin(crank_pin_max_tilt)``, each limit ``angle_margin`` [rad] in; the platform joints'
        heights ``height_margin`` [m] above the base plane plus ``base_clearance`` (none: the
        plane)."""
        p = self.platform.params
        fold = (-np.inf, np.inf)
        if p.rod_crank_angle_limits is not None:
            least, most = p.rod_crank_angle_limits
            fold = (np.cos(most - angle_margin), np.cos(least + angle_margin))
        cones = [np.cos(limit - angle_margin) if limit is not None else -np.inf
                 for limit in (p.crank_joint_max_angle, p.platform_joint_max_angle)]
        floor = base_plane(p) + (p.base_clearance or 0.0) + height_margin
        tilt = np.inf if p.crank_pin_max_tilt is None else np.sin(p.crank_pin_max_tilt - angle_margin)
        low = np.concatenate([np.full(6, fold[0]), np.full(6, cones[0]), np.full(6, cones[1]), np.full(6, floor),
                              np.full(6, -tilt)])
        high = np.concatenate([np.full(6, fold[1]), np.full(18, np.inf), np.full(6, tilt)])
        return low, high

    def _weights(self):
        """The cost's weights per second of horizon ``(18,)``: on the pose and its rates (per
        pose box), on the perceived channels (per perception threshold), and on the inputs
        ``(6,)``."""
        prm = self.params
        thresholds = np.array([vestibular.THRESHOLDS[c] for c in vestibular.CHANNELS])
        box = np.asarray(prm.box)
        states = np.concatenate([np.asarray(prm.position) / box ** 2, np.asarray(prm.velocity) / box ** 2,
                                 np.concatenate([prm.specific_force, prm.angular_velocity]) / thresholds ** 2])
        return states, np.asarray(prm.acceleration) / box ** 2

    def _compiled_step(self, edges, cone_limits, motor=None):
        """The :class:`~stewart.model.compiled.CueingStep` of this QP."""
        n, vs, prm = self.n, self.vestibular, self.params
        channel = np.argmax(vs.B != 0, axis=1)          # the one input of each section
        sections = np.arange(vs.n)
        states, inputs = self._weights()
        knots = np.concatenate([[0.0], np.cumsum(self.h)])
        # the last plan at the intervals' starts one sample later: its knot and the weight of the next
        starts = np.minimum(knots[:-1] + self.dt, knots[-1])
        k = np.minimum(np.searchsorted(knots, starts, side="right") - 1, n - 1)
        shift = np.column_stack([k, (starts - knots[k]) / (knots[k + 1] - knots[k])])
        limits = (prm.force, np.min(self.force_limit), self.stroke[0], self.stroke[1], np.min(self.speed_limit),
                  prm.tilt_rate)
        return CueingStep(self.platform.kernel, self.rider.kernel, self.h, self.dt, self.home, self.neutral,
                          np.diagonal(self.ad, axis1=1, axis2=2), self.bd[:, sections, channel], channel,
                          vs.C[channel, sections], states, np.repeat(self.h, 6) * np.tile(inputs, n), shift, edges,
                          self.row_scale, self._inset, limits, self.cone_cosines, *self.next_limits, prm.box,
                          np.diag(self.ad_dt), self.bd_dt[sections, channel], motor)

    def condensed(self, x0, v0, z0, vehicle):
        """The QP's data for pose ``x0``, rates ``v0``, vestibular error states ``z0`` and the
        vehicle's signals ``vehicle`` ``(N, 6)`` at the intervals' midpoints, linearized about the
        last plan: ``(H, q, M, lo, hi, S, d)`` with the cost ``u^T H u / 2 + q^T u`` (constant
        dropped), the constraint rows ``lo <= M u <= hi`` (unscaled, without slacks) and the
        states ``s_1..s_N = S u + d``, built in C (:class:`~stewart.model.compiled.CueingStep`);
        copies, which the next step leaves alone."""
        step = self.step
        step.condense(x0, v0, z0, vehicle)
        return (step.H.copy(), step.q.copy(), step.M.copy(), step.lo.copy(), step.hi.copy(), step.S[1:].copy(),
                step.d[1:].copy())

    def next_values(self, x0, v0, u0):
        """The leg lengths, leg speeds and joint-angle cosines ``(24,)`` (on a rotary rig the
        crank angles, crank rates, reaches and joints ``(48,)``) at the next log sample after
        ``u0`` held from pose ``x0`` and rates ``v0``, exact: the ``legs`` rows' values, within
        :attr:`next_limits` when the platform's limits hold there."""
        return self.step.next_values(x0, v0, u0)

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
        n, step = self.n, self.step
        step.condense(x0, v0, z0, vehicle)  # the QP, built in C into the step's own arrays
        H, q, rows, M, lo, hi = step.H, step.q, step.A, step.M, step.lo, step.hi
        legs = self.rows["legs"]
        low, high = self.next_limits
        iterations, solve_time, tightened = 0, 0.0, 0
        for level, sense in self.levels.items():
            upper, lower = step.upper, step.lower
            for attempt in range(TIGHTENINGS + 1):
                u, _, exitflag, info = daqp.solve(H, q, rows, upper, lower, sense, dual_start=self.multipliers,
                                                  **SOLVER_SETTINGS)
                iterations += info["iterations"]
                solve_time += info["solve_time"]
                if exitflag not in SOLVED:
                    break
                values = step.next_values(x0, v0, u[:6])
                above, below = np.maximum(values - high, 0.0), np.maximum(low - values, 0.0)
                if not (np.any(above > 0) or np.any(below > 0)) or attempt == TIGHTENINGS:
                    break  # (what the last attempt leaves, the exact check of the reference reports)
                # a row passed is bounded by its limit less the linearization's error there and the
                # excess (the error grows as the plan moves along the row)
                error = values - (M[legs] @ u + step.legs_constant)
                scale, inset = 1.0 / self.row_scale[legs], self._inset[legs]
                upper, lower = upper.copy(), lower.copy()
                upper[legs] = np.where(above > 0, np.minimum(upper[legs], (hi[legs] - error - above) * scale - inset),
                                       upper[legs])
                lower[legs] = np.where(below > 0, np.maximum(lower[legs], (lo[legs] - error + below) * scale + inset),
                                       lower[legs])
                tightened += 1
            if exitflag in SOLVED:
                break
            self.multipliers = None
        else:
            level = "brake"
            force = self.rows["actuators"]
            brake, _, exitflag, info = daqp.solve(self.dt ** 2 * self._brake_weight, self.dt * self._brake_weight @ v0,
                                                  rows[force, :6], step.upper[force], step.lower[force],
                                                  np.full(6, HARD, dtype=np.intc), **SOLVER_SETTINGS)
            iterations += info["iterations"]
            solve_time += info["solve_time"]
            u = np.zeros(6 * n)
            u[:6] = brake
        info.update(exitflag=exitflag, level=level, iterations=iterations, solve_time=solve_time, tightened=tightened)
        if exitflag not in SOLVED:
            return None, None, None, info
        x, v = step.states(u)
        # the next step linearizes about this plan (after a brake step: about the state held)
        if level == "brake":
            step.forget()
        else:
            step.keep(u.reshape(n, 6), x, v)
            self.multipliers = info["lam"]
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
    y_rest = qp.rider.rider_signals(qp.home, np.zeros(6), np.zeros(6)).y
    z_platform = vs.steady_state(y_rest)
    mid_offsets = np.concatenate([[0.0], np.cumsum(h)[:-1]]) + 0.5 * h
    step_time, solve_time, iterations, status, level = np.zeros(steps), np.zeros(steps), np.zeros(steps, int), [], []
    failures = tightened = 0
    remaining = None  # the last plan's inputs after the one applied
    iterator = range(steps)
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
        qp.step.advance(x[k], v[k], applied, y_log[k], y_log[k + 1], z_platform, z_vehicle)
    return Plan(x, v, u, step_time, solve_time, iterations, status, level, tightened, failures)
