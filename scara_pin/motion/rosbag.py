"""A trajectory as a ROS 2 bag, written without ROS (the ``rosbags`` library): what a ROS 2 controller replays.

Two topics, the joints named as the robot's URDF names them (``robot.joint_names``):

- ``/joint_trajectory``, one ``trajectory_msgs/msg/JointTrajectory``: the samples at ``rate`` as its points
  (positions, velocities, accelerations, ``time_from_start``), header stamp 0 ("start when received", as
  ``joint_trajectory_controller`` reads it): the message a controller executes;
- ``/joint_states``, one ``sensor_msgs/msg/JointState`` per sample (position, velocity; no effort), stamped
  with the sample's time from 0: the motion as a robot driver would have published it.

Times are whole nanoseconds (ROS time): the rate's grid ``k / rate`` is exact when ``rate`` divides 1e9 (1 kHz,
500 Hz, ...), else rounded to the nearest nanosecond. Values are the samples' own (SI: rad, m, per s, per s^2),
the same floats as the CSV written at the same rate.

The file is one storage file of a bag, chosen by its name: ``.mcap`` (MCAP, the ROS 2 default since Iron: its
message definitions and the bag's metadata are inside it) or ``.db3`` (SQLite 3, Humble's default). The
messages are those of ROS 2 Humble and Jazzy (the same definitions in both); the bag layout is rosbag2's
version 8. The writer makes a bag folder beside the output; its storage file becomes the output through the
package's atomic output (:func:`~scara_pin.files.atomic_output`): the old file or the new one, never half.
"""

from __future__ import annotations

import os
import shutil
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Literal

import numpy as np

from ..errors import InvalidInputError
from ..files import atomic_output, check_output_path

if TYPE_CHECKING:
    from .trajectory import Trajectory

__all__ = ["BAG_FORMATS", "JOINT_STATES", "JOINT_TRAJECTORY", "is_bag", "write_bag"]

BAG_FORMATS = {".mcap": "mcap", ".db3": "sqlite3"}
"""A bag's file endings and their rosbag2 storage."""
JOINT_TRAJECTORY = "/joint_trajectory"
"""The topic of the one JointTrajectory message."""
JOINT_STATES = "/joint_states"
"""The topic of the JointState messages, one per sample."""
_VERSION: Literal[8] = 8
"""rosbag2's bag version written (Jazzy's; the oldest the writer knows)."""


def is_bag(path: str | os.PathLike[str]) -> bool:
    """Whether an output name asks for a ROS 2 bag (``.mcap``, ``.db3``)."""
    return Path(path).suffix.lower() in BAG_FORMATS


def _time(t: float) -> tuple[int, int]:
    """(sec, nanosec) of ``t`` >= 0 [s], rounded to the nanosecond."""
    ns = int(round(float(t) * 1e9))
    return ns // 1_000_000_000, ns % 1_000_000_000


def write_bag(path: str | os.PathLike[str], trajectory: Trajectory, joint_names: Sequence[str],
              rate: float = 1000.0) -> Path:  # fmt: skip
    """Write ``trajectory`` sampled at ``rate`` [Hz] as a ROS 2 bag file (module docstring), atomically.

    Raises:
        InvalidInputError: a name that is not ``.mcap`` nor ``.db3``, joint names that do not fit, an unwritable
            folder, too many samples (the trajectory's own cap).
    """
    from rosbags.rosbag2 import StoragePlugin, Writer
    from rosbags.typesys import Stores, get_typestore

    path = check_output_path(path)
    storage = BAG_FORMATS.get(path.suffix.lower())
    if storage is None or str(path) == "-":
        raise InvalidInputError(f"cannot write {path}: a ROS 2 bag is a .mcap or .db3 file")
    names = [str(n) for n in joint_names]
    if len(names) != trajectory.dof:
        raise InvalidInputError(f"{len(names)} joint names for a trajectory of {trajectory.dof} joints")
    samples = trajectory.resample(rate)
    store = get_typestore(Stores.ROS2_HUMBLE)
    types = store.types
    Header, Time, Duration = (types[n] for n in ("std_msgs/msg/Header", "builtin_interfaces/msg/Time",
                                                 "builtin_interfaces/msg/Duration"))  # fmt: skip
    Point, JointTrajectory = types["trajectory_msgs/msg/JointTrajectoryPoint"], types[
        "trajectory_msgs/msg/JointTrajectory"]
    JointState = types["sensor_msgs/msg/JointState"]
    empty = np.zeros(0)
    points = [Point(positions=samples.q[k].copy(), velocities=samples.qd[k].copy(),
                    accelerations=samples.qdd[k].copy(), effort=empty,
                    time_from_start=Duration(*_time(t))) for k, t in enumerate(samples.t.tolist())]  # fmt: skip
    plan = JointTrajectory(header=Header(stamp=Time(sec=0, nanosec=0), frame_id=""), joint_names=names,
                           points=points)  # fmt: skip
    plugin = StoragePlugin.MCAP if storage == "mcap" else StoragePlugin.SQLITE3
    with atomic_output(path) as tmp:  # the package's atomic output: the storage file copied onto its temporary file
        work = tmp.with_name(tmp.name + ".bag")
        try:
            with Writer(work, version=_VERSION, storage_plugin=plugin) as writer:
                plans = writer.add_connection(JOINT_TRAJECTORY, JointTrajectory.__msgtype__, typestore=store)
                states = writer.add_connection(JOINT_STATES, JointState.__msgtype__, typestore=store)
                writer.write(plans, 0, store.serialize_cdr(plan, JointTrajectory.__msgtype__))
                for k, t in enumerate(samples.t.tolist()):
                    sec, nsec = _time(t)
                    state = JointState(header=Header(stamp=Time(sec=sec, nanosec=nsec), frame_id=""), name=names,
                                       position=samples.q[k].copy(), velocity=samples.qd[k].copy(), effort=empty)
                    writer.write(states, sec * 1_000_000_000 + nsec, store.serialize_cdr(state,
                                                                                         JointState.__msgtype__))
            files = [p for p in work.iterdir() if p.suffix == path.suffix.lower()]
            if len(files) != 1:  # pragma: no cover - the writer makes one storage file
                raise InvalidInputError(f"cannot write {path}: the bag writer made {len(files)} storage files")
            shutil.copyfile(files[0], tmp)
        finally:
            shutil.rmtree(work, ignore_errors=True)
    return path
