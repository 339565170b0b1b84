"""An independent model of a 6-RSS rotary rig for the tests, written from the mechanism, not
from codegen/ and importing nothing from stewart.model or the kernels (a parameter set is
read by its attribute names only).

- The crank angles by atan2 and acos, each leg's two roots tried and the one kept whose
  (P_i - c_i) . (a_i x (c_i - b_i)) has the sign crank_branch[i] (the definition itself).
- Velocities and accelerations by hand from the loop closure |P_i - c_i| = d: alpha' =
  n . v_P / (n . t), alpha'' = (n . a_P + alpha'^2 r n . u + |n'|^2) / (n . t).
- The torques by the principle of virtual power in the pose coordinates (d'Alembert):
  Q_k = sum over bodies of the partial velocities along xd_k times their inertia forces and
  weights, tau = (d alpha' / d xd)^-T Q, the partials taken as the velocities at xd = e_k.
- The energy T + V of the bodies, in complex arithmetic as well, for the power balance
  dE/dt = tau . alpha' by complex step.
- The forward dynamics from the torques alone (they are affine in the accelerations: seven
  evaluations give the matrix and the offset), and a classic RK4 step over it, both in
  complex arithmetic as well, for complex-step derivatives.
"""

import numpy as np

EZ = np.array([0.0, 0.0, 1.0])


def rotation(angles):
    """R = Rz(psi) Ry(theta) Rx(phi) (complex entries allowed)."""
    psi, theta, phi = angles
    cz, sz, cy, sy, cx, sx = np.cos(psi), np.sin(psi), np.cos(theta), np.sin(theta), np.cos(phi), np.sin(phi)
    Rz = np.array([[cz, -sz, 0 * cz], [sz, cz, 0 * cz], [0 * cz, 0 * cz, 1 + 0 * cz]])
    Ry = np.array([[cy, 0 * cy, sy], [0 * cy, 1 + 0 * cy, 0 * cy], [-sy, 0 * cy, cy]])
    Rx = np.array([[1 + 0 * cx, 0 * cx, 0 * cx], [0 * cx, cx, -sx], [0 * cx, sx, cx]])
    return Rz @ Ry @ Rx


def angular_velocity(angles, rates):
    """omega in {B} from the ZYX Euler rates: psi' z + theta' Rz y + phi' Rz Ry x."""
    psi, theta, _ = angles
    Rz = rotation([psi, 0.0 * theta, 0.0 * psi])
    Rzy = rotation([psi, theta, 0.0 * psi])
    return rates[0] * EZ + rates[1] * Rz[:, 1] + rates[2] * Rzy[:, 0]


def angular_acceleration(angles, rates, accelerations):
    """omega' by differentiating `angular_velocity` by hand: the frames' axes z, Rz y and
    Rz Ry x turn with 0, psi' z and psi' z + theta' Rz y."""
    psi, theta, _ = angles
    y_axis = rotation([psi, 0.0 * theta, 0.0 * psi])[:, 1]
    x_axis = rotation([psi, theta, 0.0 * psi])[:, 0]
    turning = rates[0] * EZ + rates[1] * y_axis
    return (angular_velocity(angles, accelerations) + rates[1] * np.cross(rates[0] * EZ, y_axis)
            + rates[2] * np.cross(turning, x_axis))


def crank_angles(rig, x):
    """The crank angles in their branches by atan2 and acos, or None where out of reach."""
    R = rotation(x[3:])
    out = np.empty(6)
    for i in range(6):
        b, a, h = rig.base_points[i], rig.motor_axes[i], rig.crank_zero[i]
        k = np.cross(a, h)
        P = x[:3] + R @ rig.platform_points[i]
        e = P - b
        A, B = 2 * rig.crank_length * e @ h, 2 * rig.crank_length * e @ k
        C = e @ e + rig.crank_length ** 2 - rig.rod_length ** 2
        phi, ratio = np.arctan2(B, A), C / np.hypot(A, B)
        if abs(ratio) > 1.0:
            return None
        for alpha in (phi + np.arccos(ratio), phi - np.arccos(ratio)):
            c = b + rig.crank_length * (np.cos(alpha) * h + np.sin(alpha) * k)
            if np.sign((P - c) @ np.cross(a, c - b)) == rig.crank_branch[i]:
                out[i] = np.angle(np.exp(1j * alpha))
                break
    return out


