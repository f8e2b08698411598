"""The plan cache: every move of a job kept between runs, keyed on everything its plan depends on.

An integrator's loop is "what if": move a frame, slow down, move the robot, and run the job again. Most of
its moves did not change; planning them again costs seconds each. A move's plan is a function of its inputs
only, so it is kept in a file named by their SHA-256 digest (:func:`move_key`):

- the robot: its URDF text, its limits (all of them), its frames, locks and name (:func:`robot_digest`);
- the move: its kind, both end configurations bit for bit, the speed and acceleration fractions, the jump's
  clearance, the job's jerk limits, torque and payload;
- the cell in force (:func:`cell_digest`): every obstacle's shape and placement (a mesh's triangles), the boxes
  placed so far, the part the tool holds, the margin and the allowed pairs, or "no cell" for the same move
  planned in free space (the cell-cost column). The whole cell, not only the obstacles near the move: a jump in
  a cell goes around or over them as the planner finds best, so which obstacles it comes near is its output,
  not its input; an obstacle anywhere in reach may change it. A frame moved (a pallet, a feeder) changes only
  the moves that start or end there; an obstacle moved re-plans the moves in the cell (their free-space twins
  stay cached);
- the planner (:func:`planner_digest`): this package's version and the bytes of every source file the plan
  goes through (``motion/``, ``cell/``, the job's planning, the symbolic model, the kinematics), and the
  versions of the libraries that solve (Pinocchio, coal, CasADi, TOPP-RA, NumPy, SciPy): a change of the planner
  is a new key.

An entry holds the plan as data, never as code: the trajectory's pieces (a jump's polynomial coefficients; a
straight or joint move's path and time law: :func:`encode_trajectory`), its duration, what binds, its
clearance and lower bound. It is stored and read by the description cache's machinery
(:class:`~scara_pin.description.cache.DigestStore`): the digest of key and body checked on every read, opened
without following a link, a regular file of the user's of at most :data:`MAX_PLAN_BYTES`, written atomically
with mode 0600 in a folder of mode 0700 (``plans/`` in the user's cache folder; ``SCARA_PIN_CACHE_DIR``,
``SCARA_PIN_NO_CACHE=1`` as there). A corrupted entry is warned about once, and the move is planned again and
the entry replaced. A move read from the cache is not verified again: it was verified at 10 kHz when planned,
and the digest says it is that move. ``job --no-cache`` neither reads nor writes.

A straight move's path evaluates its derivatives with CasADi: a move read from the cache is rebuilt when it is
first sampled (:class:`StoredPiece`), so a job whose every move is cached prints its table without importing
the planners.
"""

from __future__ import annotations

import functools
import hashlib
import json
import logging
import math
from collections.abc import Iterable
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from ..description.cache import DigestStore, cache_folder
from ..motion.trajectory import Piece

if TYPE_CHECKING:
    from ..cell import Cell, Shape
    from ..model import RobotModel
    from ..motion.trajectory import Trajectory

__all__ = ["FORMAT", "MAX_PLAN_BYTES", "PlanStore", "StoredPiece", "built", "cell_digest", "decode_trajectory",
           "encode_trajectory", "move_key", "planner_digest", "robot_digest"]  # fmt: skip

log = logging.getLogger(__name__)

FORMAT = 2
"""The layout of a plan entry (part of every key)."""
MAX_PLAN_BYTES = 16 * 1024 * 1024
"""[bytes] a plan entry larger than this is not read (a jump is a few KB, a straight move about 100 KB)."""
FOLDER = "plans"
"""The plan cache's folder inside the user's cache folder."""
_HEADER = b"scara-pin plan cache sha256="
_PLANNER_SOURCES = ("motion", "cell", "kinematics", "job/planning.py", "symbolic.py", "model.py", "_version.py")
_LIBRARIES = ("pin", "coal", "casadi", "toppra", "numpy", "scipy", "ruckig")
_ENTRY_KEYS = {"format": int, "duration": float, "method": str, "binding": list, "seconds": float}


