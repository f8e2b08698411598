"""The robot's tool position and inverse dynamics as CasADi expressions, built from its Pinocchio model.

The pip ``pin`` wheel has no ``pinocchio.casadi``, and an optimiser that calls Pinocchio through Python
callbacks gets first derivatives only (and pays a Python call per node and iteration). So the jump planner
(:mod:`scara_pin.motion.jump`) takes the kinematic tree FROM THE LOADED MODEL, joint by joint, and writes
it in CasADi's symbolic algebra: exact first and second derivatives for IPOPT, no second copy of any
robot's geometry (every number comes from ``model.jointPlacements``, ``model.inertias``, ``model.frames``
and each joint's motion subspace as Pinocchio computes it).

Every joint of the robots this package loads has one degree of freedom and a CONSTANT motion subspace
S (6-vector, linear part first, in the joint frame): revolute about any axis, prismatic along any axis,
helical, a continuous joint (Pinocchio's (cos, sin) pair: here its angle), or a mimic joint (Pinocchio's
``S`` already carries the mimic's ``scaling``). The joint's motion is then the exponential

    M_j(theta) = exp6(S_unit theta),    theta = scaling q_i + offset,

(Rodrigues' formula for the rotation, ``(I - R)(w x v) + w w^T v theta`` for the translation), and the
placement of joint j in its parent ``liMi = jointPlacements[j] M_j``. The tool position is the product
along the chain, expressed in the robot's base frame (a fixed frame: its placement at the neutral
configuration). The inverse dynamics is the recursive Newton-Euler algorithm in Pinocchio's conventions
(spatial vectors linear part first; the base accelerating at ``-model.gravity``; a mimic joint's force
projected on its source joint), so that ``rnea(q, qd, qdd)`` equals ``pinocchio.rnea`` (gravity
included, no friction) to rounding. Both are tested against Pinocchio to 1e-12 on the shipped robots,
a continuous-joint URDF and a model carrying a payload.

The same functions, evaluated on numbers (``joint_frames.map(n)``), place every joint at many configurations in
one call: the cell's sweep (:func:`scara_pin.cell.sweep.joint_placements`) and the jump planner's obstacle rows
use them, so the package has one vectorised forward kinematics besides Pinocchio's.

CasADi is imported inside :func:`symbolic_model` only (``scara-pin fk``/``ik`` never load it).
"""

from __future__ import annotations

import weakref
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np
import pinocchio as pin

from .errors import InvalidInputError

if TYPE_CHECKING:
    from .model import RobotModel

__all__ = ["SymbolicModel", "symbolic_model"]

_MIMIC = "JointModelMimic"
_AXIS_TOL = 1e-12
"""A motion subspace whose angular part is shorter than this is a translation (prismatic joint)."""


@dataclass(frozen=True)
class _Joint:
    """One joint of the chain: parent index, placement in the parent, unit twist, source index in q, mimic map."""

    parent: int
    rotation: np.ndarray
    translation: np.ndarray
    twist: np.ndarray  # (6,) the unit motion subspace S_unit (linear, angular)
    source: int  # index in the user's q (and in Pinocchio's v)
    scaling: float
    offset: float
    mass: float
    lever: np.ndarray
    inertia: np.ndarray


@dataclass(frozen=True)
class SymbolicModel:
    """CasADi functions of a robot (module docstring).

    Attributes:
        tool_position: ``p = tool_position(q)``, (3,) tool origin in the base frame [m].
        tool_velocity: ``v = tool_velocity(q, qd)``, (3,) its velocity J(q) qd [m/s].
        inverse_dynamics: ``tau = inverse_dynamics(q, qd, qdd)``, (dof,) joint efforts [N m or N], as
            ``pinocchio.rnea`` (gravity included).
        dof: the number of joint values in q.
        joint_frames: ``F = joint_frames(q)``, (12, njoints): column j is Pinocchio's ``oMi[j]`` (the rotation
            column by column, then the translation) in the model's world frame (the root link), as
            ``pinocchio.forwardKinematics`` gives it; column 0 is the root's identity.
        twists: (njoints, 6) each joint's unit motion (linear part first) in its own frame, at its origin: joint j
            moves its subtree at ``scalings[j] * qd[sources[j]]`` times it (row 0, the root: zero).
        sources: (njoints,) the index in q each joint follows (-1 for the root).
        scalings: (njoints,) its ratio to that joint (1, or a mimic's multiplier).
    """

    tool_position: Any
    tool_velocity: Any
    inverse_dynamics: Any
    dof: int
    joint_frames: Any = None
    twists: np.ndarray = field(default_factory=lambda: np.zeros((1, 6)))
    sources: np.ndarray = field(default_factory=lambda: np.full(1, -1))
    scalings: np.ndarray = field(default_factory=lambda: np.zeros(1))


