"""Calibration without a tracker: measure a perturbed copy of the robot (seeded), to try the whole loop.

The copy is the robot's own URDF text with EVERY joint's ``<origin>`` changed (the fixed base and tool joints
too), each error drawn uniformly (seeded) within the sizes a real robot shows:

- its ``xyz`` moved by up to ``POSITION`` [m] along each axis;
- its rotation turned, ``R = R0 exp(B w)`` (``B``: the joint frame's basis whose last axis is the joint's own,
  z for a fixed joint), by up to ``TILT`` [rad] about each of the two axes across the joint's (the tilts) and
  up to ``OFFSET`` [rad] about the joint's own axis (its zero offset).

The tool is "measured" there: its position in the copy's ``base`` frame (and its yaw) at the readings asked,
plus Gaussian noise (``noise`` [m] per coordinate; ``noise / yaw_weight`` [rad] on the yaw). The readings are
the ones asked, as a controller would report them.
"""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from ..errors import ParameterError
from ..kinematics.planar2r import wrap
from ..model import RobotModel
from .chain import read_triple, rotation_basis
from .measurements import Measurements, measurement_columns
from .urdf_edit import edit_origins

__all__ = ["NOISE", "OFFSET", "POSITION", "TILT", "Simulation", "perturbed_urdf", "simulate"]

POSITION = 1e-3
"""[m] the largest change of each coordinate of a joint origin's ``xyz``."""
TILT = math.radians(0.1)
"""[rad] the largest turn of a joint origin about each axis across the joint's."""
OFFSET = math.radians(0.5)
"""[rad] the largest turn of a joint origin about the joint's own axis (its zero offset)."""
NOISE = 1e-5
"""[m] the default measurement noise per coordinate (a laser tracker's, about 10 um)."""


def perturbed_urdf(urdf: str, rng: np.random.Generator) -> tuple[str, dict[str, tuple[np.ndarray, np.ndarray]]]:
    """``urdf`` with every joint's origin perturbed (see the module docstring), and the errors made.

    Returns:
        The URDF text, and per joint (URDF order) its ``xyz`` change [m] and its rotation error ``w`` [rad]
        in the joint frame's basis (two tilts, then the turn about the joint's axis).
    """
    edits: dict[str, tuple[np.ndarray | None, np.ndarray | None]] = {}
    errors: dict[str, tuple[np.ndarray, np.ndarray]] = {}
    for el in ET.fromstring(urdf).findall("joint"):
        name = el.get("name", "")
        origin = el.find("origin")
        xyz, rpy = read_triple(origin, "xyz"), read_triple(origin, "rpy")
        axis = np.array([0.0, 0.0, 1.0])  # a fixed joint's: its frame's z
        if el.get("type") in ("revolute", "continuous", "prismatic"):
            axis_el = el.find("axis")
            axis = read_triple(axis_el, "xyz") if axis_el is not None else np.array([1.0, 0.0, 0.0])  # URDF's default
            axis = axis / np.linalg.norm(axis)
        dp = rng.uniform(-POSITION, POSITION, 3)
        w = np.array([rng.uniform(-TILT, TILT), rng.uniform(-TILT, TILT), rng.uniform(-OFFSET, OFFSET)])
        R = pin.rpy.rpyToMatrix(*rpy) @ pin.exp3(rotation_basis(axis)[0] @ w)
        edits[name] = (xyz + dp, np.asarray(pin.rpy.matrixToRpy(R), dtype=float))
        errors[name] = (dp, w)
    return edit_origins(urdf, edits), errors


