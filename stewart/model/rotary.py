"""``stewart.RotaryPlatform``: the compiled model of a 6-RSS rotary-actuator rig (issue 40),
the facade of the rotary functions of the generated C (codegen/rotary.py; their table
:data:`stewart._generated_rotary.FUNCTIONS`)."""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from . import arguments
from .compiled import RotaryKernel
from .errors import ConvergenceError
from .platform import ForwardDynamicsDerivatives, InverseDynamicsDerivatives, Step, StepDerivatives
from .rotary_params import RotaryParams, rotary_params

__all__ = ["RotaryPlatform", "RotaryJointCosines", "CueingRows"]


class RotaryJointCosines(NamedTuple):
    """The rig's joints at a pose (:meth:`RotaryPlatform.joint_cosines`, codegen/rotary_joints.py):
    ``crank_angles`` (..., 6) [rad]; ``rod_crank`` (..., 6) the cosines of the rod-crank angles
    (``-u_i . n_i / d``: 1 where the rod folds back over its crank, -1 where it stretches straight
    out); ``crank_joint`` and ``platform_joint`` (..., 6) the cosines of the ball joints' angles
    from their neutral axes (the rod's direction at the reference pose, fixed in the crank and in
    {P}); ``platform_heights`` (..., 6) [m] the heights of the platform joints ``(P_i)_z`` in {B};
    ``pin_tilt_sines`` (..., 6) the sines of the rods' tilts out of the cranks' planes of motion
    (``n_i . a_i / d``: the misalignment of a rod end on a pin parallel to the motor axis)."""

    crank_angles: np.ndarray
    rod_crank: np.ndarray
    crank_joint: np.ndarray
    platform_joint: np.ndarray
    platform_heights: np.ndarray
    pin_tilt_sines: np.ndarray



class CueingRows(NamedTuple):
    """:meth:`RotaryPlatform.cueing_rows`: crank angles ``alpha``, ``JP = J_alpha T``, crank
    rates ``ad`` and ``dad_dx``, the reach ``reach = sin^2(delta)`` and ``dreach_dx``, the
    ``joints`` (..., 30): the rod-crank, crank-joint and platform-joint cosines, the platform
    joints' heights and the pins' tilt sines of :class:`RotaryJointCosines`, in that order, and
    ``djoints_dx`` (..., 30, 6)."""

    alpha: np.ndarray
    JP: np.ndarray
    ad: np.ndarray
    dad_dx: np.ndarray
    reach: np.ndarray
    dreach_dx: np.ndarray
    joints: np.ndarray
    djoints_dx: np.ndarray

#: Most Newton iterations :meth:`RotaryPlatform.forward_kinematics` allows.
MAX_ITERATIONS = 10_000


