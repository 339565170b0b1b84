"""``stewart.Platform``: the compiled model of one platform, the object most users hold."""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from . import arguments, kinematics, stiffness as _stiffness
from .._generated import FUNCTIONS
from .compiled import Kernel
from .errors import WrongTypeError
from .params import platform_params
from .params import PlatformParams
from .results import JointReactions

__all__ = ["Platform", "AllTerms", "InverseDynamicsDerivatives", "ForwardDynamicsDerivatives",
           "StaticForceDerivatives", "Step", "StepDerivatives", "LegResidualJacobians", "RotationPartials",
           "EulerRateJacobianPartials", "LegUnitVectors", "ModalStiffness", "JointCosines",
           "RiderSignals", "as_platform"]


def _result_type(function, doc):
    """The named tuple of the results of the C model's function ``function``: its name and
    fields from the generated table (:data:`stewart._generated.FUNCTIONS`), its docstring ``doc``."""
    spec = FUNCTIONS[function]
    cls = NamedTuple(spec.result_type, [(name, np.ndarray) for name, *_ in spec.results])
    cls.__doc__, cls.__module__ = doc, __name__
    return cls


def _same_fields(cls, function):
    """``cls``, a named tuple declared elsewhere, if its name and fields are those of the results of
    the C model's function ``function`` (:data:`stewart._generated.FUNCTIONS`); else ImportError."""
    spec = FUNCTIONS[function]
    if (cls.__name__, cls._fields) != (spec.result_type, tuple(name for name, *_ in spec.results)):
        raise ImportError(f"{cls.__name__}{cls._fields} does not match the results of {function}: {spec.results}")
    return cls


AllTerms = _result_type("all_terms", """The terms of the equation of motion ``M xddot + V xdot + G = J_C^T tau`` at one
    state or a batch (:meth:`Platform.all_terms`).""")

InverseDynamicsDerivatives = _result_type("inverse_dynamics_derivatives", """Actuator forces and their Jacobians
    (:meth:`Platform.inverse_dynamics_derivatives`): row = output, column = input,
    ``dtau_dx[..., i, j] = d tau_i / d x_j``.""")

ForwardDynamicsDerivatives = _result_type("forward_dynamics_derivatives", """Accelerations and their Jacobians
    (:meth:`Platform.forward_dynamics_derivatives`): row = output, column = input,
    ``dxdd_dx[..., i, j] = d xddot_i / d x_j``.""")

StaticForceDerivatives = _result_type("static_force_derivatives", """The static forces and their Jacobian
    (:meth:`Platform.static_force_derivatives`): row = output, column = input,
    ``dtau_dx[..., i, j] = d tau_i / d x_j``.""")

Step = _result_type("rk4_step", """The state after one RK4 step (:meth:`Platform.rk4_step`).""")

StepDerivatives = _result_type("rk4_step_derivatives", """The state after one RK4 step and its Jacobians
    (:meth:`Platform.rk4_step` with ``jacobians=True``): ``A = d(x+, xd+)/d(x, xd)`` (12 x 12),
    ``B = d(x+, xd+)/d tau`` (12 x 6), row = output, column = input.""")

LegResidualJacobians = _result_type("leg_residual_jacobians", """The exact partials of the calibration residuals
    (:meth:`Platform.leg_residual_jacobians`): ``dr_dtheta[..., i, :]`` those of leg i's residual in
    its own geometric parameters ``(b_i, p_i, delta_i)``, ``[u_i, -R^T u_i, 1]`` (the other 35 of
    the 42 are zero), and ``dr_dx`` (``(..., 6, 6)``, row = leg, column = pose coordinate).""")

RotationPartials = _result_type("rotation_partials", """The rotation and its partials along the Euler angles
    (:meth:`Platform.rotation` with ``partials=True``), each of shape ``(..., 3, 3)``.""")

