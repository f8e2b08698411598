"""Cross-validation of the closed-form IK against Pinocchio (FK and numeric IK).

The closed form is the robot kind's (``robot.kinematics``): the SCARA's or the palletizer's
geometric IK (on the coupled model with its mimic joints).

For N configurations sampled inside the joint limits (seeded), with target = FK(q) from Pinocchio:

1. every closed-form solution reproduces the target under Pinocchio FK to ``POSE_TOL`` (1e-9 m / rad);
2. the sampled q is among the closed-form solutions (to ``Q_TOL``, 1e-9; at any of a solution's turns);
3. the numeric IK (:mod:`scara_pin.kinematics.numeric`) from the default start (middle of the joint ranges)
   converges to the target and coincides (to ``Q_TOL``) with a closed-form solution of the same branch.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from ..model import RobotModel
from .numeric import solve_numeric

__all__ = ["POSE_TOL", "Q_TOL", "ValidationReport", "validate_ik"]

POSE_TOL = 1e-9
"""[m, rad] largest pose error of a closed-form solution under Pinocchio FK."""
Q_TOL = 1e-9
"""[rad, m] largest joint difference for two configurations to count as the same."""


@dataclass(kw_only=True)
class ValidationReport:
    """Counts, worst errors and timings of :func:`validate_ik`.

    Attributes:
        robot: robot name. samples: N. seed: the sampling seed.
        solutions: closed-form solutions checked in all.
        fk_fail / sample_missing / numeric_fail / numeric_mismatch: failures of checks 1, 2, 3.
        worst_pose_error: largest pose error of a closed-form solution [m or rad].
        worst_sample_distance: largest distance from a sampled q to its nearest solution.
        worst_numeric_distance: largest distance from a numeric solution to its closed-form twin.
        time_closed, time_numeric: mean seconds per call.
        failures: the first few failures, described.
    """

    robot: str
    samples: int
    seed: int
    solutions: int = 0
    fk_fail: int = 0
    sample_missing: int = 0
    numeric_fail: int = 0
    numeric_mismatch: int = 0
    worst_pose_error: float = 0.0
    worst_sample_distance: float = 0.0
    worst_numeric_distance: float = 0.0
    time_closed: float = 0.0
    time_numeric: float = 0.0
    failures: list[str] = field(default_factory=list)

    @property
    def ok(self) -> bool:
        """All three checks held for every sample."""
        return self.fk_fail + self.sample_missing + self.numeric_fail + self.numeric_mismatch == 0

    def table(self) -> str:
        """A plain-text summary table."""
        rows = [
            ("robot", self.robot, ""),
            ("samples (seed)", f"{self.samples} ({self.seed})", ""),
            ("closed-form solutions checked", str(self.solutions), ""),
            ("1. solutions off target > 1e-9", str(self.fk_fail), f"worst {self.worst_pose_error:.3g}"),
            ("2. sampled q not among solutions", str(self.sample_missing), f"worst {self.worst_sample_distance:.3g}"),
            ("3a. numeric IK not converged", str(self.numeric_fail), ""),
            ("3b. numeric != closed form (same branch)", str(self.numeric_mismatch),
             f"worst {self.worst_numeric_distance:.3g}"),
            ("closed form per call", f"{self.time_closed * 1e6:.1f} us", ""),
            ("numeric IK per call", f"{self.time_numeric * 1e6:.1f} us", ""),
            ("result", "PASS" if self.ok else "FAIL", ""),
        ]  # fmt: skip
        width = max(len(r[0]) for r in rows)
        lines = [f"{a:<{width}}  {b:>16}  {c}".rstrip() for a, b, c in rows]
        return "\n".join(lines + [f"  {f}" for f in self.failures])


def pose_error(robot: RobotModel, q: np.ndarray, target: np.ndarray) -> float:
    """The largest of |FK(q) - target| over (x, y, z, yaw), the yaw difference wrapped to [-pi, pi) [m or rad]."""
    e = robot.tool_pose(q) - target
    e[3] = (e[3] + math.pi) % (2 * math.pi) - math.pi
    return float(np.abs(e).max())


def validate_ik(
    robot: RobotModel, samples: int = 1000, seed: int = 0, max_failures: int = 10,
    progress: Callable[[int], object] | None = None,
) -> ValidationReport:  # fmt: skip
    """Run the three checks on ``samples`` seeded configurations (see the module docstring).

    ``progress(1)`` is called after each sample (a progress bar's ``update``, say).
    """
    kin = robot.kinematics
    rng = np.random.default_rng(seed)
    lo, hi = np.asarray(robot.limits.lower), np.asarray(robot.limits.upper)
    report = ValidationReport(robot=robot.name, samples=samples, seed=seed)
    t_closed = t_numeric = 0.0

    def fail(text: str) -> None:
        if len(report.failures) < max_failures:
            report.failures.append(text)

    for _ in range(samples):
        q = rng.uniform(lo, hi)
        target = robot.tool_pose(q)
        t0 = time.perf_counter()
        result = kin.solve(target)
        t_closed += time.perf_counter() - t0
        report.solutions += len(result.solutions)
        for sol in result.solutions:
            err = pose_error(robot, sol.q, target)
            report.worst_pose_error = max(report.worst_pose_error, err)
            if err > POSE_TOL:
                report.fk_fail += 1
                fail(f"q = {q.tolist()}: solution {sol.q.tolist()} ({sol.branch}) is {err:.3g} off target")
        dist = min((s.distance(q) for s in result.solutions), default=math.inf)
        report.worst_sample_distance = max(report.worst_sample_distance, dist)
        if dist > Q_TOL:
            report.sample_missing += 1
            fail(f"q = {q.tolist()}: not among the {len(result.solutions)} solutions ({result.message})")
        t0 = time.perf_counter()
        num = solve_numeric(robot, target)
        t_numeric += time.perf_counter() - t0
        if not num.success:
            report.numeric_fail += 1
            fail(f"q = {q.tolist()}: numeric IK did not converge (residual {num.residual:.3g})")
            continue
        branch = kin.branch_of(num.q)
        twins = [s for s in result.solutions if s.matches(branch)]
        dist = min((s.distance(num.q) for s in twins), default=math.inf)
        report.worst_numeric_distance = max(report.worst_numeric_distance, dist)
        if dist > Q_TOL:
            report.numeric_mismatch += 1
            fail(f"q = {q.tolist()}: numeric {num.q.tolist()} ({branch}) is {dist:.3g} from every {branch} solution")
        if progress is not None:
            progress(1)
    report.time_closed = t_closed / max(samples, 1)
    report.time_numeric = t_numeric / max(samples, 1)
    return report
