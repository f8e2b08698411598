"""Experiment design: the joint configurations to measure so that the identification is well conditioned.

From a pool of candidate configurations drawn uniformly inside the joint limits (seeded), ``n`` are chosen
to maximise a criterion of the information matrix ``M = sum_i A_i^T A_i``, ``A_i`` the rows of pose ``i`` of
the identification Jacobian at the nominal model, restricted to the identifiable errors (the base set of
:func:`~scara_pin.calibration.identify.identify` on the pool) with each column scaled to unit RMS over the
pool (metres, radians and scales then compare):

- :attr:`Criterion.DET` (D-optimal): ``log det M``, the volume of the confidence ellipsoid's inverse;
- :attr:`Criterion.MIN_SV` (E-optimal): ``sqrt(lambda_min(M))``, the smallest singular value of the stacked
  scaled Jacobian: the worst-determined combination of errors.

The poses are picked greedily (each the candidate that most increases ``log det M``: by the determinant
lemma, ``log det(I + A M^-1 A^T)``), then improved by exchanges: each chosen pose is replaced by the
candidate that most improves the criterion, while one does (Fedorov's exchange; for MIN_SV among
``EXCHANGE_TRIALS`` random candidates per pose).
"""

from __future__ import annotations

import enum
import math
from collections.abc import Iterable
from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from ..errors import InvalidInputError
from ..limits import MAX_PLAN_POSES, MAX_PLAN_WORK, check_count
from ..model import RobotModel
from ..summary import Summarized
from .chain import ALL_GROUPS, ChainModel, Group, MeasurementFrame
from .fit import random_poses, structural_count
from .identify import identify
from .measurements import measurement_columns

__all__ = ["Criterion", "ExperimentPlan", "plan_experiment"]

EXCHANGE_PASSES = 3
"""The most exchange passes over the chosen poses."""
EXCHANGE_TRIALS = 64
"""Candidates tried per chosen pose and pass for the MIN_SV criterion."""
MAX_CANDIDATES = 4000
"""The largest candidate pool (the default pool: 20 per pose asked, at least 500)."""
_RIDGE = 1e-9
"""The information matrix starts at this multiple of the identity (the first poses are then comparable)."""


class Criterion(enum.Enum):
    """What the experiment design maximises."""

    DET = "det"
    """D-optimal: log det of the information matrix."""
    MIN_SV = "min-sv"
    """E-optimal: the smallest singular value of the scaled identification Jacobian."""


@dataclass(frozen=True, eq=False, repr=False)
class ExperimentPlan(Summarized):
    """The configurations to measure.

    Attributes:
        robot: the robot's name. columns: the measurement file's header (``q1 .. qN, x, y, z[, yaw]``).
        q: (n, dof) joint configurations, inside the limits [rad, m].
        predicted: (n, 3) or (n, 4) the nominal model's tool positions (and yaws) there, base frame [m, rad].
        criterion: the criterion maximised.
        identified: the errors the plan identifies (the base set), in the model's order.
        log_det: log det of the scaled information matrix. min_sv: its smallest singular value (sqrt of the
            smallest eigenvalue). condition: the scaled Jacobian's condition number.
        candidates: the size of the candidate pool. seed: its seed.
    """

    robot: str
    columns: tuple[str, ...]
    q: np.ndarray
    predicted: np.ndarray
    criterion: Criterion
    identified: tuple[str, ...]
    log_det: float
    min_sv: float
    condition: float
    candidates: int
    seed: int

    def summary(self, units: object = None) -> str:
        """How many configurations, the criterion, what they identify and how well."""
        return (f"ExperimentPlan for {self.robot!r}: {len(self.q)} configurations ({self.criterion.value}-optimal, "
                f"from {self.candidates} candidates, seed {self.seed}); identifies {len(self.identified)} errors: "
                f"{', '.join(self.identified)}; condition {self.condition:.4g}, smallest singular value "
                f"{self.min_sv:.4g}")  # fmt: skip

    def to_csv(self) -> str:
        """A measurement file template: the configurations and the nominal positions, to replace by measured ones."""
        head = [f"# scara-pin calibrate --plan {len(self.q)}: robot {self.robot!r}, criterion {self.criterion.value} "
                f"(log det {self.log_det:.6g}, smallest singular value {self.min_sv:.6g}, "
                f"condition {self.condition:.6g})",
                "# x, y, z (and yaw) are the NOMINAL model's, base frame: replace them by the measured values",
                ",".join(self.columns)]  # fmt: skip
        rows = [",".join(repr(float(v)) for v in (*q, *p)) for q, p in zip(self.q, self.predicted)]
        return "\n".join(head + rows) + "\n"

    def to_dict(self) -> dict[str, object]:
        """JSON-ready (SI units)."""
        return {"robot": self.robot, "units": {"length": "m", "angle": "rad"}, "criterion": self.criterion.value,
                "columns": list(self.columns), "q": self.q.tolist(), "predicted": self.predicted.tolist(),
                "identified": list(self.identified), "log_det": self.log_det, "min_sv": self.min_sv,
                "condition": self.condition, "candidates": self.candidates, "seed": self.seed}  # fmt: skip