EulerRateJacobianPartials = _result_type("euler_rate_jacobian_partials", """``J_A`` and its partials along the Euler
    angles (:meth:`Platform.euler_rate_jacobian` with ``partials=True``), each of shape ``(..., 3, 3)``.""")

LegUnitVectors = _result_type("leg_unit_vector_gradients", """The unit leg vectors, ``(..., 6, 3)``, and their pose
    gradients ``du_dx[..., i, a, j] = d u_i,a / d x_j``, ``(..., 6, 3, 6)`` (:meth:`Platform.leg_unit_vectors` with
    ``gradients=True``).""")

ModalStiffness = _result_type("modal_stiffness", """The twist-space stiffness ``Kt`` (not symmetrized), ``J_C`` and
    the twist-space mass matrix ``Mt`` of the platform on preloaded leg springs (:meth:`Platform.modal_stiffness`),
    each of shape ``(..., 6, 6)``.""")

JointCosines = _result_type("joint_cosines", """The cosines of the joint angles and their gradient in the pose
    (:meth:`Platform.joint_cosines`): ``cosines`` ``(..., 12)`` (universal joints, then spherical
    joints), ``dcosines_dx[..., i, j] = d cosines_i / d x_j``.""")

RiderSignals = _result_type("rider_signals", """What a rider at {P}'s origin senses and its Jacobians
    (:meth:`Platform.rider_signals`): ``y = [f; w]`` ``(..., 6)``, row = output, column = input,
    ``dy_dx[..., i, j] = d y_i / d x_j``.""")

# The joint reactions' type (shared with the Newton-Euler oracle) has the fields of the C's results.
_same_fields(JointReactions, "joint_reactions")


def _named(kind, result, return_mask):
    """``result`` of a kernel method (a tuple, or ``(tuple, ok)``) as the named tuple ``kind``
    (built by ``tuple.__new__``, which skips the named tuple's own ``__new__``)."""
    return (tuple.__new__(kind, result[0]), result[1]) if return_mask else tuple.__new__(kind, result)


