"""The palletizer kind: its closed form (:mod:`scara_pin.kinematics.palletizer`) behind the kinematics protocol.

:class:`PalletizerKinematics` is what ``robot.kinematics`` is for a double-parallelogram palletizer (see
:class:`~scara_pin.model.Kinematics`); its arm-plane envelope is :mod:`scara_pin.workspace.palletizer`,
imported on first use.
"""

from __future__ import annotations

import enum
from typing import TYPE_CHECKING, Any

import numpy as np

from ..ik_results import BatchIKResult, IKResult
from . import palletizer
from .palletizer_model import read

if TYPE_CHECKING:
    from .._typing import ArrayLike
    from ..model import RobotModel

__all__ = ["PalletizerKinematics"]


class PalletizerKinematics:
    """The palletizer's kinematics (see :mod:`scara_pin.kinematics.palletizer`).

    Attributes:
        geometry: the geometry read from the model.
    """

    kind: str = "palletizer"
    branches: tuple[str, ...] = palletizer.BRANCHES
    status: type[enum.IntEnum] = palletizer.PalletizerIKStatus
    geometry: palletizer.PalletizerGeometry

    def __init__(self, geometry: palletizer.PalletizerGeometry) -> None:
        self.geometry = geometry

    @classmethod
    def from_robot(cls, robot: RobotModel) -> PalletizerKinematics:
        """Read the geometry from the robot's model; NotPalletizerError says where it departs."""
        return cls(read(robot))

    def solve(self, target: Any, *, branch: str = "all", reference: ArrayLike | None = None,
              all_turns: bool = False) -> IKResult:  # fmt: skip
        """:func:`scara_pin.kinematics.palletizer.solve`."""
        return palletizer.solve(self.geometry, target, branch=branch, reference=reference, all_turns=all_turns)

    def nearest(self, target: Any, reference: ArrayLike | None = None, *, weights: ArrayLike | None = None,
                branch: str = "all") -> np.ndarray:  # fmt: skip
        """:func:`scara_pin.kinematics.palletizer.solve_nearest`."""
        return palletizer.solve_nearest(self.geometry, target, reference, weights=weights, branch=branch)

    def batch(self, targets: ArrayLike, reference: ArrayLike | None = None, *, branch: str = "nearest"
              ) -> BatchIKResult:  # fmt: skip
        """:func:`scara_pin.kinematics.palletizer.solve_batch`."""
        return palletizer.solve_batch(self.geometry, targets, branch=branch, reference=reference)

    def branch_of(self, q: ArrayLike) -> str:
        """:func:`scara_pin.kinematics.palletizer.branch_of`."""
        return palletizer.branch_of(q, self.geometry)