@dataclass(frozen=True)
class PlanStore(DigestStore):
    """The plan cache's folder (module docstring); ``folder`` None: off."""

    what: str = "plan cache"
    header: bytes = _HEADER
    max_bytes: int = MAX_PLAN_BYTES

    @classmethod
    def default(cls) -> PlanStore:
        """The user's plan cache (``plans/`` in the cache folder), or off as the environment says."""
        folder = cache_folder()
        return cls(None if folder is None else folder / FOLDER)

    def check(self, entry: Any) -> None:
        """An entry holds one planned move: its format, duration, method, what binds, and its trajectory."""
        for key, kind in _ENTRY_KEYS.items():
            value = entry.get(key)
            if not isinstance(value, (int, float) if kind is float else kind) or isinstance(value, bool):
                raise ValueError(f"it does not hold a planned move ({key})")
        if entry["format"] != FORMAT:
            raise ValueError(f"its format is {entry['format']}, not {FORMAT}")
        if entry.get("trajectory") is not None and not isinstance(entry["trajectory"], dict):
            raise ValueError("its trajectory is not a mapping")


def _add(digest: Any, label: str, data: bytes) -> None:
    digest.update(f"{label}\0{len(data)}\0".encode())
    digest.update(data)


def _versions() -> dict[str, str]:
    """The installed distributions' versions by normalised name, from the ``*.dist-info`` folders on ``sys.path``.

    What ``importlib.metadata.version`` reads, without importing it (a tenth of a second at every start).
    """
    import os
    import sys

    found: dict[str, str] = {}
    for folder in sys.path:
        try:
            entries = os.scandir(folder or ".")
        except OSError:
            continue
        with entries:
            for entry in entries:
                if entry.name.endswith(".dist-info"):
                    name, _, version = entry.name[: -len(".dist-info")].partition("-")
                    found.setdefault(name.lower().replace("_", "-"), version)
    return found


@functools.cache
def planner_digest() -> str:
    """The digest of the planner: the package's version, its planning sources' bytes, the solvers' versions."""
    from .._version import __version__

    root = Path(__file__).resolve().parents[1]
    digest = hashlib.sha256()
    _add(digest, "format", str(FORMAT).encode())
    _add(digest, "scara-pin", __version__.encode())
    for name in _PLANNER_SOURCES:
        path = root / name
        files = sorted(path.rglob("*.py")) if path.is_dir() else [path]
        for file in files:
            _add(digest, str(file.relative_to(root)), file.read_bytes())
    versions = _versions()
    for lib in _LIBRARIES:
        _add(digest, lib, versions.get(lib, "").encode())
    return digest.hexdigest()


def robot_digest(robot: RobotModel) -> str:
    """The digest of what a robot plans with: its URDF text, its limits, frames, locks, kind and name."""
    digest = hashlib.sha256()
    _add(digest, "urdf", str(getattr(robot, "urdf", "")).encode())
    for name in ("name", "kind", "base_frame", "tool_frame", "locked", "geared", "joint_names"):
        _add(digest, name, repr(getattr(robot, name, None)).encode())
    lim = robot.limits
    for name in ("lower", "upper", "velocity", "acceleration", "effort", "jerk", "tool_speed"):
        _add(digest, f"limit {name}", repr(getattr(lim, name, None)).encode())
    return digest.hexdigest()


def _shape_bytes(shape: Shape | None) -> bytes:
    if shape is None:
        return b"none"
    parts = [shape.kind.encode(), repr(tuple(float(v) for v in shape.size)).encode(), shape.xyz.tobytes(),
             shape.rpy.tobytes()]  # fmt: skip
    for arr in (shape.vertices, shape.faces):
        parts.append(b"" if arr is None else np.ascontiguousarray(arr).tobytes())
    return b"\0".join(parts)


def cell_digest(cell: Cell | None) -> str:
    """The digest of a cell in force (module docstring): obstacles, the part held, margin, allowed pairs; or none."""
    if cell is None:
        return "no cell"
    digest = hashlib.sha256()
    _add(digest, "margin", repr(float(cell.margin)).encode())
    _add(digest, "allow", repr(tuple(cell.allow)).encode())
    _add(digest, "carried", _shape_bytes(cell.carried))
    for o in cell.obstacles:
        _add(digest, f"obstacle {o.name} {o.margin!r}", _shape_bytes(o.shape))
    return digest.hexdigest()


