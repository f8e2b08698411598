"""What a command writes: its output files, checked before any work against the files it reads; its log."""

from __future__ import annotations

import argparse
import contextlib
import logging
from collections.abc import Sequence

from ..description import config_files
from ..errors import UnknownRobotError
from ._robot import MAX_NAME

log = logging.getLogger("scara_pin")
"""The logger of the command line's warnings (``warning: ...`` on stderr; :func:`scara_pin.cli.main`)."""

INPUT_OPTIONS = ("urdf", "dh", "points", "measurements", "input", "traj", "simulate", "cell", "carry", "file")
"""The options that name a file a command reads (those it has)."""


def input_files(args: argparse.Namespace) -> dict[str, list[str]]:
    """The files a command reads, by option: its input options, and the yaml files of a configured ``--robot``."""
    found = {f"--{name}": [value] for name in INPUT_OPTIONS
             if isinstance(value := getattr(args, name, None), str) and value not in ("", "-")}  # fmt: skip
    robot = getattr(args, "robot", None)
    if "--urdf" not in found and "--dh" not in found and (robot is None or len(robot) <= MAX_NAME):
        with contextlib.suppress(UnknownRobotError, ValueError, OSError):  # refused when the robot is loaded
            found["--robot"] = [str(f) for f in config_files(robot or "default")]
    return found


def check_command_outputs(args: argparse.Namespace, outputs: dict[str, str | None], figures: Sequence[str] = ()
                          ) -> None:  # fmt: skip
    """The command's outputs, checked BEFORE any work by :func:`scara_pin.files.check_outputs`.

    Each name (no device, folder or missing folder; a plot's ending), at most one on standard output (with
    ``--json``), none the same file as an input of the command (:func:`input_files`), as a file it has read so far,
    or as another output. They are then declared (:func:`scara_pin.limits.declare_outputs`): a file the command
    reads afterwards (a mesh or an include of its cell, its robot's meshes) that is one of them is refused then.
    """
    from ..files import check_outputs
    from ..limits import declare_outputs

    stdout = "--json" if getattr(args, "json", False) else None
    check_outputs(outputs, input_files(args), figures=figures, stdout=stdout)
    declare_outputs(outputs)
