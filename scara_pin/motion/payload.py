"""A payload carried by the tool, added to a copy of the robot's Pinocchio model (for the RNEA torques).

Every function that takes a payload takes a :class:`Payload` or a mass in kilograms (``payload=2.0``: 2 kg at
the tool frame's origin), through :func:`as_payload`.

The payload is a point mass ``mass`` at ``com``, a point given in the TOOL frame (``tool0``). It is added
to the inertia of the joint that carries the tool frame (the wrist), as ``pin.Inertia(mass, com, 0)``
moved by the tool frame's placement in that joint. The robot itself is never modified: :func:`with_payload`
returns a shallow copy whose ``model`` (and ``data``) are new; kinematics, limits and IK are shared.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
import pinocchio as pin

from ..errors import ParameterError

if TYPE_CHECKING:
    from ..model import RobotModel

__all__ = ["Payload", "PayloadLike", "as_payload", "with_payload"]


@dataclass(frozen=True)
class Payload:
    """A point-mass payload held by the tool.

    Attributes:
        mass: [kg], >= 0.
        com: (x, y, z) of its centre of mass in the tool frame [m].
    """

    mass: float = 0.0
    com: tuple[float, float, float] = (0.0, 0.0, 0.0)

    def __post_init__(self) -> None:
        try:
            m = float(self.mass)
        except (TypeError, ValueError):
            raise ParameterError("payload mass", self.mass, "must be a number", "kg") from None
        if not (math.isfinite(m) and m >= 0.0):
            raise ParameterError("payload mass", m, "must be finite and >= 0", "kg")
        try:
            c = np.array(self.com, dtype=float)
        except (TypeError, ValueError):
            raise ParameterError("payload com", self.com, "must be 3 numbers X Y Z", "m") from None
        if c.shape != (3,) or not np.isfinite(c).all():
            raise ParameterError("payload com", self.com, "must be 3 finite numbers X Y Z (tool frame)", "m")
        object.__setattr__(self, "mass", m)
        object.__setattr__(self, "com", tuple(float(v) for v in c))

    def to_dict(self) -> dict[str, object]:
        """JSON-ready: {"mass": kg, "com": [x, y, z] m in the tool frame}."""
        return {"mass": self.mass, "com": list(self.com), "frame": "tool0"}


PayloadLike = Payload | float | int | None
"""What a ``payload`` argument accepts: a :class:`Payload`, a mass [kg] (at the tool frame's origin), or None."""


def as_payload(payload: PayloadLike) -> Payload:
    """``payload`` as a :class:`Payload`: a number is a mass [kg] at the tool frame's origin; None is none.

    Raises:
        ParameterError: a mass that is not a finite number >= 0, or something else than a number or a Payload.
    """
    if payload is None:
        return Payload()
    if isinstance(payload, Payload):
        return payload
    if isinstance(payload, bool) or not isinstance(payload, (int, float, np.integer, np.floating)):
        raise ParameterError("payload", payload, "must be a mass in kg or a Payload(mass, com)")
    return Payload(float(payload))


def with_payload(robot: RobotModel, payload: PayloadLike) -> RobotModel:
    """The robot carrying ``payload``: rebuilt on a copy of its Pinocchio model (``robot`` is untouched).

    ``payload``: a :class:`Payload` or a mass [kg] (:func:`as_payload`). Without a payload (None or zero mass)
    the robot itself is returned.
    """
    payload = as_payload(payload)
    if payload.mass == 0.0:
        return robot
    model = pin.Model(robot.model)  # a deep copy of the model
    frame = model.frames[robot.tool_id]
    joint = frame.parentJoint
    added = frame.placement.act(pin.Inertia(payload.mass, np.array(payload.com), np.zeros((3, 3))))
    model.inertias[joint] = model.inertias[joint] + added
    return robot.with_model(model)
