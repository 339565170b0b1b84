"""The compiled model as CasADi functions with exact Jacobians, for optimal control.

Each function here returns a :class:`casadi.Function` (a ``casadi.Callback``) that a CasADi
or acados user drops into an expression graph or an NLP like any other function. Its
values come from :class:`stewart.Platform`; its Jacobian (``has_jacobian``/``get_jacobian``)
is the platform's exact derivative code, never finite differences:

==========================  ==========================  ===========================================
function                    inputs -> outputs           Jacobian blocks
==========================  ==========================  ===========================================
:func:`inverse_dynamics`    ``x, xd, xdd -> tau``       :meth:`~stewart.Platform.inverse_dynamics_derivatives`
:func:`forward_dynamics`    ``x, xd, tau -> xdd``       :meth:`~stewart.Platform.forward_dynamics_derivatives`
:func:`rk4_step`            ``s, tau -> s_next``        ``A``, ``B`` of :meth:`~stewart.Platform.rk4_step`
:func:`leg_lengths`         ``x -> L``                  ``dL/dx = J_C T`` (eqs. 5, 18)
==========================  ==========================  ===========================================

Every input and output is a dense column (``x``, ``xd``, ``xdd``, ``tau``, ``L``: 6; the
RK4 state ``s = [x; xd]``: 12), or with ``count = N`` a matrix of ``N`` such columns, one
state each, evaluated as one batch by the compiled kernel: the function then equals its
``count = 1`` version mapped over the columns (``Function.map``), with block-diagonal
sparse Jacobians, and costs one call instead of ``N``. Where the model is undefined (a singular ``J_C``,
``theta = +-90 deg`` in forward dynamics, a degenerate leg) the outputs and Jacobians are
NaN rather than an exception, which is how a solver such as IPOPT is told that a trial
point lies outside the domain (it then shortens its step).

Only first derivatives are provided: use a quasi-Newton Hessian (IPOPT's
``hessian_approximation = "limited-memory"``). CasADi is the optional ``opt`` extra
(``pip install stewart[opt]``).
"""

from __future__ import annotations

from functools import cache
from typing import Callable, Sequence

import numpy as np

from ..model import arguments
from ..model.kinematics import twist_transform
from ..model.platform import Platform

__all__ = ["inverse_dynamics", "forward_dynamics", "rk4_step", "leg_lengths"]


def _casadi():
    try:
        import casadi
    except ImportError:  # pragma: no cover - depends on the environment
        raise ImportError("stewart.motion.casadi_functions needs CasADi: pip install 'stewart[opt]'") from None
    return casadi


@cache
def _callback_class():
    ca = _casadi()

    class ModelCallback(ca.Callback):
        """A CasADi function of ``count`` states side by side, evaluated in Python: input i is a
        dense ``inputs[i][1] x count`` matrix, one state per column, and so are the outputs.
        ``evaluate(*inputs)`` takes and returns ``(count, rows)`` arrays; ``jacobian(*inputs)``
        returns the blocks ``d out_i / d in_j`` (over outputs, then inputs) as
        ``(count, rows out, rows in)`` arrays, which become block-diagonal sparse matrices
        (state k depends on column k alone)."""

        def __init__(self, name: str, inputs: Sequence[tuple[str, int]], outputs: Sequence[tuple[str, int]],
                     count: int, evaluate: Callable, jacobian: Callable | None = None, opts: dict | None = None,
                     blocks: Sequence | None = None):
            ca.Callback.__init__(self)
            self._inputs, self._outputs, self._count = list(inputs), list(outputs), count
            self._evaluate, self._jacobian = evaluate, jacobian
            # The sparsity of each output: dense columns, or (for a Jacobian) the blocks.
            self._blocks = blocks is not None
            self._sparsity = list(blocks) if self._blocks else [ca.Sparsity.dense(n, count) for _, n in self._outputs]
            self._jacobian_function = None  # kept alive with this function
            self.construct(name, dict(opts or {}))

        def get_n_in(self):
            return len(self._inputs)

        def get_n_out(self):
            return len(self._outputs)

        def get_name_in(self, i):
            return self._inputs[i][0]

        def get_name_out(self, i):
            return self._outputs[i][0]

        def get_sparsity_in(self, i):
            return ca.Sparsity.dense(self._inputs[i][1], self._count)

        def get_sparsity_out(self, i):
            return self._sparsity[i]

        def eval(self, arg):
            values = self._evaluate(*(np.asarray(a, dtype=float).T for a in arg))
            # Column-major nonzeros: a state's column, or a state's block column by column.
            return [ca.DM(sparsity, (np.swapaxes(v, -1, -2) if self._blocks else np.asarray(v)).ravel())
                    for v, sparsity in zip(values, self._sparsity)]

        def _block(self, oind, iind):
            """The sparsity of d out / d in: state k's column depends on state k's alone."""
            return ca.kron(ca.Sparsity.diag(self._count),
                           ca.Sparsity.dense(self._outputs[oind][1], self._inputs[iind][1]))

        def has_jac_sparsity(self, oind, iind):
            return not self._blocks

        def get_jac_sparsity(self, oind, iind, symmetric):
            return self._block(oind, iind)

        def has_jacobian(self):
            return self._jacobian is not None

        def get_jacobian(self, name, inames, onames, opts):
            # CasADi's convention: inputs are the nominal inputs, then the nominal outputs;
            # outputs are the blocks d out_i / d in_j, for every output, then every input.
            n_in = len(self._inputs)
            blocks = [self._block(o, i) for o in range(len(self._outputs)) for i in range(n_in)]
            self._jacobian_function = ModelCallback(
                name, list(zip(inames, [n for _, n in self._inputs + self._outputs])),
                [(o, 0) for o in onames], self._count, lambda *values: self._jacobian(*values[:n_in]), None, opts,
                blocks)
            return self._jacobian_function

    return ModelCallback


