"""scara-pin: exact kinematics, motion and pictures for 4-DOF Schoenflies robots (SCARA first).

Describe a robot once (yaml parameters -> xacro -> URDF), load it into Pinocchio, and get forward
kinematics and Jacobians from the model. Heavy optional packages (toppra, matplotlib, yourdfpy, meshcat)
are imported only by the functions that need them.
"""

import logging
from pathlib import Path
from typing import TYPE_CHECKING, Any

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
from .model import Kinematics, RobotModel, pose_from_placement
from .robots import Robot, kinematics_for, load_robot, load_urdf, robot_from_urdf

if TYPE_CHECKING:
    from .cell import Cell

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
    "RobotModel",
    "RobotParameters",
    "ScaraError",
    "UnknownRobotError",
    "UrdfError",
    "__version__",
    "available_robots",
    "generate_urdf",
    "kinematics_for",
    "load_cell",
    "load_parameters",
    "load_robot",
    "load_urdf",
    "pose_from_placement",
    "robot_from_urdf",
    "sweep",
    "urdf_dir",
]



def load_cell(path: str | Path, **kwargs: Any) -> "Cell":
    """Read a cell file (obstacles, carried part, margin): :func:`scara_pin.cell.load_cell` (imported on first use)."""
    from .cell import load_cell as _load_cell

    return _load_cell(path, **kwargs)


def __getattr__(name: str) -> Any:
    """``scara_pin.sweep``: the sweeps' package, imported on first use (it is callable: ``scara_pin.sweep(spec)``)."""
    if name == "sweep":
        import importlib

        return importlib.import_module(".sweep", __name__)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


logging.getLogger(__name__).addHandler(logging.NullHandler())