class RotaryPlatform:
    """The model of a rotary rig for one :class:`~stewart.RotaryParams`, evaluated by the
    generated C.

    Every method takes one state ``(6,)`` or a batch ``(N, 6)`` (a row broadcasts against a
    batch) and returns the matching shape, as :class:`stewart.Platform` does: a wrong shape
    or a value that is not a real number raises ``ValueError`` naming the argument; a state
    where the model is undefined (a crank that cannot reach the pose, ``theta = +-90 deg`` for
    the forward dynamics, a singular ``J_alpha``) raises :class:`stewart.SingularityError`
    naming the condition (and the crank) and the rows, or with ``return_mask=True`` gives NaN
    rows and returns ``(result, ok)``. Batches run with the GIL released.

    The pose ``x = [px, py, pz, psi, theta, phi]`` and its rates are the package's usual ones;
    crank angles in radians, torques in N m about the motor axes ``+a_i``.
    """

    def __init__(self, params: RotaryParams):
        self._params = rotary_params(params)
        self._kernel = RotaryKernel(self._params)
        self._call = self._kernel.call

    @classmethod
    def preset(cls, name: str) -> "RotaryPlatform":
        """The model of a built-in rotary rig (:func:`stewart.model.rotary_presets.presets`)."""
        return cls(RotaryParams.preset(name))

    @classmethod
    def load(cls, path) -> "RotaryPlatform":
        """The model of a rotary rig's TOML or JSON parameter file (``kind = "rotary"``)."""
        return cls(RotaryParams.load(path))

    @property
    def params(self) -> RotaryParams:
        """The parameter set (immutable)."""
        return self._params

    @property
    def kernel(self) -> RotaryKernel:
        """The compiled rotary model (:class:`stewart.model.compiled.RotaryKernel`) whose batch
        functions the methods call, for the compiled loops in C over it (the simulator's
        :class:`~stewart.model.compiled.RotaryLoop`, the envelope's
        :class:`~stewart.model.compiled.RotaryPeaks`, the MPC cueing step)."""
        return self._kernel

    @property
    def home(self) -> np.ndarray:
        """A level pose above the base's origin with the cranks near their zero angle: the
        height at which each rod reaches from its crank tip at ``alpha = 0`` to its platform
        joint, averaged over the legs (the pose itself for a symmetric rig); the default guess
        of :meth:`forward_kinematics`."""
        p = self._params
        gap = p.platform_points - (p.base_points + p.crank_length * p.crank_zero)
        height = np.sqrt(np.maximum(p.rod_length ** 2 - np.sum(gap[:, :2] ** 2, axis=1), 0.0)) - gap[:, 2]
        return np.array([0.0, 0.0, float(np.mean(height)), 0.0, 0.0, 0.0])

    def crank_angles(self, x, return_mask: bool = False):
        """The crank angles ``alpha`` (6,) in (-pi, pi], each in its leg's branch
        (``crank_branch``); a pose out of a crank's reach names the crank."""
        return self._call("crank_angles", (x,), return_mask)

    def jacobian(self, x, return_mask: bool = False):
        """``J_alpha`` (6, 6) in the twist: ``alpha_dot = J_alpha [v; omega]``, row i
        ``[j_i^T, (R p_i x j_i)^T]``, ``j_i = n_i / (n_i . t_i)`` (codegen/rotary.py), as
        :meth:`stewart.Platform.jacobian` is for the legs."""
        return self._call("jacobian", (x,), return_mask)

    def pose_jacobian(self, x, return_mask: bool = False):
        """``J_alpha T`` (6, 6) in the pose rates: ``alpha_dot = J_alpha T xd``."""
        return self._call("pose_jacobian", (x,), return_mask)

    def crank_rates(self, x, xd, return_mask: bool = False):
        """The crank rates ``alpha_dot = J_alpha T xd`` (rad/s)."""
        return self._call("crank_rates", (x, xd), return_mask)

    def mass_matrix(self, x, return_mask: bool = False):
        """``M = M_t T`` (6, 6) in the pose coordinates (not symmetric)."""
        return self._call("mass_matrix", (x,), return_mask)

    def twist_mass_matrix(self, x, return_mask: bool = False):
        """``M_t`` (6, 6), symmetric positive definite: the bodies' kinetic energy is
        ``t^T M_t t / 2`` for the twist ``t``."""
        return self._call("twist_mass_matrix", (x,), return_mask)

    def gravity_vector(self, x, return_mask: bool = False):
        """``G(x)`` in the twist's equations (the torques at rest are ``J_alpha^-T G``)."""
        return self._call("gravity_vector", (x,), return_mask)

    def inverse_dynamics(self, x, xd, xdd, return_mask: bool = False):
        """The motor torques ``tau`` (N m about ``+a_i``) that move the rig along ``x, xd, xdd``:
        ``J_alpha^T tau = M_t T xdd + V xd + G``."""
        return self._call("inverse_dynamics", (x, xd, xdd), return_mask)

    def inverse_dynamics_derivatives(self, x, xd, xdd, return_mask: bool = False):
        """The motor torques and their exact Jacobians, an
        :class:`~stewart.InverseDynamicsDerivatives` ``(tau, dtau_dx, dtau_dxd, dtau_dxdd)``
        (row = output, column = input): ``dtau/dq = J_alpha^-T dR/dq`` with
        ``R = M_t T xdd + V xd + G - J_alpha^T tau`` at fixed ``tau``, by forward mode on the
        derivation (codegen/rotary.py)."""
        result = self._call("inverse_dynamics_derivatives", (x, xd, xdd), return_mask)
        if return_mask:
            return tuple.__new__(InverseDynamicsDerivatives, result[0]), result[1]
        return tuple.__new__(InverseDynamicsDerivatives, result)

    def cueing_rows(self, x, xd, reference=None, return_mask: bool = False):
        """What MPC cueing holds of the rig (:mod:`stewart.cueing.planner`), a
        :class:`CueingRows` ``(alpha, JP, ad, dad_dx, reach, dreach_dx, joints, djoints_dx)``: the
        crank angles, the pose Jacobian ``J_alpha T`` (``d alpha/dx = d alpha_dot/dxd``), the
        crank rates and their exact partials in ``x``, the reach ``s_i = sin^2(delta_i)``
        (codegen/rotary.py ``crank_geometry``: 0 at the edge of crank i's reach, where ``J_alpha``
        is singular) and ``ds/dx``, and the joints of :meth:`joint_cosines` (centred at the pose
        ``reference``, default :attr:`home`) with their gradient, by forward mode on the derivation
        (codegen/rotary_joints.py ``rotary_cueing_rows_kernel``)."""
        result = self._call("cueing_rows", (x, xd, self._reference(reference)), return_mask)
        alpha, rates, reach, grads, joints, djoints = result[0] if return_mask else result
        grads = np.moveaxis(grads, -3, 0)
        rows = CueingRows(alpha, grads[0], rates, grads[1], reach, grads[2], joints, djoints)
        return (rows, result[1]) if return_mask else rows

    def forward_dynamics(self, x, xd, torque, return_mask: bool = False):
        """The pose accelerations ``xdd`` under the motor torques ``torque``."""
        return self._call("forward_dynamics", (x, xd, torque), return_mask)

    def joint_cosines(self, x, reference=None, return_mask: bool = False):
        """The crank angles, the cosines of the rod-crank angles and of the ball joints' angles,
        and the platform joints' heights at poses ``x``, a :class:`RotaryJointCosines`, all from
        the generated C (codegen/rotary_joints.py). The joints' neutral axes are the rods'
        directions at the pose ``reference`` (one pose, default :attr:`home`: the rig as it is
        mounted), fixed in each crank for the joint at its tip and in {P} for the joint on the
        platform, as the linear model's joints are centred at home."""
        result = self._call("joint_cosines", (x, self._reference(reference)), return_mask)
        if return_mask:
            return tuple.__new__(RotaryJointCosines, result[0]), result[1]
        return tuple.__new__(RotaryJointCosines, result)

    def _reference(self, reference) -> np.ndarray:
        """The pose the joints are centred at: ``reference`` (one pose), default :attr:`home`."""
        reference = self.home if reference is None else arguments.states("reference", reference)
        if reference.ndim != 1:
            raise ValueError(f"reference: expected one pose (6,), got shape {reference.shape}")
        return reference

    def forward_dynamics_derivatives(self, x, xd, torque, return_mask: bool = False):
        """The pose accelerations and their exact Jacobians, a
        :class:`~stewart.ForwardDynamicsDerivatives` ``(xdd, dxdd_dx, dxdd_dxd, dxdd_dtau)``
        (row = output, column = input; ``dxdd_dtau`` by the torque): with
        ``R = M_t T xdd + V xd + G - J_alpha^T torque`` (the residual of
        :meth:`inverse_dynamics_derivatives`, at the accelerations ``xdd`` of
        :meth:`forward_dynamics` and fixed torque), ``dxdd/dq = -T^-1 M_t^-1 dR/dq`` for ``q = x,
        xd`` and ``dxdd/dtorque = T^-1 M_t^-1 J_alpha^T``, ``T = blockdiag(E, J_A)`` (eq. 18)."""
        result = self._call("forward_dynamics_derivatives", (x, xd, torque), return_mask)
        if return_mask:
            return tuple.__new__(ForwardDynamicsDerivatives, result[0]), result[1]
        return tuple.__new__(ForwardDynamicsDerivatives, result)

    def rk4_step(self, x, xd, torque, dt, *, jacobians: bool = False, return_mask: bool = False):
        """One classic RK4 step of ``[x; xdot]`` under motor torques ``torque`` held over ``dt``
        seconds (zero-order hold; a positive finite number), as :meth:`stewart.Platform.rk4_step`:
        a :class:`~stewart.Step` ``(x, xd)``, or with ``jacobians`` a
        :class:`~stewart.StepDerivatives` ``(x, xd, A, B)``, ``A = d(x+, xd+)/d(x, xd)``
        ``(..., 12, 12)`` and ``B = d(x+, xd+)/d torque`` ``(..., 12, 6)``, exact (the chain rule
        through the stages with :meth:`forward_dynamics_derivatives`)."""
        dt = arguments.time_step("dt", dt)
        kind, name = (StepDerivatives, "rk4_step_derivatives") if jacobians else (Step, "rk4_step")
        result = self._call(name, (x, xd, torque), return_mask, dt)
        if return_mask:
            return tuple.__new__(kind, result[0]), result[1]
        return tuple.__new__(kind, result)

    def forward_kinematics(self, alpha, guess=None, *, tol: float = 1e-12, max_iter: int = 50) -> np.ndarray:
        """The pose(s) whose crank angles are ``alpha`` ((6,) or (N, 6), radians; e.g. the
        encoders'), by Newton on ``crank_angles(x) = alpha`` with the generated ``J_alpha T``,
        each residual wrapped to (-pi, pi], a step halved while it does not reduce the residual
        (up to 30 times). Starts from ``guess`` (one pose or one per row; default :attr:`home`).
        :class:`~stewart.ConvergenceError` naming the rows that do not reach
        ``max|alpha(x) - alpha| <= tol``."""
        target = arguments.states("alpha", alpha)
        tol = arguments.real("tol", tol)
        if not tol > 0.0:
            raise ValueError(f"tol: must be positive, got {tol}")
        max_iter = arguments.count("max_iter", max_iter, MAX_ITERATIONS)
        rows = np.atleast_2d(target)
        start = self.home if guess is None else arguments.states("guess", guess)
        if start.ndim == 2 and start.shape != rows.shape:
            raise ValueError(f"guess: expected one pose or one per row of alpha {target.shape}, got {start.shape}")
        x = np.broadcast_to(start, rows.shape).copy()

        def residual(poses, wanted):
            angles, ok = self._call("crank_angles", (poses,), True)
            out = np.angle(np.exp(1j * (angles - wanted)))
            out[~ok] = np.inf
            return out, np.max(np.abs(out), axis=1)

        res, norm = residual(x, rows)
        active = ~(norm <= tol)
        for _ in range(max_iter):
            if not active.any():
                break
            idx = np.flatnonzero(active)
            jac, ok = self._call("pose_jacobian", (x[idx],), True)
            ok &= np.isfinite(res[idx]).all(axis=1)
            step = np.zeros((idx.size, 6))
            step[ok] = np.linalg.solve(jac[ok], res[idx][ok][..., None])[..., 0]
            scale, trial, trial_res = np.ones(idx.size), x[idx].copy(), res[idx].copy()
            trial_norm = np.full(idx.size, np.inf)
            for _ in range(30):
                todo = ok & ~(trial_norm < norm[idx])  # the rows without a step that reduces the residual yet
                if not todo.any():
                    break
                trial[todo] = x[idx][todo] - scale[todo, None] * step[todo]
                trial_res[todo], trial_norm[todo] = residual(trial[todo], rows[idx][todo])
                scale[todo] /= 2.0
            better = ok & (trial_norm < norm[idx])
            x[idx[better]], res[idx[better]], norm[idx[better]] = trial[better], trial_res[better], trial_norm[better]
            active[idx[~better]] = False
            active &= ~(norm <= tol)
        failed = np.flatnonzero(~(norm <= tol))
        if failed.size:
            raise ConvergenceError(f"forward_kinematics: no pose with these crank angles found from the guess at "
                                   f"row(s) {failed.tolist()[:10]} (residual {np.max(norm[failed]):.3g} rad)", failed.tolist())
        return x if target.ndim == 2 else x[0]