def move_key(robot: str, kind: str, q_from: np.ndarray, q_to: np.ndarray, *, speed: float, accel: float,
             shape: Iterable[object] | None, jerk: Iterable[float] | None, torque: bool, payload_key: object,
             cell: str) -> str:  # fmt: skip
    """The digest of one move's plan's inputs (module docstring); ``robot`` and ``cell`` are their digests."""
    digest = hashlib.sha256()
    _add(digest, "planner", planner_digest().encode())
    _add(digest, "robot", robot.encode())
    _add(digest, "kind", kind.encode())
    _add(digest, "from", np.asarray(q_from, dtype=float).tobytes())
    _add(digest, "to", np.asarray(q_to, dtype=float).tobytes())
    _add(digest, "fractions", repr((float(speed), float(accel))).encode())
    _add(digest, "shape", repr(None if shape is None else tuple(shape)).encode())
    _add(digest, "jerk", repr(None if jerk is None else tuple(float(v) for v in jerk)).encode())
    _add(digest, "torque", repr((bool(torque), payload_key)).encode())
    _add(digest, "cell", cell.encode())
    return digest.hexdigest()


# ---------------------------------------------------------------------------------------------- the pieces as data
def _array(value: Any, ndim: int) -> np.ndarray:
    arr = np.array(value, dtype=float)
    if arr.ndim != ndim or not np.isfinite(arr).all():
        raise ValueError(f"an array of {ndim} dimensions of finite numbers was expected, got shape {arr.shape}")
    return arr


def encode_trajectory(traj: Trajectory) -> dict[str, Any] | None:
    """A trajectory's pieces as plain data (exact: floats round-trip through JSON), or None if one is unknown.

    Each piece: its duration and its states at both ends, and the rest (``data``) as JSON text: read only when the
    piece is sampled inside (parsing thousands of numbers costs more than the table needs).
    """
    pieces = []
    for piece in traj.pieces:
        data = _encode_piece(piece)
        if data is None:
            return None
        pieces.append(data)
    return {"pieces": pieces}


def _encode_piece(piece: Piece) -> dict[str, Any] | None:
    from ..motion.paths import CartesianSegment, JointLine
    from ..motion.polynomial import PolynomialPiece
    from ..motion.trajectory import Motion, ProfileLaw, TrapezoidLaw

    if isinstance(piece, StoredPiece):
        return {"duration": piece.duration, "ends": [e.tolist() for e in piece.ends], "data": piece.data}
    ends = [e.tolist() for e in piece.evaluate(np.array([0.0, piece.duration]))]
    if isinstance(piece, PolynomialPiece):
        data: dict[str, Any] = {"type": "polynomial", "breaks": piece.breaks.tolist(),
                                "coefficients": piece.coefficients.tolist()}  # fmt: skip
        return {"duration": piece.duration, "ends": ends, "data": json.dumps(data)}
    if not isinstance(piece, Motion):
        return None
    path, law = piece.path, piece.law
    if isinstance(path, JointLine):
        p: dict[str, Any] = {"type": "joint line", "q0": path.q0.tolist(), "q1": path.q1.tolist()}
    elif isinstance(path, CartesianSegment):
        p = {"type": "tool line", "branch": path.branch, "pose0": path.pose0.tolist(), "pose1": path.pose1.tolist(),
             "s_ref": path.s_ref.tolist(), "q_ref": path.q_ref.tolist()}  # fmt: skip
    else:
        return None
    if isinstance(law, TrapezoidLaw):
        w: dict[str, Any] = {"type": "trapezoid", "velocity": law.velocity, "acceleration": law.acceleration}
    elif isinstance(law, ProfileLaw):
        w = {"type": "profile", "s": law.s.tolist(), "sd": law.sd.tolist()}
    else:
        from ..motion.jerk import JerkLaw

        if not isinstance(law, JerkLaw):
            return None
        w = {"type": "jerk", "t": law.t.tolist(), "c": law.c.tolist(), "knots": list(law.knots)}
    return {"duration": piece.duration, "ends": ends, "data": json.dumps({"type": "motion", "path": p, "law": w})}


def decode_trajectory(robot: RobotModel, data: dict[str, Any]) -> Trajectory:
    """The trajectory of :func:`encode_trajectory`'s data (``ValueError``: not such data)."""
    from ..motion.trajectory import Trajectory

    items = data.get("pieces")
    if not isinstance(items, list) or not items:
        raise ValueError("no pieces")
    return Trajectory(tuple(_decode_piece(robot, item) for item in items))