@dataclass(frozen=True, eq=False)
class Simulation:
    """Measurements of a perturbed copy of a robot.

    Attributes:
        robot: the nominal robot's name.
        truth: the perturbed copy (what the calibration should find).
        errors: per URDF joint, its ``xyz`` change [m] and its rotation error [rad] (tilts, then the turn about
            its axis), as :func:`perturbed_urdf` made them.
        measurements: the readings asked and the copy's measured tool positions (and yaws), with noise.
        noise: [m] the noise per coordinate. seed: the seed of the errors and of the noise.
    """

    robot: str
    truth: RobotModel
    errors: dict[str, tuple[np.ndarray, np.ndarray]]
    measurements: Measurements
    noise: float
    seed: int

    def to_csv(self) -> str:
        """A measurement file (``calibrate --measurements`` reads it), the errors made in its comments."""
        m = self.measurements
        lines = [
            f"# scara-pin calibrate --simulate: robot {self.robot!r}, every joint origin perturbed (seed {self.seed}: "
            f"xyz up to +/-{POSITION * 1e3:g} mm, tilts up to {math.degrees(TILT):g} deg, zero offsets up to "
            f"{math.degrees(OFFSET):g} deg), measured in its base frame with {self.noise:g} m of noise per coordinate",
            "# the errors made (xyz change in mm; rotation in deg: two tilts, then the turn about the joint's axis):",
        ]
        for joint, (dp, w) in self.errors.items():
            xyz = " ".join(f"{v * 1e3:+.4f}" for v in dp)
            rot = " ".join(f"{math.degrees(v):+.4f}" for v in w)
            lines.append(f"#   {joint}: xyz {xyz} mm; rotation {rot} deg")
        columns = measurement_columns(m.q.shape[1]) + (("yaw",) if m.yaw is not None else ())
        lines.append(",".join(columns))
        table = np.column_stack([m.q, m.position] + ([m.yaw] if m.yaw is not None else []))
        lines.extend(",".join(repr(float(v)) for v in row) for row in table)
        return "\n".join(lines) + "\n"


def simulate(robot: RobotModel, readings: np.ndarray, *, seed: int = 0, noise: float = NOISE, yaw: bool = False,
             yaw_weight: float = 0.1) -> Simulation:  # fmt: skip
    """Measure the tool of a perturbed copy of ``robot`` at ``readings`` (see the module docstring).

    Args:
        robot: the nominal robot.
        readings: (n, dof) joint readings [rad, m] (a plan's poses, say).
        seed: the seed of the errors and of the noise.
        noise: [m] the standard deviation of the noise on each coordinate (0: exact measurements).
        yaw: measure the tool's yaw too (noise ``noise / yaw_weight`` [rad]).
        yaw_weight: [m/rad] the ratio of the position noise to the yaw noise.

    Raises:
        ParameterError: a negative or non-finite noise, a yaw weight that is not > 0.
        InvalidInputError: readings that do not fit the robot.
    """
    if not (isinstance(noise, (int, float)) and math.isfinite(noise) and noise >= 0):
        raise ParameterError("noise", noise, "must be a finite number >= 0 [m]")
    if not (isinstance(yaw_weight, (int, float)) and math.isfinite(yaw_weight) and yaw_weight > 0):
        raise ParameterError("yaw_weight", yaw_weight, "must be a finite number > 0 [m/rad]")
    q = np.array(readings, dtype=float, ndmin=2)
    Measurements(q, np.zeros((len(q), 3))).check(robot)
    rng = np.random.default_rng(seed)
    urdf, errors = perturbed_urdf(robot.urdf, rng)
    truth = type(robot)(urdf, base_frame=robot.base_frame, tool_frame=robot.tool_frame,
                        origin=f"{robot.name} (perturbed)")  # fmt: skip
    poses = np.array([truth.tool_pose(x) for x in q])
    position = poses[:, :3] + rng.normal(0.0, noise, (len(q), 3))
    measured_yaw = np.array([wrap(float(v)) for v in poses[:, 3] + rng.normal(0.0, noise / yaw_weight, len(q))]) \
        if yaw else None
    return Simulation(robot.name, truth, errors, Measurements(q, position, measured_yaw), float(noise), seed)
