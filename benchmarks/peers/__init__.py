"""Peer implementations of the same platform model, for side-by-side benchmarks.

Each peer module imports its package (casadi, sympy/pydy, mujoco) lazily, so
``python -m benchmarks`` runs without them and reports which peers it skipped
(``pip install .[peers]`` installs them).
"""

from .common import PARAM_COUNT, param_vector, peer_available

__all__ = ["PARAM_COUNT", "param_vector", "peer_available"]
