"""Real robots, round 4 (issue 39): every real file usable as written.

Fixtures in ``tests/data/round4`` were written for these tests, shaped like the public descriptions the issue
tried (never copied): an LS3-like SCARA exported for PyBullet (meshes named ``/Mesh/Visual/Base.stl``: item 5).
The truth: the STL files' own extents, read here.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest

from scara_pin import load_robot
from scara_pin.cell.meshes import visual_meshes
from scara_pin.lint import check_urdf_file

DATA = Path(__file__).resolve().parent / "data"
ROUND4 = DATA / "round4"
GRIPPER = ROUND4 / "vendor_gripper_scara.urdf"
MG400 = ROUND4 / "mg400_empty_material.urdf"
DUARO = ROUND4 / "duaro_empty_material.urdf"
LS3 = ROUND4 / "ls3_like" / "ls3_like.urdf"
LAB = ROUND4 / "rprr_lab_description" / "urdf" / "rprr_lab.urdf.xacro"
MACROS = ROUND4 / "macros_only.urdf.xacro"
TWO_JOINTS = ROUND4 / "two_joint_palletizer.urdf"
PALLETIZER_J2 = ROUND4 / "palletizer_j2_continuous.urdf"
ACC = ["--acceleration", "20", "30", "5", "60"]
RNG_SEED = 39


def gripper_pose(q: np.ndarray) -> np.ndarray:
    """The vendor SCARA: J1 at 0.2 m, arms 0.2 and 0.15 m (arm 2 0.04 m higher), the quill q3 down from there, the
    hand 0.03 m below the quill's end."""
    q1, q2, q3, q4 = q
    return np.array([0.2 * np.cos(q1) + 0.15 * np.cos(q1 + q2), 0.2 * np.sin(q1) + 0.15 * np.sin(q1 + q2),
                     0.2 + 0.04 - q3 - 0.03, q1 + q2 + q4])  # fmt: skip


def duaro_upper_pose(q: np.ndarray) -> np.ndarray:
    """The duAro-like upper arm: J1 at 0.9 m, arms 0.4 and 0.36 m, the quill down by q3, J4 0.08 m below."""
    q1, q2, q3, q4 = q
    return np.array([0.4 * np.cos(q1) + 0.36 * np.cos(q1 + q2), 0.4 * np.sin(q1) + 0.36 * np.sin(q1 + q2),
                     0.9 - q3 - 0.08, q1 + q2 + q4])  # fmt: skip


def samples(robot, n: int = 20) -> np.ndarray:  # type: ignore[no-untyped-def]
    """Seeded configurations inside the joint limits (continuous joints: one turn)."""
    lo, hi = np.array(robot.limits.lower), np.array(robot.limits.upper)
    return np.random.default_rng(RNG_SEED).uniform(lo, hi, (n, robot.dof))


def pinocchio_loads(path: Path) -> tuple[pin.Model, int, int]:
    """Pinocchio's own parsers on the file: the model, its visual and collision geometries (the judge)."""
    model = pin.buildModelFromUrdf(str(path))
    visual = pin.buildGeomFromUrdf(model, str(path), pin.GeometryType.VISUAL, package_dirs=[str(path.parent)])
    collision = pin.buildGeomFromUrdf(model, str(path), pin.GeometryType.COLLISION, package_dirs=[str(path.parent)])
    return model, visual.ngeoms, collision.ngeoms


# ====================================================================== item 5: meshes written PyBullet's way
def test_pybullet_mesh_paths_are_read_from_the_files_folder(caplog: pytest.LogCaptureFixture,
                                                            capfd: pytest.CaptureFixture[str]) -> None:  # fmt: skip
    assert not Path("/Mesh/Visual/Base.stl").exists()
    robot = load_robot(urdf=LS3)
    with caplog.at_level("WARNING", logger="scara_pin"):
        meshes = {m.link: m for m in visual_meshes(robot)}
    assert set(meshes) == {"Base", "Arm1", "Arm2", "Shaft"}
    assert meshes["Arm1"].path == LS3.parent / "Mesh" / "Visual" / "Arm1.stl"
    # the box written in the STL file: 0.3 x 0.08 x 0.05
    np.testing.assert_allclose(np.ptp(meshes["Arm1"].vertices, axis=0), [0.3, 0.08, 0.05], atol=1e-12)
    assert caplog.text.count("PyBullet's rule") == 4 and "'/Mesh/Visual/Base.stl' does not exist" in caplog.text
    findings = check_urdf_file(LS3).find("mesh-path")
    assert len(findings) == 4 and all("PyBullet's rule" in f.message for f in findings)
    assert not check_urdf_file(LS3).find("mesh-missing")


def _written(text: str) -> Path:
    import tempfile

    path = Path(tempfile.mkdtemp()) / "p.urdf"
    path.write_text(text)
    return path