def complex_crank_angles(rig, x, alpha):
    """The crank angles at a complex pose x near a real one, by Newton on the loop closure
    from the real roots `alpha` (three steps: exact to first order in the imaginary part)."""
    R = rotation(x[3:])
    alpha = alpha.astype(complex)
    for _ in range(3):
        for i in range(6):
            u = np.cos(alpha[i]) * rig.crank_zero[i] + np.sin(alpha[i]) * np.cross(rig.motor_axes[i], rig.crank_zero[i])
            n = x[:3] + R @ rig.platform_points[i] - rig.base_points[i] - rig.crank_length * u
            t = rig.crank_length * np.cross(rig.motor_axes[i], u)
            alpha[i] += (n @ n - rig.rod_length ** 2) / (2 * (n @ t))
    return alpha


def legs(rig, x, xd, xdd, alpha):
    """Per leg (alpha', alpha'', u, n, n', n'', t, v_P, a_P) at the state."""
    R = rotation(x[3:])
    w, wd = angular_velocity(x[3:], xd[3:]), angular_acceleration(x[3:], xd[3:], xdd[3:])
    r = rig.crank_length
    out = []
    for i in range(6):
        a, h = rig.motor_axes[i], rig.crank_zero[i]
        u = np.cos(alpha[i]) * h + np.sin(alpha[i]) * np.cross(a, h)
        t = r * np.cross(a, u)
        rp = R @ rig.platform_points[i]
        n = x[:3] + rp - rig.base_points[i] - r * u
        v_P = xd[:3] + np.cross(w, rp)
        a_P = xdd[:3] + np.cross(wd, rp) + np.cross(w, np.cross(w, rp))
        ad = (n @ v_P) / (n @ t)
        nd = v_P - ad * t
        add = (n @ a_P + ad ** 2 * r * (n @ u) + nd @ nd) / (n @ t)
        ndd = a_P - (add * t - ad ** 2 * r * u)
        out.append((ad, add, u, n, nd, ndd, t, v_P, a_P))
    return out


def _bodies(rig, x, xd, xdd, alpha):
    """Each body's (velocity, acceleration) pairs: the platform's centre of mass and angular
    velocity; per leg the crank's rate, the rod's centre of mass and its angular velocity."""
    R = rotation(x[3:])
    w, wd = angular_velocity(x[3:], xd[3:]), angular_acceleration(x[3:], xd[3:], xdd[3:])
    com = np.zeros(3) if rig.platform_com is None else np.asarray(rig.platform_com)
    rho = R @ com
    v_G = xd[:3] + np.cross(w, rho)
    a_G = xdd[:3] + np.cross(wd, rho) + np.cross(w, np.cross(w, rho))
    sigma = rig.rod_com_distance / rig.rod_length
    d2 = rig.rod_length ** 2
    per_leg = []
    for ad, add, u, n, nd, ndd, t, v_P, a_P in legs(rig, x, xd, xdd, alpha):
        c_d, c_dd = ad * t, add * t - ad ** 2 * rig.crank_length * u
        per_leg.append(((ad, add), ((1 - sigma) * c_d + sigma * v_P, (1 - sigma) * c_dd + sigma * a_P),
                        (np.cross(n, nd) / d2, np.cross(n, ndd) / d2), u))
    return (v_G, a_G), (w, wd), R, per_leg


def _inertia(rig):
    I = np.asarray(rig.platform_inertia, dtype=float)
    return np.diag(I) if I.shape == (3,) else I


