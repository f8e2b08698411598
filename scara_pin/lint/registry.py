"""The rules of ``scara-pin check``, in one table, in the order they run (``scara-pin check --list-rules``).

A rule is a small function of the :class:`~scara_pin.lint.context.Context` that adds the findings of its
code. The table gives each its code, family (the module it lives in), the most severe finding it makes, and
one line saying what it finds. Two flags place it in the run:

- ``gate``: the checks stop after it when the file has an error so far (what follows needs a well-formed
  tree: one root, named links and joints, finite numbers, existing frames);
- ``model``: it reads the robot as the toolkit loads it, which is tried only on a file without errors.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

from . import frames, geometry, joints, scope, tree
from .context import Context, Stop
from .report import Severity

__all__ = ["FAMILIES", "RULES", "Rule", "rules_text", "run"]

FAMILIES = {
    "tree": "tree and names",
    "joints": "joints and limits",
    "frames": "frames and axes",
    "geometry": "geometry and meshes",
    "scope": "scope",
}
"""The families of rules (their modules) and what each covers."""


@dataclass(frozen=True)
class Rule:
    """One rule of ``check``.

    Attributes:
        code: the code of its findings (``Finding.code``).
        family: its module (a key of :data:`FAMILIES`).
        severity: the most severe finding it makes (some report less where it matters less).
        summary: what it finds, in one line.
        check: the function adding its findings.
        gate: stop the checks after it when the file has an error.
        model: it needs the file loaded by the toolkit (skipped once the file has an error).
    """

    code: str
    family: str
    severity: Severity
    summary: str
    check: Callable[[Context], None]
    gate: bool = False
    model: bool = False


E, W, I = Severity.ERROR, Severity.WARNING, Severity.INFO  # noqa: E741

RULES: tuple[Rule, ...] = (
    Rule("unreadable", "tree", E, "a file that cannot be read (missing, too large, not UTF-8)", tree.unreadable,
         gate=True),
    Rule("xacro-failed", "tree", E, "a .xacro file that cannot be expanded", tree.xacro_failed, gate=True),
    Rule("malformed-xml", "tree", E, "the text is not well-formed XML", tree.malformed_xml, gate=True),
    Rule("root-not-robot", "tree", E, "the root element is not <robot>", tree.root_not_robot, gate=True),
    Rule("too-large", "tree", E, "more links and joints than check reads (MAX_CHECK_ELEMENTS)", tree.too_large,
         gate=True),
    Rule("xacro-not-expanded", "tree", E, "xacro that changes the robot (a macro, a condition, a substitution)",
         tree.xacro_not_expanded, gate=True),
    Rule("xacro-ignored", "tree", W, "only xacro declarations the document never substitutes: ignored",
         tree.xacro_ignored),
    Rule("missing-name", "tree", E, "a <link> or <joint> without a name", tree.missing_name),
    Rule("duplicate-name", "tree", E, "two links, or two joints, of one name", tree.duplicate_name),
    Rule("joint-type", "tree", E, "a joint type URDF does not have (floating/planar: a warning)", tree.joint_type),
    Rule("missing-link", "tree", E, "a joint's parent or child is no link of the file", tree.missing_link),
    Rule("bad-number", "joints", E, "an origin, axis or limit that is not finite numbers, or a zero axis",
         joints.bad_number),
    Rule("colour-ignored", "geometry", W, "a colour urdfdom cannot read (rgb=, a malformed rgba): ignored",
         geometry.colour_ignored),
    Rule("bad-inertial", "geometry", E, "a mass or inertia that is not finite, or a negative mass",
         geometry.bad_inertial, gate=True),
    Rule("two-parents", "tree", E, "a link that is the child of two joints", tree.two_parents, gate=True),
    Rule("disconnected", "tree", E, "not one tree: no link, several root links, or a cycle", tree.disconnected,
         gate=True),
    Rule("frame-missing", "frames", E, "--tool or --base names no link, or a base that moves", frames.frame_missing,
         gate=True),
    Rule("locked", "tree", I, "free joints off the chain root -> tool: locked", tree.locked),
    Rule("geared", "tree", I, "a <mimic> joint: it follows another, not in q", tree.geared),
    Rule("mimic-unresolved", "tree", E, "a <mimic> that leads to no free joint (a loop...) or Pinocchio cannot take",
         tree.mimic_unresolved),
    Rule("mimic-ignored", "tree", W, '<mimic joint="">: it names no joint; ignored, the joint is free',
         tree.mimic_ignored),
    Rule("joints", "tree", I, "the joints of q in chain order", tree.joints),
    Rule("not-serial", "tree", E, "joints hung off the chain (not downstream of one another)", tree.not_serial),
    Rule("joint-count", "tree", E, "not 4 joints (3 without a wrist)", tree.joint_count),
    Rule("no-wrist", "tree", I, "3 joints: a SCARA without a wrist", tree.no_wrist),
    Rule("continuous-joint", "joints", W, "a continuous joint: Pinocchio's (cos, sin), one angle in q",
         joints.continuous_joint),
    Rule("limit-missing", "joints", E, "no <limit>, effort or velocity (urdfdom refuses it), or no lower/upper",
         joints.limit_missing),
    Rule("limits-inverted", "joints", E, "lower > upper", joints.limits_inverted),
    Rule("limits-empty", "joints", E, "lower = upper: the joint cannot move", joints.limits_empty),
    Rule("limits-implausible", "joints", W, "revolute limits beyond +/-4 pi, strokes beyond 5 m (units?)",
         joints.limits_implausible),
    Rule("velocity-zero", "joints", W, "a velocity limit of 0: a placeholder", joints.velocity_zero),
    Rule("velocity-placeholder", "joints", W, "a velocity limit of 100, 1000, 10000, or one value on every joint",
         joints.velocity_placeholder),
    Rule("velocity-implausible", "joints", W, "outside 0.05..50 rad/s or 0.05..10 m/s (a deg/s reading offered)",
         joints.velocity_implausible),
    Rule("tool-frame", "frames", I, "no tool0: which link is the tool, why, and the other ends of the tree",
         frames.tool_frame),
    Rule("tool-ambiguous", "frames", W, "no tool0, and links ending equally long chains with no name to decide",
         frames.tool_ambiguous),
    Rule("wrist-tilted", "frames", W, "the wrist's axis alone tilted, up to 0.1 rad: refined on the model",
         frames.wrist_tilted),
    Rule("axis-tilted", "frames", W, "an axis more than 1e-2 rad from vertical: the closed form refuses it",
         frames.axis_tilted),
    Rule("axis-near-parallel", "frames", I, "an axis 1e-6..1e-2 rad from vertical", frames.axis_near_parallel),
    Rule("axis-flipped", "frames", W, "a revolute axis along base -z: q turns clockwise", frames.axis_flipped),
    Rule("axis-down", "frames", I, "a quill whose q grows downward", frames.axis_down),
    Rule("prismatic-position", "frames", W, "the prismatic joint of 4 is not the third: supported",
         frames.prismatic_position),
    Rule("zero-pose-folded", "frames", W, "the elbow folded back at q = 0", frames.zero_pose_folded),
    Rule("zero-pose-bent", "frames", I, "arm 2 turned from arm 1 at q = 0", frames.zero_pose_bent),
    Rule("zero-pose-direction", "frames", I, "arm 1 not along +x at q = 0: handled", frames.zero_pose_direction),
    Rule("length-implausible", "frames", W, "a joint origin beyond 10 m: millimetres?", frames.length_implausible),
    Rule("rpy-approximate", "frames", W, "an rpy such as 3.14 near k pi/2, with the tool error it makes",
         frames.rpy_approximate),
    Rule("not-loadable", "scope", E, "Pinocchio or the toolkit's loader refuses the file", scope.not_loadable,
         model=True),
    Rule("not-a-scara", "scope", W, "an arm of another layout: what it is, what applies", scope.not_a_scara,
         model=True),
    Rule("closed-form-refused", "scope", W, "the closed form refuses the model: numeric IK only",
         scope.closed_form_refused, model=True),
    Rule("palletizer", "scope", I, "recognised as a palletizer: its closed form applies", scope.palletizer,
         model=True),
    Rule("near-parallel", "scope", W, "near-parallel axes: the closed form's error without refinement",
         scope.near_parallel, model=True),
    Rule("effort-limit", "scope", W, "an effort limit of 0, or below the static load: torque-limited timing refuses",
         scope.effort_limit, model=True),
    Rule("motion-limits", "scope", I, "what cycle, traj, jog and job will need: --acceleration, --velocity",
         scope.motion_limits, model=True),
    Rule("mesh-missing", "geometry", W, "a visual's mesh the viewer cannot find or read", geometry.mesh_missing),
    Rule("mesh-path", "geometry", W, "a mesh named PyBullet's way (/Mesh/..., missing): read from the file's folder",
         geometry.mesh_path),
)  # fmt: skip
"""Every rule, in the order they run."""


def run(ctx: Context) -> None:
    """Run the rules of :data:`RULES` on ``ctx`` in order, stopping at a gate once the file has an error."""
    errors_before_model = None
    for rule in RULES:
        if rule.model:
            if errors_before_model is None:
                errors_before_model = ctx.has_errors
            if errors_before_model:
                continue
        try:
            rule.check(ctx)
        except Stop:
            return
        if rule.gate and ctx.has_errors:
            return


def rules_text() -> str:
    """One line per rule: code, severity, family, what it finds (``scara-pin check --list-rules``)."""
    width = max(len(r.code) for r in RULES)
    return "\n".join(f"{r.code:<{width}}  {r.severity.value:<7}  {r.family:<8}  {r.summary}" for r in RULES)
