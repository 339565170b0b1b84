"""The rotary rigs' kernels (issue 40) against the linear model's, per state in a batch, measured
side by side in interleaved rounds (:mod:`stewart.cli.interleaved`): the motor torques over the
linear inverse dynamics and the rotary forward dynamics over the linear one (targets: at most
1.5 times), and, without targets, the exact derivatives (the torques' and the accelerations'
Jacobians, the RK4 step with A and B) over the linear model's same functions. The rotary rig
is ``simrig100`` (the sim-racing rig), the linear one ``motion_simulator`` (the paper's model
of a motion simulator), on random states about each one's home pose, on the path in use::

    python -m benchmarks.rotary_kernel
"""

from __future__ import annotations

import numpy as np

import stewart
from stewart.cli import bench
from stewart.cli.interleaved import Target

from .report import target_table

#: The rigs compared.
ROTARY, LINEAR = "simrig100", "motion_simulator"
#: Issue 40: batched torques and forward dynamics at most 1.5 times the linear model's, a state each.
TARGET = Target(1.5, True, "the linear model")
#: Figure key stem -> (the table's name, the batch's states, target or None). The values on
#: bench.ROUND_BATCH states a round, the derivatives on those of bench.DERIVATIVE_ROUND.
FUNCTIONS = {
    "inverse_dynamics": ("motor torques / inverse dynamics", bench.ROUND_BATCH, TARGET),
    "forward_dynamics": ("forward dynamics", bench.ROUND_BATCH, TARGET),
    "inverse_dynamics_derivatives": ("torques and their 3 Jacobians",
                                     bench.DERIVATIVE_ROUND["inverse_dynamics_derivatives"], None),
    "forward_dynamics_derivatives": ("xdd and its 3 Jacobians",
                                     bench.DERIVATIVE_ROUND["forward_dynamics_derivatives"], None),
    "rk4_step_jacobians": ("RK4 step with A and B", bench.DERIVATIVE_ROUND["rk4_step_jacobians"], None),
}


def rotary_states(model: stewart.RotaryPlatform, n: int, seed: int = 0):
    """(x, xd, xdd) of n states about the rig's home, every crank within reach: poses within
    2 cm and 0.05 rad, rates and accelerations as :func:`stewart.cli.bench.states` draws them."""
    rng = np.random.default_rng(seed)
    scale = np.array([0.02] * 3 + [0.05] * 3)
    x = model.home + rng.uniform(-1, 1, (2 * n, 6)) * scale
    x = x[model.crank_angles(x, return_mask=True)[1]][:n]
    if len(x) < n:
        raise RuntimeError(f"{model.params.name}: fewer than {n} reachable states drawn")
    return x, rng.normal(size=(n, 6)) * scale * 5, rng.normal(size=(n, 6)) * scale * 50


def _calls(model, x, xd, xdd, tau):
    dt = bench.RK4_DT
    return {"inverse_dynamics": lambda m: model.inverse_dynamics(x[:m], xd[:m], xdd[:m]),
            "forward_dynamics": lambda m: model.forward_dynamics(x[:m], xd[:m], tau[:m]),
            "inverse_dynamics_derivatives": lambda m: model.inverse_dynamics_derivatives(x[:m], xd[:m], xdd[:m]),
            "forward_dynamics_derivatives": lambda m: model.forward_dynamics_derivatives(x[:m], xd[:m], tau[:m]),
            "rk4_step_jacobians": lambda m: model.rk4_step(x[:m], xd[:m], tau[:m], dt, jacobians=True)}


def figures(rounds: bench.Rounds | None = None) -> dict:
    """Per function: the rotary batch per state (µs at the reference machine's speed) and its
    ratio to the linear model's on as many states."""
    rounds = rounds or bench.Rounds()
    rotary, linear = stewart.RotaryPlatform.preset(ROTARY), stewart.Platform.preset(LINEAR)
    n = bench.ROUND_BATCH
    x, xd, xdd = rotary_states(rotary, n)
    ours = _calls(rotary, x, xd, xdd, rotary.inverse_dynamics(x, xd, xdd))
    x, xd, xdd = bench.states(linear.params, n)
    theirs = _calls(linear, x, xd, xdd, linear.inverse_dynamics(x, xd, xdd))
    for name, (_, m, target) in FUNCTIONS.items():
        rounds.absolute(f"rotary_batch_{name}_us", lambda f=ours[name], m=m: f(m), m)
        rounds.ratio(f"rotary_over_linear_{name}", lambda f=ours[name], m=m: f(m), lambda f=theirs[name], m=m: f(m),
                     target=target)
    return {"rotary": ROTARY, "linear": LINEAR, "path": stewart.build_info()["simd"],
            **bench.figures_of(rounds.measure())}


def rows(fig: dict) -> list[tuple[str, str, str, str, str]]:
    """(measure, figure, spread, target, verdict) rows."""
    out = []
    for name, (what, m, target) in FUNCTIONS.items():
        out.append(bench.measure_row(f"rotary {fig['rotary']}: {what}, C batch loop ({m} states)",
                                     f"rotary_batch_{name}_us", bench.as_measurement(fig, f"rotary_batch_{name}_us"),
                                     1.0, "us/state", ".3f"))
        out.append(bench.measure_row(f"rotary {fig['rotary']} over linear {fig['linear']}: {what}, a state each "
                                     f"({fig['path']})", f"rotary_over_linear_{name}",
                                     bench.as_measurement(fig, f"rotary_over_linear_{name}"), 1.0, "x", ".2f", target))
    return out


def format_rows(fig: dict) -> str:
    return target_table(rows(fig))


if __name__ == "__main__":
    print(format_rows(figures()))
