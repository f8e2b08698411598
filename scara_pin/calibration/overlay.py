"""The yaml overlay of a configured robot: the kinematic parameters a calibration changes.

A configured robot's URDF is generated from its yaml parameters (``l1``, ``d2``, ``tool_x``, ...). Which
``<origin>`` numbers each parameter sets is read from the generator itself, never written here: each
kinematic parameter is moved by ``STEP`` and the URDF generated again, which gives the (linear) map from the
parameters to the origins of the calibrated joints. The overlay is the least-squares change of the
parameters that reproduces the calibrated origins; what no parameter carries (tilts, zero offsets, lateral
offsets) is listed, and the measurements' residual with the overlay alone is computed on the model it
generates, so the user sees what the overlay loses against the calibrated URDF.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from dataclasses import dataclass

import numpy as np

from ..description import SCHEMAS, generate_urdf
from ..errors import InvalidInputError
from ..kinematics.planar2r import wrap
from .chain import ChainModel, read_triple
from .results import CalibrationResult, ResidualStats

__all__ = ["STEP", "YamlOverlay", "yaml_overlay"]

STEP = 1e-3
"""[m or rad] the move of each parameter that reads its effect on the origins (the map is linear)."""
_EXPRESSED = 1e-12
"""[m or rad] an origin change the overlay misses by more than this is not expressible in the yaml."""


@dataclass(frozen=True)
class YamlOverlay:
    """The changed kinematic parameters of a configured robot.

    Attributes:
        robot: the robot's name.
        values: the changed parameters (flat names, as ``--set`` takes them) with their calibrated values [SI].
        unexpressed: the calibrated origin components no yaml parameter carries (the calibrated URDF does).
        residual: the measurements' residual with the overlay alone (rows used by the fit).
        calibrated: the calibrated URDF's residual, for comparison.
    """

    robot: str
    values: dict[str, float]
    unexpressed: tuple[str, ...]
    residual: ResidualStats
    calibrated: ResidualStats

    def to_yaml(self) -> str:
        """The overlay as yaml (flat names), with comments saying how to use it and what it leaves out."""
        sets = " ".join(f"--set {k}={v!r}" for k, v in self.values.items())
        lines = [
            f"# scara-pin calibrate: the changed kinematic parameters of robot {self.robot!r} (SI units: m, rad)",
            f"# use: --robot {self.robot} {sets}" if self.values else "# no yaml parameter changes",
            "#   or copy the values into the robot's kinematics.yaml (tool_x is tool: x:, and so on)",
            f"# residual with these values alone: rms {self.residual.rms:.4g} m, max {self.residual.max:.4g} m "
            f"(the calibrated URDF: rms {self.calibrated.rms:.4g} m, max {self.calibrated.max:.4g} m)",
        ]
        if self.unexpressed:
            lines.append("# not expressible in the yaml (the calibrated URDF carries them): "
                         + ", ".join(self.unexpressed))  # fmt: skip
        lines.extend(f"{k}: {v!r}" for k, v in self.values.items())
        return "\n".join(lines) + "\n"


def _origins(urdf: str, names: list[str]) -> np.ndarray:
    """The (xyz, rpy) of the named joints' origins, concatenated."""
    joints = {el.get("name", ""): el for el in ET.fromstring(urdf).findall("joint")}
    return np.concatenate([np.concatenate([read_triple(joints[n].find("origin"), "xyz"),
                                           read_triple(joints[n].find("origin"), "rpy")]) for n in names])  # fmt: skip


def yaml_overlay(result: CalibrationResult) -> YamlOverlay:
    """The yaml overlay of a calibrated configured robot (see the module docstring).

    Raises:
        InvalidInputError: the robot was loaded from a URDF file (it has no yaml parameters).
    """
    chain = result.chain
    params = chain.robot.parameters
    if params is None:
        raise InvalidInputError(f"robot {chain.robot.name!r} was loaded from a URDF file: it has no yaml parameters "
                                "to overlay (its calibrated URDF is the result)")  # fmt: skip
    names = [o.name for o in chain.origins]
    nominal = np.concatenate([np.concatenate([o.xyz, o.rpy]) for o in chain.origins])
    target = np.concatenate([np.concatenate(v) for v in chain.calibrated_origins(result.theta).values()]) - nominal
    rpy = np.tile(np.repeat([False, True], 3), len(names))
    target[rpy] = wrap(target[rpy])
    kinematic = SCHEMAS[params.kind].files["kinematics.yaml"]
    S = np.empty((len(target), len(kinematic)))
    for k, name in enumerate(kinematic):
        moved = _origins(generate_urdf(params, {name: params.values[name] + STEP}), names) - nominal
        moved[rpy] = wrap(moved[rpy])
        S[:, k] = moved / STEP
    S[np.abs(S) < 1e-9] = 0.0  # float noise of the generated text
    acting = np.flatnonzero(np.abs(S).sum(axis=0) > 0)
    delta = np.zeros(len(kinematic))
    if len(acting):
        delta[acting] = np.linalg.lstsq(S[:, acting], target, rcond=None)[0]
    miss = np.abs(target - S @ delta) > _EXPRESSED
    labels = [f"{n} {attr}[{axis}]" for n in names for attr, axes in (("xyz", "xyz"), ("rpy", ("roll", "pitch", "yaw")))
              for axis in axes]  # fmt: skip
    values = {kinematic[k]: float(params.values[kinematic[k]] + delta[k]) for k in range(len(kinematic))
              if abs(delta[k]) > _EXPRESSED}  # fmt: skip
    frames = {"base_frame": chain.robot.base_frame, "tool_frame": chain.robot.tool_frame}
    overlaid = type(chain.robot).from_config(params, values, **frames)
    chain_o = ChainModel.from_robot(overlaid, frame=chain.frame, yaw=chain.yaw, groups=chain.groups)
    keep = {p.name: v for p, v in zip(chain.parameters, result.theta) if p.group.value in ("scale", "device")}
    theta_o = np.array([keep.get(p.name, 0.0) for p in chain_o.parameters])
    used = result.measurements.subset(result.used)
    out, _ = chain_o.predict(theta_o, chain_o.pinocchio_q(used.q), result.device0, jacobian=False)
    r = out - used.values()
    if chain.yaw:
        r[:, 3] = wrap(r[:, 3])
    return YamlOverlay(chain.robot.name, values, tuple(lab for lab, m in zip(labels, miss) if m),
                       ResidualStats.of(r), result.after)  # fmt: skip