def torques(rig, x, xd, xdd):
    """The motor torques at (x, xd, xdd), by virtual power in the pose coordinates (complex
    arithmetic allowed, for complex-step derivatives)."""
    alpha = crank_angles(rig, np.real(x))
    if np.iscomplexobj(x):
        alpha = complex_crank_angles(rig, x, alpha)
    (v_G, a_G), (w, wd), R, per_leg = _bodies(rig, x, xd, xdd, alpha)
    I_B = R @ _inertia(rig) @ R.T
    g = rig.gravity
    force_G = rig.platform_mass * (a_G + g * EZ)
    moment = I_B @ wd + np.cross(w, I_B @ w)
    Q, Jq = np.zeros(6, dtype=complex), np.zeros((6, 6), dtype=complex)
    for k in range(6):
        e = np.eye(6)[k]
        (pv_G, _), (pw, _), _, partial = _bodies(rig, x, e, np.zeros(6), alpha)
        Q[k] = pv_G @ force_G + pw @ moment
        for i, (((pad, _), (pv_R, _), (pw_R, _), _), ((_, add), (_, a_R), (w_R, wd_R), u)) in enumerate(
                zip(partial, per_leg)):
            weight = rig.crank_mass * g * rig.crank_com_distance * np.cross(rig.motor_axes[i], u)[2]
            Q[k] += pad * (rig.crank_inertia * add + weight)
            Q[k] += pv_R @ (rig.rod_mass * (a_R + g * EZ)) + pw_R @ (rig.rod_inertia * wd_R)
            Jq[i, k] = pad
    tau = np.linalg.solve(Jq.T, Q)
    return tau if any(np.iscomplexobj(a) for a in (x, xd, xdd)) else tau.real


def crank_rates(rig, x, xd):
    """alpha' at (x, xd)."""
    return np.array([leg[0] for leg in legs(rig, x, xd, np.zeros(6), crank_angles(rig, x))])


def energy(rig, x, xd, alpha):
    """T + V of the bodies at (x, xd) (complex arithmetic allowed; `alpha` the real crank angles
    of the real part of x)."""
    alpha = complex_crank_angles(rig, x, alpha) if np.iscomplexobj(x) or np.iscomplexobj(xd) else alpha
    (v_G, _), (w, _), R, per_leg = _bodies(rig, x, xd, np.zeros(6), alpha)
    com = np.zeros(3) if rig.platform_com is None else np.asarray(rig.platform_com)
    T = 0.5 * rig.platform_mass * (v_G @ v_G) + 0.5 * w @ (R @ _inertia(rig) @ R.T) @ w
    V = rig.platform_mass * rig.gravity * (x[2] + (R @ com)[2])
    for i, ((ad, _), (v_R, _), (w_R, _), u) in enumerate(per_leg):
        T += 0.5 * rig.crank_inertia * ad ** 2 + 0.5 * rig.rod_mass * (v_R @ v_R) + 0.5 * rig.rod_inertia * (w_R @ w_R)
        c = rig.base_points[i] + rig.crank_length * u
        P = x[:3] + R @ rig.platform_points[i]
        z_R = c[2] + rig.rod_com_distance / rig.rod_length * (P - c)[2]
        V += rig.gravity * (rig.crank_mass * (rig.base_points[i][2] + rig.crank_com_distance * u[2]) + rig.rod_mass * z_R)
    return T + V


def forward_dynamics(rig, x, xd, torque):
    """The pose accelerations under `torque`: `torques` is affine in xdd, tau = A xdd + b with
    b = torques(x, xd, 0) and column k of A = torques(x, xd, e_k) - b, so xdd = A^-1 (torque - b)
    (complex arithmetic allowed); one step of iterative refinement on the residual
    torque - torques(x, xd, xdd) recovers the digits the differences of A lose to b."""
    b = torques(rig, x, xd, np.zeros(6))
    A = np.array([torques(rig, x, xd, e) for e in np.eye(6)]).T - b[:, None]
    xdd = np.linalg.solve(A, torque - b)
    return xdd + np.linalg.solve(A, torque - torques(rig, x, xd, xdd))


def rk4_step(rig, x, xd, torque, dt):
    """One classic RK4 step of s = [x; xd], s' = [xd; forward_dynamics], torque held."""
    def f(s):
        return np.concatenate([s[6:], forward_dynamics(rig, s[:6], s[6:], torque)])
    s = np.concatenate([x, xd])
    k1 = f(s)
    k2 = f(s + dt / 2 * k1)
    k3 = f(s + dt / 2 * k2)
    k4 = f(s + dt * k3)
    return s + dt / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
