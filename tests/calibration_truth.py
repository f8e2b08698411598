"""A synthetic truth for calibration tests: a robot's URDF with every joint origin perturbed, measured by yourdfpy.

The perturbation is this module's own XML edit (scipy writes each rotation as rpy), independent of the package's
``calibration.simulate``; the measurement is yourdfpy's forward kinematics (a second library) of the file.
"""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
from scipy.spatial.transform import Rotation


def perturbed_everywhere(urdf: str, rng: np.random.Generator, position: float = 1e-3, tilt_deg: float = 0.1,
                         offset_deg: float = 0.5) -> str:  # fmt: skip
    """Every joint's origin: each xyz coordinate moved by up to +/-``position`` [m], the rotation turned by a
    rotation vector (joint frame) of two tilts up to ``tilt_deg`` and a turn about z up to ``offset_deg``.

    The joints' axes must be along z (the rotation vector's z is then the joint's zero offset).
    """
    root = ET.fromstring(urdf)
    for j in root.findall("joint"):
        axis = j.find("axis")
        if axis is not None:
            assert np.allclose(np.abs([float(v) for v in axis.get("xyz").split()]), [0, 0, 1]), j.get("name")
        o = j.find("origin")
        xyz = np.array([float(v) for v in o.get("xyz").split()]) + rng.uniform(-position, position, 3)
        w = np.radians([rng.uniform(-tilt_deg, tilt_deg), rng.uniform(-tilt_deg, tilt_deg),
                        rng.uniform(-offset_deg, offset_deg)])  # fmt: skip
        R = Rotation.from_euler("xyz", [float(v) for v in o.get("rpy", "0 0 0").split()]) * Rotation.from_rotvec(w)
        o.set("xyz", " ".join(repr(float(v)) for v in xyz))
        o.set("rpy", " ".join(repr(float(v)) for v in R.as_euler("xyz")))
    return ET.tostring(root, encoding="unicode")


class Tracker:
    """A robot's tool position and yaw in its base frame, by yourdfpy (joints ``joint1`` ..)."""

    def __init__(self, urdf: str, folder: Path, base: str = "base", tool: str = "tool0") -> None:
        import yourdfpy

        path = folder / "truth.urdf"
        path.write_text(urdf)
        self.urdf = yourdfpy.URDF.load(str(path), load_meshes=False, build_scene_graph=True)
        self.base, self.tool = base, tool
        self.joints = list(self.urdf.actuated_joint_names)

    def __call__(self, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        p, yaw = [], []
        for x in np.atleast_2d(q):
            self.urdf.update_cfg(dict(zip(self.joints, x)))
            T = self.urdf.get_transform(self.tool, self.base)
            p.append(T[:3, 3])
            yaw.append(math.atan2(T[1, 0], T[0, 0]))
        return np.array(p), np.array(yaw)


def write_csv(path: Path, q: np.ndarray, p: np.ndarray, yaw: np.ndarray | None = None, comment: str = "") -> Path:
    """A measurement file: optional ``#`` comment lines, the header, one row per pose (repr of each value)."""
    cols = [f"q{i + 1}" for i in range(q.shape[1])] + ["x", "y", "z"] + (["yaw"] if yaw is not None else [])
    rows = np.column_stack([q, p] + ([yaw] if yaw is not None else []))
    head = "".join(f"# {line}\n" for line in comment.splitlines())
    path.write_text(head + ",".join(cols) + "\n" + "\n".join(",".join(repr(float(v)) for v in r) for r in rows) + "\n")
    return path