class Platform:
    """The generalized-momentum model of Lopes & Pires (2011) for one parameter set,
    evaluated by the generated C kernel.

    Every method takes one state ``(6,)`` or a batch ``(N, 6)`` (a single row broadcasts
    against a batch) and returns the matching shape. Inputs of any integer or floating
    dtype, byte order, alignment and memory layout are converted to C-contiguous native
    float64 (copied only when needed). A wrong shape, a value that is not a real number
    (complex, bool, ``timedelta64``, ``datetime64``, strings, objects) or a NaN raises
    ``ValueError`` naming the argument. A state where the model is undefined
    raises :class:`stewart.SingularityError` naming the condition and the rows; with
    ``return_mask=True`` such rows come back as NaN instead and the method returns
    ``(result, ok)`` with a boolean mask (a bool for one state), for workspace sweeps.

    ``threads`` > 1 splits batches over that many threads: an int from 1 to 256
    (``ValueError`` otherwise).
    """

    def __init__(self, params: PlatformParams, *, threads: int = 1):
        self._params = params = platform_params(params)
        self._home = kinematics.home_pose(params)
        self._home.flags.writeable = False
        kinematics.check_universal_joint_axes(params, self._home)
        self._kernel = Kernel(params, threads)
        # The kernel's call, bound once: the methods below call it without looking it up.
        self._call = self._kernel.call
        # the joints' neutral axes, the legs' unit vectors at home (joint_cosines' default)
        self._neutral = self.jacobian(self._home)[:, :3].copy()

    @classmethod
    def preset(cls, name: str, **options) -> "Platform":
        """The compiled model of a built-in parameter set (see :func:`stewart.presets`)."""
        return cls(PlatformParams.preset(name), **options)

    @classmethod
    def load(cls, path, **options) -> "Platform":
        """The compiled model of a TOML or JSON parameter file."""
        return cls(PlatformParams.load(path), **options)

    #: The same as :meth:`load`.
    from_file = load

    def with_payload(self, mass, com, inertia) -> "Platform":
        """The compiled model of this platform carrying a rigid payload
        (:meth:`PlatformParams.with_payload`), with the same options."""
        return type(self)(self._params.with_payload(mass, com, inertia), threads=self.threads)

    @property
    def params(self) -> PlatformParams:
        """The parameter set (immutable)."""
        return self._params

    @property
    def home_pose(self) -> np.ndarray:
        """The home pose of :func:`stewart.home_pose` (read-only)."""
        return self._home

    @property
    def threads(self) -> int:
        return self._kernel.threads

    @property
    def kernel(self) -> Kernel:
        """The compiled model (:class:`stewart.model.compiled.Kernel`) whose batch functions the
        methods call, for the compiled reductions that take one (:class:`stewart.model.compiled.Peaks`
        of the motion envelopes)."""
        return self._kernel

    def __repr__(self) -> str:
        return f"Platform({self._params!r}, threads={self.threads})"

    def leg_lengths(self, x, *, return_mask=False):
        """Leg lengths ``|l_i|``, ``l_i = p + R p_i - b_i`` (eq. 26)."""
        return self._call("leg_lengths", (x,), return_mask)

    def encoder_readings(self, x):
        """The encoder readings at ``x``: the leg lengths less ``params.leg_length_offsets``
        (:func:`stewart.model.kinematics.encoder_readings`)."""
        return kinematics.encoder_readings(self._params, x)

    def jacobian(self, x, *, return_mask=False):
        """``J_C`` (eq. 5): ``Ldot = J_C [v; omega]``, shape ``(..., 6, 6)``."""
        return self._call("jacobian", (x,), return_mask)

    def leg_rates(self, x, xd, *, return_mask=False):
        """Leg lengths and rates ``(L, Ldot)`` in one pass: ``L_i = |l_i|`` (eq. 26) and
        ``Ldot = J_C T xdot`` (eqs. 5, 8, 18), each of shape ``(..., 6)``."""
        return self._call("leg_rates", (x, xd), return_mask)

    def leg_accelerations(self, x, xd, xdd, *, return_mask=False):
        """Leg extension accelerations ``Lddot``, the second time derivative of ``L_i = |l_i|``
        (eq. 26): the rate of ``Ldot_i = u_i . (v + omega x r_i)`` (eqs. 4, 5) at the pose
        accelerations ``xddot``, shape ``(..., 6)``; equal to ``u_i . a_i + (|v_i|^2 - Ldot_i^2)
        / L_i`` with ``v_i``, ``a_i`` the velocity and acceleration of the spherical joint P_i
        (:func:`stewart.model.kinematics.leg_accelerations`)."""
        return self._call("leg_accelerations", (x, xd, xdd), return_mask)

    def rotation(self, x, *, partials=False, return_mask=False):
        """The orientation ``R = Rz(psi) Ry(theta) Rx(phi)`` of {P} in {B} (eq. 3), shape ``(..., 3,
        3)``; with ``partials``, a :class:`RotationPartials` ``(R, dR_dpsi, dR_dtheta, dR_dphi)``.
        It does not depend on the platform's parameters."""
        if partials:
            return _named(RotationPartials, self._call("rotation_partials", (x,), return_mask), return_mask)
        return self._call("rotation", (x,), return_mask)

    def euler_rate_jacobian(self, x, *, partials=False, return_mask=False):
        """``J_A`` (eq. 8): the angular velocity ``omega = J_A [psi', theta', phi']`` in {B},
        shape ``(..., 3, 3)``; with ``partials``, an :class:`EulerRateJacobianPartials` ``(JA,
        dJA_dpsi, dJA_dtheta, dJA_dphi)``."""
        if partials:
            return _named(EulerRateJacobianPartials, self._call("euler_rate_jacobian_partials", (x,), return_mask),
                          return_mask)
        return self._call("euler_rate_jacobian", (x,), return_mask)

    def inverse_euler_rate_jacobian(self, x, *, return_mask=False):
        """``J_A^-1`` (eq. 8 inverted): the Euler rates of an angular velocity in {B}, shape
        ``(..., 3, 3)``; singular where ``cos(theta)`` is too small (``euler_singular``)."""
        return self._call("inverse_euler_rate_jacobian", (x,), return_mask)

    def leg_vectors(self, x, *, return_mask=False):
        """The leg vectors ``l_i = p + R p_i - b_i`` (eq. 26), shape ``(..., 6, 3)``; a zero-length
        leg is no error here."""
        return self._call("leg_vectors", (x,), return_mask)

    def leg_unit_vectors(self, x, *, gradients=False, return_mask=False):
        """The unit leg vectors ``u_i = l_i / |l_i|`` (eqs. 25, 26), shape ``(..., 6, 3)``; with
        ``gradients``, a :class:`LegUnitVectors` ``(u, du_dx)`` with their exact pose gradients
        ``du_dx[..., i, a, j] = d u_i,a / d x_j``, shape ``(..., 6, 3, 6)``."""
        if gradients:
            return _named(LegUnitVectors, self._call("leg_unit_vector_gradients", (x,), return_mask), return_mask)
        return self._call("leg_unit_vectors", (x,), return_mask)

    def modal_stiffness(self, x, k, *, return_mask=False):
        """The twist-space stiffness of the platform on leg springs ``k`` [N/m] (``(6,)`` one per
        leg, or ``(N, 6)`` one set per state) preloaded to hold it at ``x``, a
        :class:`ModalStiffness` ``(Kt, JC, Mt)``: ``K_t = J_C^T (diag(k) J_C + dtau_s/dx T^-1)``
        with ``T^-1 = blockdiag(I, J_A^-1)`` (eqs. 5, 8, 18; not symmetrized), ``J_C`` and the
        twist-space mass matrix ``M_t``, whose generalized eigenproblem ``K_t phi = w^2 M_t phi``
        gives the modes (:meth:`modes`, :mod:`stewart.model.stiffness`)."""
        return _named(ModalStiffness, self._call("modal_stiffness", (x, k), return_mask), return_mask)

    def mass_matrix(self, x, *, return_mask=False):
        """``M = sum_b J_b^T I_b J_b T`` (eqs. 22, 40, 52, 62, 70); multiplies ``xddot``."""
        return self._call("mass_matrix", (x,), return_mask)

    def twist_mass_matrix(self, x, *, return_mask=False):
        """The twist-space mass matrix ``M_t = sum_b J_b^T I_b J_b`` (eqs. 19, 39, 51, 61,
        69), symmetric positive definite, with ``M = M_t T`` (eq. 18); shape ``(..., 6, 6)``."""
        return self._call("twist_mass_matrix", (x,), return_mask)

    def coriolis_matrix(self, x, xd, *, return_mask=False):
        """``V = sum_b J_b^T d/dt(I_b J_b T)`` (eqs. 23, 41, 53, 63, 71)."""
        return self._call("coriolis_matrix", (x, xd), return_mask)

    def coriolis_vector(self, x, xd, *, return_mask=False):
        """``V xdot``, computed without forming ``V``."""
        return self._call("coriolis_vector", (x, xd), return_mask)

    def gravity_vector(self, x, *, return_mask=False):
        """``G`` (eqs. 72-76), computed as ``sum_b m_b g J_b^T e_z``."""
        return self._call("gravity_vector", (x,), return_mask)

    def all_terms(self, x, xd, *, return_mask=False):
        """The mass matrix ``M = M_t T``, ``V xdot``, ``G`` and ``J_C`` (eqs. 5, 19, 39, 51,
        61, 69, 72-76) in one call, as an :class:`AllTerms` (like Pinocchio's
        ``computeAllTerms``); each is the method of its name, bit for bit."""
        return _named(AllTerms, self._call("all_terms", (x, xd), return_mask), return_mask)

    def inverse_dynamics(self, x, xd, xdd, *, return_mask=False):
        """Actuator forces along the legs [N]: ``tau = J_C^-T (M xddot + V xdot + G)``."""
        return self._call("inverse_dynamics", (x, xd, xdd), return_mask)

    def forward_dynamics(self, x, xd, tau, *, return_mask=False):
        """Euler accelerations ``xddot = M^-1 (J_C^T tau - V xdot - G)``."""
        return self._call("forward_dynamics", (x, xd, tau), return_mask)

    def regressor(self, x, xd, xdd, *, return_mask=False):
        """The regressor ``Y`` of the actuator forces, linear in the inertial parameters:
        ``Y @ params.inertial_vector() == actuator_forces(x, xd, xdd)``, shape ``(..., 6, 32)``,
        columns in the order of :meth:`PlatformParams.inertial_names`. ``J_C^T Y`` holds the
        partials of ``M xddot + V xdot + G`` (eqs. 19, 39, 51, 61, 69, 72-76) with respect to
        each body's mass, first moments and second moments about its joint (the parallel-axis
        form), then ``Ldot_i`` and ``tanh(Ldot_i / coulomb_velocity)`` of each leg for its
        friction. The columns of parameters that never act are zero: ``cylinder.m`` (the
        cylinder turns about the fixed B_i) and, for legs that do not spin (no
        ``universal_joint_axes``), the axial moments. Legs that do not spin are described in
        the frames of eqs. 43-48, so a vertical leg is singular here (``leg_vertical``)."""
        return self._call("regressor", (x, xd, xdd), return_mask)

    def friction_forces(self, x, xd, *, return_mask=False):
        """The actuator force each leg loses to friction at ``(x, xdot)`` [N]:
        ``F_v,i Ldot_i + F_c,i tanh(Ldot_i / coulomb_velocity)`` (:class:`PlatformParams`),
        zero without friction parameters; shape ``(..., 6)``. A force that overflows double
        precision is a failed row (``nonfinite``), as in the kernel's methods."""
        friction, ok = self._friction(x, xd, return_mask)
        return arguments.finite_rows("friction_forces", friction, ok, return_mask)

    def _friction(self, x, xd, return_mask):
        """The friction forces by the C model's law (NaN where they overflow) and the kernel's
        mask (True without ``return_mask``)."""
        result = self._call("leg_rates", (x, xd), return_mask)
        rates = (result[0] if return_mask else result)[1]
        friction = self._kernel.friction_forces(rates, friction_law(self._params))
        return friction, result[1] if return_mask else True

    def actuator_forces(self, x, xd, xdd, *, return_mask=False):
        """The forces the actuators deliver [N]: the rigid-body forces of
        :meth:`inverse_dynamics` plus :meth:`friction_forces`, ``Y @ pi`` of :meth:`regressor`
        (a sum that overflows is a failed row, as in :meth:`friction_forces`)."""
        tau = self._call("inverse_dynamics", (x, xd, xdd), return_mask)
        friction, ok = self._friction(x, xd, return_mask)
        with np.errstate(over="ignore", invalid="ignore"):
            forces = (tau[0] if return_mask else tau) + friction
        return arguments.finite_rows("actuator_forces", forces, tau[1] & ok if return_mask else True, return_mask)

    def joint_reactions(self, x, xd, xdd, *, return_mask=False):
        """Actuator forces and the reactions at each leg's joints, a
        :class:`~stewart.model.results.JointReactions` ``(tau, base, platform, base_moment)`` in
        {B}: ``base`` the force the base exerts on leg i at its universal joint B_i, ``platform``
        the force leg i exerts on the platform at its spherical joint P_i, ``base_moment`` the
        moment the base exerts on leg i through its universal joint, each of shape ``(..., 6, 3)``.
        From the model's own leg terms: ``platform = tau_i u_i - f_i`` with ``f_i`` the force at
        P_i equivalent to the leg's momentum rates and weight, ``base`` from the leg's Newton
        equation, ``base_moment`` from its moment balance about B_i (along ``a_i x y_i`` with
        joint axes, along the leg in the paper's model, where it keeps a leg with
        ``I_yy != I_zz`` from spinning, zero for axisymmetric legs). Equal to the Newton-Euler
        solution :func:`stewart.oracles.newton_euler.joint_reactions` wherever that is defined."""
        return _named(JointReactions,
                      self._call("joint_reactions", (x, xd, xdd), return_mask), return_mask)

    def forward_kinematics(self, lengths, guess=None, **options):
        """Pose(s) from leg lengths by Newton-Raphson (:func:`stewart.forward_kinematics`),
        starting from ``guess`` or the home pose; ``encoder=True`` takes encoder readings."""
        return kinematics.forward_kinematics(
            self._params, lengths, self._home if guess is None else guess, **options
        )

    def inverse_dynamics_derivatives(self, x, xd, xdd, *, return_mask=False):
        """Actuator forces and their exact Jacobians, an :class:`InverseDynamicsDerivatives`
        ``(tau, dtau_dx, dtau_dxd, dtau_dxdd)``: with the residual ``r = M xddot + V xdot + G
        - J_C^T tau`` of the equation of motion and its partials ``R_x``, ``R_xd`` at that
        ``tau``, ``dtau/dx = J_C^-T R_x``, ``dtau/dxd = J_C^-T R_xd``, ``dtau/dxdd = J_C^-T M``.
        Row = output, column = input; each Jacobian of shape ``(..., 6, 6)``."""
        return _named(InverseDynamicsDerivatives,
                      self._call("inverse_dynamics_derivatives", (x, xd, xdd), return_mask),
                      return_mask)

    def static_force_derivatives(self, x, *, return_mask=False):
        """The static forces, which hold the platform at rest at ``x``, and their exact Jacobian, a
        :class:`StaticForceDerivatives` ``(tau, dtau_dx)``: ``tau = J_C^-T G`` and ``dtau/dx =
        J_C^-T R_x`` with ``R_x = d(G - J_C^T tau)/dx`` at that ``tau`` (eqs. 5, 72-76), what
        :meth:`inverse_dynamics_derivatives` gives at ``xdot = xddot = 0``, derived without the
        velocity and acceleration terms (the preload of :meth:`stiffness_matrix`). Row = output,
        column = input; ``dtau_dx`` of shape ``(..., 6, 6)``."""
        return _named(StaticForceDerivatives, self._call("static_force_derivatives", (x,), return_mask), return_mask)

    def forward_dynamics_derivatives(self, x, xd, tau, *, return_mask=False):
        """Euler accelerations and their exact Jacobians, a :class:`ForwardDynamicsDerivatives`
        ``(xdd, dxdd_dx, dxdd_dxd, dxdd_dtau)``: ``dxdd/dx = -M^-1 R_x``, ``dxdd/dxd = -M^-1
        R_xd`` (partials of the residual at that ``xddot``) and ``dxdd/dtau = M^-1 J_C^T``.
        Row = output, column = input; each Jacobian of shape ``(..., 6, 6)``."""
        return _named(ForwardDynamicsDerivatives,
                      self._call("forward_dynamics_derivatives", (x, xd, tau), return_mask),
                      return_mask)

    def joint_cosines(self, x, axes=None, *, return_mask=False):
        """The cosines of the universal- and spherical-joint angles at poses ``x`` and their exact
        gradient in the pose, a :class:`JointCosines` ``(cosines, dcosines_dx)``: leg i's unit
        vector ``u_i = l_i / |l_i|`` (eq. 26) against its neutral axis ``a_i``, fixed in {B} for the
        universal joint (``u_i . a_i``, columns 0-5) and in {P} for the spherical joint
        (``u_i . R a_i``, columns 6-11); shapes ``(..., 12)`` and ``(..., 12, 6)``. ``axes``
        ``(6, 3)`` (one per leg, a unit vector in each) defaults to the legs' unit vectors at the
        home pose, the neutral axes of :func:`stewart.model.reachability.joint_angles`."""
        if axes is None:
            axes = self._neutral
        else:
            axes = arguments.states("axes", axes, 3)
            if axes.shape != (6, 3):
                raise ValueError(f"axes: expected shape (6, 3), one axis per leg, got {axes.shape}")
        return _named(JointCosines, self._call("joint_cosines", (x, axes[:, 0], axes[:, 1], axes[:, 2]),
                                               return_mask), return_mask)

    def rider_signals(self, x, xd, xdd, *, return_mask=False):
        """What a rider at the origin of {P} senses at poses ``x``, pose rates ``xd`` and pose
        accelerations ``xdd``, with its exact Jacobians, a :class:`RiderSignals` ``(y, dy_dx,
        dy_dxd, dy_dxdd)``: ``y = [f; w]``, the specific force ``f = R^T (a + g e_z)`` (``a`` the
        acceleration of {P}'s origin, ``g`` the parameters' gravity) and the angular velocity ``w
        = R^T J_A [psi', theta', phi']`` (eq. 8), both in {P}
        (:func:`stewart.cueing.vestibular.platform_signals`); row = output, column = input, each
        Jacobian of shape ``(..., 6, 6)``."""
        return _named(RiderSignals, self._call("rider_signals", (x, xd, xdd), return_mask), return_mask)

    def rk4_step(self, x, xd, tau, dt, *, jacobians=False, return_mask=False):
        """One classic RK4 step of ``[x; xdot]`` under forces ``tau`` held over ``dt`` seconds (a
        positive finite number): the step :func:`stewart.simulate` takes in open loop. Returns a
        :class:`Step` ``(x, xd)``, or with ``jacobians`` a :class:`StepDerivatives` ``(x, xd,
        A, B)`` with ``A = d(x+, xd+)/d(x, xd)`` of shape ``(..., 12, 12)`` and ``B = d(x+,
        xd+)/d tau`` of shape ``(..., 12, 6)``, exact (the chain rule through the stages)."""
        dt = arguments.time_step("dt", dt)
        if jacobians:
            return _named(StepDerivatives, self._call("rk4_step_derivatives", (x, xd, tau), return_mask, dt),
                          return_mask)
        return _named(Step, self._call("rk4_step", (x, xd, tau), return_mask, dt), return_mask)

    def leg_residuals(self, x, readings, *, return_mask=False):
        """The inverse-kinematics residuals of kinematic calibration (Zhuang & Roth 1993):
        ``r_i = e_i + delta_i - |l_i|``, the encoder ``readings`` e plus ``params.leg_length_offsets``
        less the leg lengths of eq. 26 at the pose ``x``, shape ``(..., 6)``."""
        return self._call("leg_residuals", (x, readings), return_mask)

    def leg_residual_jacobians(self, x, *, return_mask=False):
        """The exact partials of :meth:`leg_residuals` (Masory, Wang & Zhuang 1993), a
        :class:`LegResidualJacobians` ``(dr_dtheta, dr_dx)``: per leg i, shape ``(..., 6, 7)``,
        those in its own base joint ``b_i``, platform joint ``p_i`` (in {P}) and offset
        ``delta_i``, ``[u_i, -R^T u_i, 1]`` with ``u_i = l_i / |l_i|`` (the other parameters'
        are zero); and ``dr/dx = -J_C T`` (eqs. 5, 8, 18), shape ``(..., 6, 6)``."""
        return _named(LegResidualJacobians, self._call("leg_residual_jacobians", (x,), return_mask), return_mask)

    def target_positions(self, x, offsets, *, return_mask=False):
        """The position ``t + R c`` in {B} of a target fixed to the platform at ``offsets`` ``c``
        in {P} (``(3,)`` or ``(N, 3)``) at the pose ``x``, shape ``(..., 3)``."""
        return self._call("target_positions", (x, _target_offsets(offsets)), return_mask)

    def target_jacobian(self, x, offsets, *, return_mask=False):
        """``d(t + R c)/dx = [E, -[R c]x J_A]`` (eq. 8) of :meth:`target_positions`, shape
        ``(..., 3, 6)``: column ``3 + j`` is the target's velocity ``(J_A e_j) x R c``."""
        return self._call("target_jacobian", (x, _target_offsets(offsets)), return_mask)

    def stiffness_matrix(self, x, stiffness=None, *, coordinates="pose", return_mask=False):
        """The stiffness of the platform on leg springs of ``stiffness`` [N/m] (one value or one
        per leg) preloaded to hold it at ``x``: the Hessian of the potential (springs and
        gravity) ``K_q = J_E^T (diag(k) J_E + dtau_s/dx)`` in the pose coordinates, or in the
        twist coordinates with ``coordinates="twist"``; exact, shape ``(..., 6, 6)``
        (:func:`stewart.model.stiffness.stiffness_matrix`)."""
        return _stiffness.stiffness_matrix(self, x, stiffness, coordinates=coordinates, return_mask=return_mask)

    def modes(self, x, stiffness=None, damping=None, *, return_mask=False):
        """The natural frequencies [Hz] (ascending), mass-normalized mode shapes as twists
        ``[dp; dtheta]`` in {B} and, with leg dampers ``damping`` [N s/m], the damping ratios of
        the platform on preloaded leg springs of ``stiffness`` [N/m] at ``x``, legs' inertia
        and payload included: a :class:`~stewart.model.stiffness.Modes`
        (:func:`stewart.model.stiffness.modes`)."""
        return _stiffness.modes(self, x, stiffness, damping, return_mask=return_mask)

    def compliance(self, x, stiffness=None, point=None, *, return_mask=False):
        """The Cartesian compliance at ``x``: the small displacement ``[dp; dtheta]`` of
        ``point`` (in {P}, default its origin) under a unit wrench ``[f; m]`` there, all in {B},
        shape ``(..., 6, 6)`` (:func:`stewart.model.stiffness.compliance`)."""
        return _stiffness.compliance(self, x, stiffness, point, return_mask=return_mask)