def _decode_piece(robot: RobotModel, item: Any) -> Piece:
    if not isinstance(item, dict) or not isinstance(item.get("data"), str):
        raise ValueError("a piece is its duration, its ends and its data")
    duration = float(item["duration"])
    ends = [_array(e, 2) for e in item["ends"]]
    if not (math.isfinite(duration) and duration > 0.0) or len(ends) != 3:
        raise ValueError("a piece's duration and end states")
    return StoredPiece(duration, tuple(ends), item["data"], robot)  # type: ignore[arg-type]


def _build(robot: RobotModel, text: str) -> Piece:
    """The piece of an entry made again from its data: a jump's polynomials, or a motion's path and time law."""
    from ..motion.polynomial import PolynomialPiece

    data = json.loads(text)
    if not isinstance(data, dict) or data.get("type") not in ("polynomial", "motion"):
        raise ValueError("not a piece's data")
    if data["type"] == "polynomial":
        return PolynomialPiece(_array(data["breaks"], 1), _array(data["coefficients"], 3))
    from ..motion.jerk import JerkLaw
    from ..motion.paths import CartesianSegment, JointLine
    from ..motion.trajectory import Motion, ProfileLaw, TrapezoidLaw

    p, w = data["path"], data["law"]
    path: Any
    if p["type"] == "joint line":
        path = JointLine(_array(p["q0"], 1), _array(p["q1"], 1))
    elif p["type"] == "tool line":
        path = CartesianSegment(robot, str(p["branch"]), _array(p["pose0"], 1), _array(p["pose1"], 1),
                                _array(p["s_ref"], 1), _array(p["q_ref"], 2))  # fmt: skip
    else:
        raise ValueError(f"unknown path {str(p['type'])[:40]!r}")
    law: Any
    if w["type"] == "trapezoid":
        law = TrapezoidLaw(float(w["velocity"]), float(w["acceleration"]))
    elif w["type"] == "profile":
        law = ProfileLaw(_array(w["s"], 1), _array(w["sd"], 1))
    elif w["type"] == "jerk":
        law = JerkLaw(_array(w["t"], 1), _array(w["c"], 1), tuple(float(v) for v in w["knots"]))
    else:
        raise ValueError(f"unknown time law {str(w['type'])[:40]!r}")
    return Motion(path, law)


@dataclass(frozen=True, eq=False)
class StoredPiece(Piece):
    """A piece read from the plan cache, rebuilt when it is first sampled inside (module docstring).

    Its states at both ends are stored: sampling only its ends (a trajectory's continuity check, a table) builds
    nothing; a jump's polynomials are checked again when they are built
    (:class:`~scara_pin.motion.polynomial.PolynomialPiece`'s continuity).

    Attributes:
        duration: [s].
        ends: (q, qd, qdd) at its start and end, each (2, dof).
        data: the entry's data of the piece (JSON text).
        robot: the robot it moves.
    """

    duration: float
    ends: tuple[np.ndarray, np.ndarray, np.ndarray]
    data: str = field(repr=False)
    robot: Any = field(repr=False)
    _built: list[Piece] = field(default_factory=list, init=False, repr=False)

    @property
    def piece(self) -> Piece:
        """The motion itself (built on first use)."""
        if not self._built:
            built = _build(self.robot, self.data)
            if abs(built.duration - self.duration) > 0.0:
                raise ValueError("a stored motion's duration differs from its entry's")
            self._built.append(built)
        return self._built[0]

    def evaluate(self, tau: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(q, qd, qdd) at local times ``tau``: the stored ends, or the motion itself inside."""
        tau = np.asarray(tau, dtype=float).ravel()
        at_start, at_end = tau <= 0.0, tau >= self.duration
        if (at_start | at_end).all():
            rows = at_end.astype(int)
            q, qd, qdd = self.ends
            return q[rows], qd[rows], qdd[rows]
        return self.piece.evaluate(tau)

    def breakpoints(self) -> np.ndarray | None:  # noqa: D102
        return self.piece.breakpoints()


def built(piece: Piece) -> Piece:
    """``piece`` itself, or the piece a :class:`StoredPiece` stands for (built now)."""
    return piece.piece if isinstance(piece, StoredPiece) else piece