def _scores(M: np.ndarray, A: np.ndarray) -> np.ndarray:
    """Per candidate block A[c] (rows x r): log det(I + A M^-1 A^T), the gain in log det M of adding it."""
    B = (A @ np.linalg.inv(M)) @ np.transpose(A, (0, 2, 1)) + np.eye(A.shape[1])
    sign, logdet = np.linalg.slogdet(B)
    return np.where(sign > 0, logdet, -np.inf)


def _min_sv(M: np.ndarray) -> float:
    return math.sqrt(max(float(np.linalg.eigvalsh(M)[0]), 0.0))


def plan_experiment(
    robot: RobotModel,
    n: int,
    *,
    criterion: Criterion = Criterion.DET,
    yaw: bool = False,
    frame: MeasurementFrame = MeasurementFrame.BASE,
    groups: Iterable[Group] = ALL_GROUPS,
    seed: int = 0,
    candidates: int | None = None,
) -> ExperimentPlan:
    """``n`` joint configurations inside the limits that make the identification well conditioned.

    Args:
        robot: the nominal robot.
        n: how many poses to measure (at least the structural count of identifiable errors).
        criterion: what to maximise (see the module docstring).
        yaw: whether the tool's yaw will be measured too.
        frame: the frame the positions will be measured in.
        groups: the error groups to identify.
        seed: the seed of the candidate pool.
        candidates: the pool's size (default ``20 n``, at least 500, at most MAX_CANDIDATES).

    Raises:
        InvalidInputError: ``n`` above MAX_PLAN_POSES, or fewer than the identifiable errors (naming both).
    """
    n = check_count("poses of the plan", n, MAX_PLAN_POSES)
    chain = ChainModel.from_robot(robot, frame=frame, yaw=yaw, groups=groups)
    count = structural_count(chain, seed)
    if n < count:
        raise InvalidInputError(f"--plan {n}: {n} poses for {count} identifiable parameters: at least {count} "
                                f"poses are needed (a few times more average the measurement noise)")  # fmt: skip
    k = candidates if candidates is not None else min(max(20 * n, 500), MAX_CANDIDATES)
    k = max(check_count("candidate poses", k, MAX_PLAN_WORK), n)
    check_count(f"the plan's work ({n} poses x {k} candidates)", n * k, MAX_PLAN_WORK, "ask fewer candidates or poses")
    rng = np.random.default_rng(seed)
    pool = random_poses(robot, k, rng)
    _, J = chain.predict(np.zeros(chain.size), chain.pinocchio_q(pool), pin.SE3.Identity())
    rows = chain.rows_per_pose
    if yaw:
        J = J.copy()  # type: ignore[union-attr]
        J[3::4] *= 0.1
    kept = list(identify(J).kept)  # type: ignore[arg-type]
    W = J[:, kept]  # type: ignore[index]
    W = W / (np.linalg.norm(W, axis=0) / math.sqrt(k))  # unit RMS per pose
    A = W.reshape(k, rows, len(kept))
    r = len(kept)
    M = _RIDGE * np.eye(r)
    chosen: list[int] = []
    free = np.ones(k, dtype=bool)
    for _ in range(n):
        gain = np.where(free, _scores(M, A), -np.inf)
        c = int(np.argmax(gain))
        chosen.append(c)
        free[c] = False
        M = M + A[c].T @ A[c]
    for _ in range(EXCHANGE_PASSES):
        improved = False
        for slot, c in enumerate(chosen):
            rest = M - A[c].T @ A[c]
            if criterion is Criterion.DET:  # the best candidate in c's place, if it does better than c
                gain = np.where(free, _scores(rest, A), -np.inf)
                best = int(np.argmax(gain))
                better = gain[best] > _scores(rest, A[c : c + 1])[0] + 1e-12
            else:
                current = _min_sv(M)
                trials = rng.choice(np.flatnonzero(free), size=min(EXCHANGE_TRIALS, int(free.sum())), replace=False)
                values = [_min_sv(rest + A[t].T @ A[t]) for t in trials]
                best = int(trials[int(np.argmax(values))])
                better = max(values) > current * (1 + 1e-12)
            if better:
                chosen[slot], free[best], free[c] = best, False, True
                M = rest + A[best].T @ A[best]
                improved = True
        if not improved:
            break
    q = pool[chosen]
    names = chain.names()
    nominal, _ = chain.predict(np.zeros(chain.size), chain.pinocchio_q(q), pin.SE3.Identity(), jacobian=False)
    S = A[chosen].reshape(-1, r)
    sv = np.linalg.svd(S, compute_uv=False)
    sign, logdet = np.linalg.slogdet(S.T @ S)
    return ExperimentPlan(
        robot=robot.name, columns=measurement_columns(robot.dof) + (("yaw",) if yaw else ()), q=q,
        predicted=nominal, criterion=criterion, identified=tuple(names[i] for i in kept),
        log_det=float(logdet) if sign > 0 else -math.inf, min_sv=float(sv[-1]),
        condition=float(sv[0] / sv[-1]) if sv[-1] > 0 else math.inf, candidates=k, seed=seed,
    )  # fmt: skip