def _joints(robot: RobotModel) -> tuple[list[_Joint], pin.SE3]:
    """The chain read from the model, and the base frame's placement (inverse) for the tool position."""
    model = robot.model
    data = model.createData()
    q_neutral = robot.to_pinocchio_q(np.zeros(robot.dof))
    pin.forwardKinematics(model, data, q_neutral)
    pin.updateFramePlacements(model, data)
    out = []
    for j in range(1, model.njoints):
        jm = model.joints[j]
        S = np.asarray(data.joints[j].S, dtype=float).reshape(-1)
        if S.shape != (6,) or jm.nv > 1:
            raise InvalidInputError(f"joint {model.names[j]} ({jm.shortname()}) has {jm.nv} degrees of freedom: the "
                                    "jump planner takes single-degree-of-freedom joints")  # fmt: skip
        scaling, offset = 1.0, 0.0
        if jm.shortname() == _MIMIC:
            mimic = jm.extract()
            scaling, offset = float(mimic.scaling), float(mimic.offset)
            if scaling == 0.0:
                raise InvalidInputError(f"mimic joint {model.names[j]} has scaling 0")
        twist = S / scaling
        norm = float(np.linalg.norm(twist[3:])) or float(np.linalg.norm(twist[:3]))
        if not norm > 0.0:
            raise InvalidInputError(f"joint {model.names[j]} ({jm.shortname()}) has no motion axis")
        inertia = model.inertias[j]
        placement = model.jointPlacements[j]
        out.append(_Joint(int(model.parents[j]), placement.rotation.copy(), placement.translation.copy(), twist,
                          int(jm.idx_v), scaling, offset, float(inertia.mass), inertia.lever.copy(),
                          inertia.inertia.copy()))  # fmt: skip
    return out, data.oMf[robot.base_id].inverse()


def frames_at(sym: SymbolicModel, Q: np.ndarray) -> np.ndarray:
    """(n, njoints, 12): :attr:`SymbolicModel.joint_frames` at each row of ``Q``, evaluated into numpy directly.

    In blocks of ``_BLOCK`` columns of one mapped function through CasADi's buffer interface (its DM results
    would cost ten times the evaluation to convert); the last block padded.
    """
    Q = np.atleast_2d(np.asarray(Q, dtype=float))
    n = len(Q)
    nj = int(sym.joint_frames.size2_out(0))
    out = np.empty((n, nj, 12))
    block = _evaluator(sym.joint_frames)
    for lo in range(0, n, _BLOCK):
        m = min(_BLOCK, n - lo)
        block.arg[:m] = Q[lo : lo + m]
        block.arg[m:] = Q[lo + m - 1]
        block.trigger()
        out[lo : lo + m] = block.res[: m * nj].reshape(m, nj, 12)
    return out


_BLOCK = 1024
"""Configurations per evaluation of the joint frames (:func:`frames_at`)."""


@dataclass(eq=False)
class _Evaluator:
    function: Any
    buffer: Any
    trigger: Any
    arg: np.ndarray
    res: np.ndarray


_EVALUATORS: dict[int, _Evaluator] = {}


def _evaluator(f: Any) -> _Evaluator:
    """The mapped ``f`` over ``_BLOCK`` columns with its numpy buffers, made once per function."""
    hit = _EVALUATORS.get(id(f))
    if hit is None or hit.function is not f:
        mapped = f.map(_BLOCK)
        buffer, trigger = mapped.buffer()
        arg = np.zeros((_BLOCK, int(f.size1_in(0))))  # column-major (dof, block) is row-major (block, dof)
        res = np.zeros((int(mapped.size2_out(0)), int(mapped.size1_out(0))))
        buffer.set_arg(0, arg.data)
        buffer.set_res(0, res.data)
        if len(_EVALUATORS) >= 16:
            _EVALUATORS.clear()
        hit = _EVALUATORS[id(f)] = _Evaluator(f, buffer, trigger, arg, res)
    return hit


_BUILT: weakref.WeakKeyDictionary[pin.Model, dict[tuple[int, int], SymbolicModel]] = weakref.WeakKeyDictionary()
"""The symbolic models built, per Pinocchio model (a payload's is another model) and (base, tool) frame."""


def symbolic_model(robot: RobotModel) -> SymbolicModel:
    """The tool position and inverse dynamics of ``robot`` (its current model: a payload included) in CasADi.

    Built once per Pinocchio model and frames (a model is not changed in place once loaded: a payload is a copy,
    :func:`~scara_pin.motion.payload.with_payload`).

    Raises:
        InvalidInputError: a joint with more than one degree of freedom, or without a motion axis.
    """
    built = _BUILT.setdefault(robot.model, {})
    key = (int(robot.base_id), int(robot.tool_id))
    if key not in built:
        built[key] = _build(robot)
    return built[key]


