"""The cell: obstacles around the robot, the robot's own collision geometry, what it carries, and distances.

A layer just above :mod:`scara_pin.model`: kinematics, the workspace and the planners ask it. A
:class:`Cell` is data (obstacles in the robot's ``base`` frame, a margin, the carried part, pairs never
checked), read from a file by :func:`load_cell` (:mod:`~scara_pin.cell.files`: YAML, URDF or xacro). A
:class:`Scene` puts a robot in a cell (:func:`scene`): the pairs checked (the robot's links and the
carried part against every obstacle, the self-collision pairs chosen as MoveIt's setup assistant does,
:mod:`~scara_pin.cell.geometry`) and their distances, coal's, exact for the primitives.
``robot.distances(q, cell)`` is the short way.
"""

from .cell import DEFAULT_MARGIN, Cell, Obstacle
from .files import FORMAT, load_cell, parse_cell
from .geometry import RobotGeometry, SelfPairs, robot_geometry
from .scene import Distances, InCollisionError, Pair, PairDistance, Scene, describe, scene
from .shapes import Shape

__all__ = [
    "DEFAULT_MARGIN",
    "FORMAT",
    "Cell",
    "Distances",
    "InCollisionError",
    "Obstacle",
    "Pair",
    "PairDistance",
    "RobotGeometry",
    "Scene",
    "SelfPairs",
    "Shape",
    "describe",
    "load_cell",
    "parse_cell",
    "robot_geometry",
    "scene",
]
