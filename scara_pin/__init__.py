"""scara-pin: exact kinematics, motion and pictures for 4-DOF Schoenflies robots (SCARA first).

Describe a robot once (yaml parameters -> xacro -> URDF), load it into Pinocchio, and get forward
kinematics and Jacobians from the model. Heavy optional packages (toppra, matplotlib, yourdfpy, meshcat)
are imported only by the functions that need them.
"""

import logging

from ._version import __version__
from .description import (
    JOINT_NAMES,
    PARAMETER_NAMES,
    JointLimits,
    RobotParameters,
    available_robots,
    generate_urdf,
    load_parameters,
    urdf_dir,
)
from .errors import (
    DescriptionError,
    InfeasibleError,
    InvalidInputError,
    NoSolutionError,
    ParameterError,
    ScaraError,
    UnknownRobotError,
    UrdfError,
)
from .model import Kinematics, Robot, pose_from_placement
from .robots import kinematics_for, load_robot, load_urdf, robot_from_urdf

__all__ = [
    "JOINT_NAMES",
    "PARAMETER_NAMES",
    "DescriptionError",
    "InfeasibleError",
    "InvalidInputError",
    "JointLimits",
    "Kinematics",
    "NoSolutionError",
    "ParameterError",
    "Robot",
    "RobotParameters",
    "ScaraError",
    "UnknownRobotError",
    "UrdfError",
    "__version__",
    "available_robots",
    "generate_urdf",
    "kinematics_for",
    "load_parameters",
    "load_robot",
    "load_urdf",
    "pose_from_placement",
    "robot_from_urdf",
    "urdf_dir",
]

logging.getLogger(__name__).addHandler(logging.NullHandler())
