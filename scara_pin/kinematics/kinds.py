"""The kinematics of a robot's kind: which closed form serves ``robot.kinematics``.

A :class:`~scara_pin.model.RobotModel` is the Pinocchio model (FK, frames, Jacobians); what it knows of inverse
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

import math
from typing import TYPE_CHECKING

import numpy as np

from ..errors import InvalidInputError

if TYPE_CHECKING:
    from ..model import Kinematics, RobotModel

__all__ = ["kinematics_for", "what_arm"]


def kinematics_for(robot: RobotModel) -> Kinematics:
    """The kinematics object of the robot's kind (``robot.kind``) and joint count (``robot.dof``).

    Raises:
        InvalidInputError: no kinematics for the robot's kind.
        UrdfError: the kind's closed form refuses the model (e.g. ``NotScaraError`` naming the joint).
    """
    if robot.kind == "palletizer":
        from .palletizer_kinematics import PalletizerKinematics

        return PalletizerKinematics.from_robot(robot)
    if robot.kind != "scara":
        raise InvalidInputError(f"robot {robot.name!r} is of kind {robot.kind!r}: no kinematics for it")
    from .scara_geometry import NotScaraError

    try:
        if robot.dof == 3:
            from .scara3_kinematics import Scara3Kinematics

            return Scara3Kinematics.from_robot(robot)
        from .scara_kinematics import ScaraKinematics

        return ScaraKinematics.from_robot(robot)
    except NotScaraError as exc:
        what = what_arm(robot)
        if what is None:
            raise
        raise NotScaraError(f"{exc}; {what}") from None


def what_arm(robot: RobotModel) -> str | None:
    """What an arm the SCARA closed form refuses is, when its layout says (else None), and what applies to it.

    - three revolute joints, a vertical waist and two parallel horizontal ones: an R-R-R arm without a wrist;
    - a palletizer's layout (:func:`scara_pin.chain.palletizer_layout`) whose flange does not stay level:
      not recognised as a palletizer, with the reason (the levelling parallelogram is not modelled).
    """
    from ..chain import AXIS_TOL, LEVEL_PROBES, flange_pitch, palletizer_layout

    axes = robot.axes
    names = [a.name for a in axes]
    if palletizer_layout(axes):
        pitch = max(flange_pitch(robot.tool_placement, q) for q in LEVEL_PROBES)
        return (f"it has a palletizer's layout ({names[0]} a vertical waist, {names[1]} and {names[2]} parallel "
                f"horizontal arm joints, {names[3]} a vertical flange) but is not recognised as a palletizer: its "
                f"flange tilts by up to {math.degrees(pitch):.3g} deg as the arms move, where a palletizer's "
                f"levelling parallelogram keeps it level; the file does not model that parallelogram (no <mimic> "
                f"joint: passive joints following {names[1]} and {names[2]} with multiplier -1, as scara-pin's own "
                "palletizer URDF has); the numeric IK reaches x, y, z, yaw with the flange tilted as the file "
                "models it")  # fmt: skip
    if len(axes) == 3 and all(a.kind == "revolute" for a in axes) and axes[0].tilt <= AXIS_TOL \
            and all(abs(a.tilt - math.pi / 2) <= AXIS_TOL for a in axes[1:]) \
            and float(np.linalg.norm(np.cross(axes[1].axis, axes[2].axis))) <= AXIS_TOL:  # fmt: skip
        return (f"it is an R-R-R arm without a wrist ({names[0]} a vertical waist, {names[1]} and {names[2]} "
                "parallel horizontal joints), neither a SCARA (vertical axes and a lift) nor a palletizer (four "
                "joints, the flange kept level): fk, jacobian, joint-space traj, view, check and the numeric IK "
                "of its tool point (x, y, z) apply; the closed form, workspace and cycle do not")  # fmt: skip
    return None