def _build(robot: RobotModel) -> SymbolicModel:
    import casadi as ca

    joints, bMo = _joints(robot)
    dof = robot.dof
    eye = ca.DM.eye(3)

    def skew(w: Any) -> Any:
        return ca.vertcat(ca.horzcat(0, -w[2], w[1]), ca.horzcat(w[2], 0, -w[0]), ca.horzcat(-w[1], w[0], 0))

    def motion(joint: _Joint, theta: Any) -> tuple[Any, Any]:
        """(R, p) of the joint's own motion exp6(S_unit theta) and then its placement in the parent."""
        v, w = joint.twist[:3], joint.twist[3:]
        if np.linalg.norm(w) < _AXIS_TOL:
            R, p = eye, ca.DM(v) * theta
        else:
            K = skew(ca.DM(w))
            R = eye + ca.sin(theta) * K + (1.0 - ca.cos(theta)) * (K @ K)
            p = (eye - R) @ ca.DM(np.cross(w, v)) + ca.DM(w * float(w @ v)) * theta
        Rp = ca.DM(joint.rotation)
        return Rp @ R, Rp @ p + ca.DM(joint.translation)

    q = ca.SX.sym("q", dof)
    qd = ca.SX.sym("qd", dof)
    qdd = ca.SX.sym("qdd", dof)
    n = len(joints)
    lR: list[Any] = [None] * (n + 1)
    lp: list[Any] = [None] * (n + 1)
    oR: list[Any] = [eye] + [None] * n
    op: list[Any] = [ca.DM.zeros(3)] + [None] * n
    for k, joint in enumerate(joints, 1):
        lR[k], lp[k] = motion(joint, joint.scaling * q[joint.source] + joint.offset)
        oR[k] = oR[joint.parent] @ lR[k]
        op[k] = oR[joint.parent] @ lp[k] + op[joint.parent]
    frame = robot.model.frames[robot.tool_id]
    j_tool = int(frame.parentJoint)
    p_world = oR[j_tool] @ ca.DM(frame.placement.translation) + op[j_tool]
    p_base = ca.DM(bMo.rotation) @ p_world + ca.DM(bMo.translation)
    tool = ca.Function("tool_position", [q], [p_base], ["q"], ["p"])
    tool_velocity = ca.Function("tool_velocity", [q, qd], [ca.jtimes(p_base, q, qd)], ["q", "qd"], ["v"])

    # recursive Newton-Euler (module docstring): forward velocities and accelerations, backward forces
    zero = ca.DM.zeros(3)
    vel: list[tuple[Any, Any]] = [(zero, zero)] + [(zero, zero)] * n
    gravity = ca.DM(-np.asarray(robot.model.gravity.linear, dtype=float))
    acc: list[tuple[Any, Any]] = [(gravity, zero)] + [(zero, zero)] * n
    force: list[list[Any]] = [[zero, zero] for _ in range(n + 1)]
    for k, joint in enumerate(joints, 1):
        R, p = lR[k], lp[k]
        S = joint.twist * joint.scaling
        Sv, Sw = ca.DM(S[:3]), ca.DM(S[3:])
        pv, pw = vel[joint.parent]
        pav, paw = acc[joint.parent]
        w = R.T @ pw + Sw * qd[joint.source]
        v = R.T @ (pv - ca.cross(p, pw)) + Sv * qd[joint.source]
        jv, jw = Sv * qd[joint.source], Sw * qd[joint.source]
        aw = R.T @ paw + Sw * qdd[joint.source] + ca.cross(w, jw)
        av = R.T @ (pav - ca.cross(p, paw)) + Sv * qdd[joint.source] + ca.cross(w, jv) + ca.cross(v, jw)
        vel[k], acc[k] = (v, w), (av, aw)
        c, Ic, m = ca.DM(joint.lever), ca.DM(joint.inertia), joint.mass
        fa = m * (av - ca.cross(c, aw))  # inertia times acceleration (linear, angular)
        na = Ic @ aw + ca.cross(c, fa)
        fv = m * (v - ca.cross(c, w))  # momentum
        nv = Ic @ w + ca.cross(c, fv)
        force[k] = [fa + ca.cross(w, fv), na + ca.cross(w, nv) + ca.cross(v, fv)]
    tau: list[Any] = [0] * dof
    for k in range(n, 0, -1):
        joint = joints[k - 1]
        S = joint.twist * joint.scaling
        f, m_ = force[k]
        tau[joint.source] = tau[joint.source] + ca.dot(ca.DM(S[:3]), f) + ca.dot(ca.DM(S[3:]), m_)
        if joint.parent > 0:
            F = lR[k] @ f
            force[joint.parent][0] = force[joint.parent][0] + F
            force[joint.parent][1] = force[joint.parent][1] + ca.cross(lp[k], F) + lR[k] @ m_
    rnea = ca.Function("inverse_dynamics", [q, qd, qdd], [ca.vertcat(*tau)], ["q", "qd", "qdd"], ["tau"])
    placements = ca.densify(ca.horzcat(*[ca.vertcat(ca.vec(oR[k]), op[k]) for k in range(n + 1)]))
    frames = ca.Function("joint_frames", [q], [placements], ["q"], ["frames"])
    twists = np.vstack([np.zeros(6)] + [j.twist for j in joints])
    sources = np.array([-1] + [j.source for j in joints])
    scalings = np.array([0.0] + [j.scaling for j in joints])
    return SymbolicModel(tool, tool_velocity, rnea, dof, frames, twists, sources, scalings)
