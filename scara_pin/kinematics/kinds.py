"""The kinematics of a robot's kind: which closed form serves ``robot.kinematics``.

A :class:`~scara_pin.model.Robot` is the Pinocchio model (FK, frames, Jacobians); what it knows of inverse
kinematics is one object of the :class:`~scara_pin.model.Kinematics` protocol, built from the loaded
model by its kind (:func:`kinematics_for`, the factory :func:`scara_pin.load_robot` gives the robot):

- :class:`~scara_pin.kinematics.scara_kinematics.ScaraKinematics`: a 4-joint SCARA;
- :class:`~scara_pin.kinematics.scara3_kinematics.Scara3Kinematics`: a SCARA without a wrist (3 joints);
- :class:`~scara_pin.kinematics.palletizer_kinematics.PalletizerKinematics`: the palletizer.

Each reads its geometry from the model, so the URDF is the single source of truth. The kind's module is
imported when the robot first needs it (``robot.ik``, ``robot.kinematics``): forward kinematics alone
(``scara-pin fk``) imports none of them.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from ..errors import InvalidInputError

if TYPE_CHECKING:
    from ..model import Kinematics, Robot

__all__ = ["kinematics_for"]


def kinematics_for(robot: Robot) -> Kinematics:
    """The kinematics object of the robot's kind (``robot.kind``) and joint count (``robot.dof``).

    Raises:
        InvalidInputError: no kinematics for the robot's kind.
        UrdfError: the kind's closed form refuses the model (e.g. ``NotScaraError`` naming the joint).
    """
    if robot.kind == "palletizer":
        from .palletizer_kinematics import PalletizerKinematics

        return PalletizerKinematics.from_robot(robot)
    if robot.kind == "scara" and robot.dof == 3:
        from .scara3_kinematics import Scara3Kinematics

        return Scara3Kinematics.from_robot(robot)
    if robot.kind == "scara":
        from .scara_kinematics import ScaraKinematics

        return ScaraKinematics.from_robot(robot)
    raise InvalidInputError(f"robot {robot.name!r} is of kind {robot.kind!r}: no kinematics for it")
