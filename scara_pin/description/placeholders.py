"""Mesh-free URDF text for Pinocchio's geometry models: every ``<mesh>`` replaced by a small box.

Pinocchio would otherwise read mesh files itself (through assimp, with none of the checks a file from a
stranger needs). The robot's geometry models (``robot.visual_model``, ``robot.collision_model``) are
built from :func:`placeholder_urdf`, so Pinocchio never reads a mesh; :mod:`scara_pin.cell.meshes` reads
the real shapes, checked, under the same geometry names, and draws this box where it cannot.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET

__all__ = ["PLACEHOLDER_SIZE", "placeholder_urdf"]

PLACEHOLDER_SIZE = 0.02
"""[m] edge of the box drawn in place of a mesh."""


def placeholder_urdf(urdf: str) -> str:
    """The URDF text with every ``<mesh>`` (visual and collision) replaced by a :data:`PLACEHOLDER_SIZE` box."""
    root = ET.fromstring(urdf)
    changed = False
    for geometry in root.iter("geometry"):
        for mesh in geometry.findall("mesh"):
            geometry.remove(mesh)
            ET.SubElement(geometry, "box", size=" ".join([repr(PLACEHOLDER_SIZE)] * 3))
            changed = True
    return ET.tostring(root, encoding="unicode") if changed else urdf