def _count(count) -> int:
    return arguments.count("count", count, 10_000_000)


def _dynamics(name: str, platform: Platform, inputs: tuple[str, str, str], output: str, method: str,
              derivatives: str, count):
    evaluate = getattr(platform, method)
    differentiate = getattr(platform, derivatives)

    def value(a, b, c):
        return [evaluate(a, b, c, return_mask=True)[0]]

    def jacobian(a, b, c):
        return list(differentiate(a, b, c, return_mask=True)[0][1:])

    return _callback_class()(name, [(n, 6) for n in inputs], [(output, 6)], _count(count), value, jacobian)


def inverse_dynamics(platform: Platform, count: int = 1, name: str = "stewart_inverse_dynamics"):
    """``tau = f(x, xd, xdd)`` (:meth:`stewart.Platform.inverse_dynamics`) with its exact
    Jacobian blocks ``dtau/dx``, ``dtau/dxd``, ``dtau/dxdd``."""
    return _dynamics(name, platform, ("x", "xd", "xdd"), "tau", "inverse_dynamics", "inverse_dynamics_derivatives",
                     count)


def forward_dynamics(platform: Platform, count: int = 1, name: str = "stewart_forward_dynamics"):
    """``xdd = f(x, xd, tau)`` (:meth:`stewart.Platform.forward_dynamics`) with its exact
    Jacobian blocks ``dxdd/dx``, ``dxdd/dxd``, ``dxdd/dtau``."""
    return _dynamics(name, platform, ("x", "xd", "tau"), "xdd", "forward_dynamics", "forward_dynamics_derivatives",
                     count)


def rk4_step(platform: Platform, dt: float, count: int = 1, name: str = "stewart_rk4_step"):
    """One RK4 step of ``s = [x; xd]`` over ``dt`` seconds under constant actuator forces:
    ``s_next = f(s, tau)`` (:meth:`stewart.Platform.rk4_step`), with the exact Jacobian blocks
    ``A = ds_next/ds`` (12 x 12) and ``B = ds_next/dtau`` (12 x 6)."""
    dt = arguments.real("dt", dt)
    if not dt > 0:
        raise ValueError(f"dt: must be > 0, got {dt}")

    def value(s, tau):
        (x, xd), _ = platform.rk4_step(s[..., :6], s[..., 6:], tau, dt, return_mask=True)
        return [np.concatenate([x, xd], axis=-1)]

    def jacobian(s, tau):
        (_, _, a, b), _ = platform.rk4_step(s[..., :6], s[..., 6:], tau, dt, jacobians=True, return_mask=True)
        return [a, b]

    return _callback_class()(name, [("s", 12), ("tau", 6)], [("s_next", 12)], _count(count), value, jacobian)


def leg_lengths(platform: Platform, count: int = 1, name: str = "stewart_leg_lengths"):
    """``L = f(x)`` (:meth:`stewart.Platform.leg_lengths`) with its exact Jacobian
    ``dL/dx = J_C T`` (``Ldot = J_C [v; omega]``, eq. 5, and ``[v; omega] = T xdot``, eq. 18)."""

    def value(x):
        return [platform.leg_lengths(x, return_mask=True)[0]]

    def jacobian(x):
        jac, _ = platform.jacobian(x, return_mask=True)
        return [jac @ twist_transform(x)]

    return _callback_class()(name, [("x", 6)], [("L", 6)], _count(count), value, jacobian)