def _target_offsets(offsets) -> np.ndarray:
    """Targets' positions in {P}, ``(3,)`` or ``(N, 3)``, as the C's input of 6 doubles a row
    (the last three zero, not read)."""
    arr = arguments.state_array("offsets", offsets, 3)
    return np.concatenate([arr, np.zeros(arr.shape[:-1] + (3,))], axis=-1)


def friction_law(params: PlatformParams, viscous=None, coulomb=None, velocity=None) -> tuple[np.ndarray, np.ndarray, float]:
    """``(F_v (6,), F_c (6,), v_c)`` of the legs' friction law: the values given, else the
    parameters' ``viscous_friction``, ``coulomb_friction`` and ``coulomb_velocity`` (zeros
    where they have none)."""
    def per_leg(given, own):
        return given if given is not None else np.zeros(6) if own is None else np.array(own)

    return (per_leg(viscous, params.viscous_friction), per_leg(coulomb, params.coulomb_friction),
            params.coulomb_velocity if velocity is None else velocity)


def as_platform(value, name: str = "platform") -> Platform:
    """``value`` as a :class:`Platform`: a :class:`Platform` as it is, a
    :class:`PlatformParams` compiled into one (``Platform(value)``); how a function that
    evaluates the compiled model takes its platform argument (see :mod:`stewart.model`).
    :class:`~stewart.WrongTypeError` (a ``TypeError`` and a ``ValueError``) naming ``name``
    for anything else."""
    if isinstance(value, Platform):
        return value
    if isinstance(value, PlatformParams):
        return Platform(value)
    raise WrongTypeError(f"{name}: expected a stewart.Platform, got {type(value).__name__}")
