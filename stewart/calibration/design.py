"""Measurement poses for calibration, chosen for observability.

The poses are picked from random reachable candidates (:mod:`stewart.model.reachability`)
around a centre pose by greedy D-optimal selection: each step adds the candidate that most
raises ``log det(J^T J + eps I)`` (``eps = 1e-6``) of the column-scaled identification
Jacobian of pose measurements (:mod:`stewart.calibration.geometry`), a rank-6 update
evaluated for every candidate at once. The index maximized is Sun & Hollerbach's ``O1 = det(J^T J)^(1/2n) /
sqrt(m)`` (the geometric mean of the singular values over the square root of the number of
rows; Sun & Hollerbach 2008, "Observability index selection for robot calibration"); the
design also reports the condition number ``sigma_max / sigma_min`` (the inverse of ``O3``)
and the noise amplification index ``O4 = sigma_min^2 / sigma_max`` (Nahvi & Hollerbach
1996), and compares them with the same number of random candidates.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..model import arguments
from ..model.params import platform_params
from ..model.kinematics import encoder_readings, home_pose
from ..model.reachability import reachability
from .geometry import NUM_PARAMETERS, leg_jacobian, parameter_vector

__all__ = ["PoseDesign", "design_poses", "observability", "DEFAULT_TRANSLATION", "DEFAULT_ROTATION"]

#: Default half-widths of the box the candidates are drawn from: a fraction of the home
#: height for the position, radians for the angles.
DEFAULT_TRANSLATION = 0.1
DEFAULT_ROTATION = 0.25
#: Candidates drawn per pose chosen.
CANDIDATES_PER_POSE = 40


@dataclass(frozen=True)
class PoseDesign:
    """Designed ``poses`` (N, 6) with their ``readings`` (N, 6), the encoder readings of the
    nominal machine, and the observability indices of the design and of ``random`` poses
    (dicts with ``O1``, ``condition`` and ``O4``)."""

    poses: np.ndarray
    readings: np.ndarray
    designed: dict
    random: dict

    def to_csv(self, path, comment: str = "designed calibration poses") -> None:
        """The campaign's CSV: the poses and the nominal encoder readings (the layout of pose
        measurements, :mod:`stewart.calibration.measurements`)."""
        from ..io import csvfile
        from .measurements import POSE_COLUMNS

        csvfile.write(path, POSE_COLUMNS, np.column_stack([self.poses, self.readings]), comment, fmt="%.12g")


def _scaled_rows(params, poses) -> np.ndarray:
    """The identification Jacobian's rows (K, 6, 42) with every column scaled to unit RMS
    over ``poses`` (the sum of squares of a pose's six rows averaging 1; so that positions in
    metres and offsets weigh alike)."""
    rows = leg_jacobian(parameter_vector(params), poses)
    scale = np.sqrt(np.mean(np.sum(rows * rows, axis=1), axis=0))
    return rows / scale


def observability(params, poses) -> dict:
    """``O1``, the ``condition`` number and ``O4`` of the column-scaled identification
    Jacobian of ``poses`` (K, 6) (scaled over those poses)."""
    rows = _scaled_rows(platform_params(params), np.atleast_2d(poses)).reshape(-1, NUM_PARAMETERS)
    sv = np.linalg.svd(rows, compute_uv=False)
    if len(sv) < NUM_PARAMETERS:  # fewer rows than parameters
        return {"O1": 0.0, "condition": float("inf"), "O4": 0.0}
    with np.errstate(divide="ignore"):  # a zero singular value gives the same 0, inf and 0
        return {"O1": float(np.exp(np.mean(np.log(sv))) / np.sqrt(len(rows))), "condition": float(sv[0] / sv[-1]),
                "O4": float(sv[-1] ** 2 / sv[0])}


def design_poses(platform, count: int, *, centre=None, translation: float | None = None,
                 rotation: float = DEFAULT_ROTATION, seed: int = 0, progress: bool = False) -> PoseDesign:
    """``count`` (at least 7) measurement poses of ``platform`` (a :class:`~stewart.Platform`
    or :class:`~stewart.PlatformParams`) in the box ``centre +- (translation, rotation)``
    (default: home, a tenth of the home height, 0.25 rad) that maximize ``O1``."""
    params = platform_params(platform, "platform")
    count = arguments.count("count", count, 100_000)
    if count < 7:
        raise ValueError(f"count: 42 parameters need at least 7 poses (6 legs each), got {count}")
    centre = home_pose(params) if centre is None else arguments.states("centre", centre)
    if centre.shape != (6,):
        raise ValueError(f"centre: expected one pose, got shape {centre.shape}")
    translation = DEFAULT_TRANSLATION * centre[2] if translation is None else arguments.real("translation", translation)
    rotation = arguments.real("rotation", rotation)
    for name, value in (("translation", translation), ("rotation", rotation)):
        if value <= 0.0:  # (finite: arguments.real)
            raise ValueError(f"{name}: must be a positive finite number, got {value}")
    rng = np.random.default_rng(arguments.seed(seed))
    box = np.array([translation] * 3 + [rotation] * 3)
    candidates = centre + rng.uniform(-1.0, 1.0, (CANDIDATES_PER_POSE * count, 6)) * box
    candidates = candidates[reachability(params, candidates).ok]
    if len(candidates) < 2 * count:
        raise ValueError(f"centre, translation, rotation: only {len(candidates)} of {CANDIDATES_PER_POSE * count} "
                         f"random poses in the box are reachable; need {2 * count} (move the centre or shrink the box)")
    rows = _scaled_rows(params, candidates)
    chosen = _greedy(rows, count, progress)
    random = candidates[rng.choice(len(candidates), count, replace=False)]
    poses = candidates[chosen]
    return PoseDesign(poses=poses, readings=encoder_readings(params, poses),
                      designed=observability(params, poses), random=observability(params, random))


def _greedy(rows: np.ndarray, count: int, progress: bool) -> list[int]:
    """Indices of ``count`` candidates chosen one by one to raise ``log det(M + eps I)`` most,
    ``M`` the information matrix of those chosen: adding candidate ``c`` multiplies
    ``det`` by ``det(I + J_c M^-1 J_c^T)`` (the matrix determinant lemma)."""
    from tqdm.auto import tqdm

    information = 1e-6 * np.eye(NUM_PARAMETERS)
    chosen: list[int] = []
    available = np.ones(len(rows), dtype=bool)
    for _ in tqdm(range(count), desc="calibration poses", disable=not progress):
        inverse = np.linalg.inv(information)
        small = np.eye(6) + np.einsum("cia,cja->cij", rows @ inverse, rows)
        gain = np.linalg.slogdet(small)[1]
        gain[~available] = -np.inf
        best = int(np.argmax(gain))
        chosen.append(best)
        available[best] = False
        information = information + rows[best].T @ rows[best]
    return chosen

