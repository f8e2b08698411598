"""Robot parameters (yaml) and the URDF generated from them with xacro.

Two kinds of robot are described: ``scara`` (the default) and ``palletizer`` (source S2's
double-parallelogram arm). ``kinematics.yaml`` chooses the kind with a top-level ``kind:`` key
(absent: ``scara``); each kind has its own parameter schema (:data:`SCHEMAS`) and entry xacro.

The yaml files under ``urdf/config/<robot>/`` are the single source of truth. For a SCARA:

- ``kinematics.yaml``: ``base_height``, ``d1``, ``l1``, ``d2``, ``l2``, ``d3`` and ``tool: {x, y, z, yaw}``;
- ``joint_limits.yaml``: per joint ``lower``, ``upper``, ``velocity``, ``acceleration``, ``effort``;
- ``physical_parameters.yaml``: per body (``base``, ``link1``, ``link2``, ``quill``, ``flange``) its
  ``mass`` and ``radius`` (and ``length`` for the quill and the flange).

For a palletizer see ``urdf/config/palletizer/*.yaml`` and :data:`PALLETIZER_PARAMETER_NAMES`.

Parameters are addressed by flat names (``l1``, ``tool_x``, ``joint2_velocity``, ``quill_mass``): the
nested yaml keys joined by ``_``. Every value is validated here, BEFORE xacro runs, and reaches xacro
only as the text ``repr(float(v))`` of a finite number: xacro evaluates ``${...}`` expressions in a
sandbox that can be escaped, so no user-supplied text may ever reach it.

Units are SI: [m], [rad], [kg], [rad/s] or [m/s], [rad/s^2] or [m/s^2], [N m] or [N]. The yaml files
may write angles as ``!degrees 132`` (xacro's yaml tag), read here as radians, as xacro reads them.
"""

from __future__ import annotations

import math
import numbers
import re
from collections.abc import Callable, Mapping
from dataclasses import InitVar, dataclass, field
from pathlib import Path
from types import MappingProxyType
from typing import Any

from ..errors import DescriptionError, InvalidInputError, ParameterError, UnknownRobotError, YamlError
from ..units import number_text

__all__ = [
    "JOINT_COUNTS",
    "JOINT_NAMES",
    "PALLETIZER_PARAMETER_NAMES",
    "PARAMETER_NAMES",
    "SCHEMAS",
    "JointLimits",
    "RobotParameters",
    "available_robots",
    "config_files",
    "configured",
    "generate_urdf",
    "load_parameters",
    "parameter_names",
    "urdf_dir",
]

JOINT_NAMES: tuple[str, ...] = ("joint1", "joint2", "joint3", "joint4")
JOINT_COUNTS: tuple[int, ...] = (4, 3)
"""The joint counts of q a robot may have (THE rule; ``Robot.dof`` reads it from the model): 4 (a SCARA with
a wrist, a palletizer) or 3 (a SCARA without a wrist: two revolute joints and a prismatic one)."""
"""The four joints, in URDF (and q) order."""

_KINEMATICS = ("base_height", "d1", "l1", "d2", "l2", "d3", "tool_x", "tool_y", "tool_z", "tool_yaw")
_LIMIT_FIELDS = ("lower", "upper", "velocity", "acceleration", "effort")
_LIMITS = tuple(f"{j}_{f}" for j in JOINT_NAMES for f in _LIMIT_FIELDS)
_PHYSICAL = (
    "base_mass", "base_radius", "link1_mass", "link1_radius", "link2_mass", "link2_radius",
    "quill_mass", "quill_radius", "quill_length", "flange_mass", "flange_radius", "flange_length",
)  # fmt: skip
_FILES: dict[str, tuple[str, ...]] = {
    "kinematics.yaml": _KINEMATICS,
    "joint_limits.yaml": _LIMITS,
    "physical_parameters.yaml": _PHYSICAL,
}
PARAMETER_NAMES: tuple[str, ...] = _KINEMATICS + _LIMITS + _PHYSICAL
"""Every parameter, by its flat name (the names ``--set key=value`` accepts)."""

# Parameters that must be strictly positive: lengths of bodies, masses and the speed/force limits.
_POSITIVE = frozenset(
    {"l1", "l2"}
    | {n for n in _PHYSICAL}
    | {f"{j}_{f}" for j in JOINT_NAMES for f in ("velocity", "acceleration", "effort")}
)

# The palletizer (S2): lengths a1..a4, heights d1, d2, d5 (see config/palletizer/kinematics.yaml).
_P_KINEMATICS = ("d1", "d2", "a1", "a2", "a3", "a4", "d5", "tool_yaw")
_P_PHYSICAL = (
    "base_mass", "base_radius", "turret_mass", "turret_radius", "big_arm_mass", "big_arm_radius",
    "small_arm_mass", "small_arm_radius", "wrist_mass", "wrist_radius",
    "flange_mass", "flange_radius", "flange_length",
)  # fmt: skip
PALLETIZER_PARAMETER_NAMES: tuple[str, ...] = _P_KINEMATICS + _LIMITS + _P_PHYSICAL
"""Every parameter of a palletizer, by its flat name."""


def _scara_rules(values: Mapping[str, float]) -> None:
    column = values["base_height"] + values["d1"]
    if column <= 0:
        raise ParameterError("base_height + d1", column, "(the column from the floor to joint1) must be > 0")


def _palletizer_rules(values: Mapping[str, float]) -> None:
    # d1, d2 (the base's and the turret's heights, drawn as cylinders) are in the positive set
    if values["a1"] < 0:
        raise ParameterError("a1", values["a1"], "(the shoulder's offset from the waist axis) must be >= 0")


@dataclass(frozen=True)
class _Schema:
    """The parameters of one kind of robot: per yaml file its flat names, the rules, the entry xacro."""

    kind: str
    files: Mapping[str, tuple[str, ...]]
    positive: frozenset[str]
    rules: Callable[[Mapping[str, float]], None]
    entry: str

    @property
    def names(self) -> tuple[str, ...]:
        return tuple(n for names in self.files.values() for n in names)

    @property
    def xacro_args(self) -> tuple[str, ...]:
        return tuple(n for n in self.names if not n.endswith("_acceleration"))


SCHEMAS: Mapping[str, _Schema] = MappingProxyType({
    "scara": _Schema("scara", MappingProxyType(_FILES), _POSITIVE, _scara_rules, "scara.urdf.xacro"),
    "palletizer": _Schema(
        "palletizer",
        MappingProxyType({"kinematics.yaml": _P_KINEMATICS, "joint_limits.yaml": _LIMITS,
                          "physical_parameters.yaml": _P_PHYSICAL}),
        frozenset({"a2", "a3", "d1", "d2"} | set(_P_PHYSICAL)
                  | {f"{j}_{f}" for j in JOINT_NAMES for f in ("velocity", "acceleration", "effort")}),
        _palletizer_rules,
        "palletizer.urdf.xacro",
    ),
})  # fmt: skip
"""Parameter schema per robot kind (the ``kind:`` key of kinematics.yaml; ``scara`` when absent)."""


def parameter_names(kind: str = "scara") -> tuple[str, ...]:
    """The flat parameter names of a robot kind (``"scara"`` or ``"palletizer"``)."""
    return _schema(kind).names


def _schema(kind: object) -> _Schema:
    if not isinstance(kind, str) or kind not in SCHEMAS:
        raise ParameterError("kind", kind, f"must be one of {', '.join(SCHEMAS)}")
    return SCHEMAS[kind]


_NAME_RE = re.compile(r"[A-Za-z][A-Za-z0-9_]*\Z")
_PREFIX_RE = re.compile(r"[A-Za-z0-9_]*\Z")
_ENTRY = "scara.urdf.xacro"


def urdf_dir() -> Path:
    """The folder of the description: ``scara.urdf.xacro``, the macro, ``inc/`` and ``config/``.

    Installed from a wheel it lies inside the package (``scara_pin/urdf``); in a source checkout it is
    the repository's top-level ``urdf/``.
    """
    here = Path(__file__).resolve().parent.parent  # the scara_pin package
    for candidate in (here / "urdf", here.parent / "urdf"):
        if (candidate / _ENTRY).is_file():
            return candidate
    raise DescriptionError(f"the robot description ({_ENTRY}) is missing from the installation at {here}")


def available_robots() -> list[str]:
    """Names of the shipped robot configurations, sorted."""
    config = urdf_dir() / "config"
    return sorted(p.name for p in config.iterdir() if (p / "kinematics.yaml").is_file())


@dataclass(frozen=True)
class JointLimits:
    """Limits of the four joints, in q order, as float tuples.

    Attributes:
        lower: lower position limit [rad] or [m].
        upper: upper position limit [rad] or [m].
        velocity: velocity limit [rad/s] or [m/s].
        acceleration: acceleration limit [rad/s^2] or [m/s^2].
        effort: effort limit [N m] or [N].
        validate: check the limits (finite, lower < upper, the rest > 0); ``False`` keeps a foreign
            URDF's limits as written (they may be placeholders such as 0).
    """

    lower: tuple[float, ...]
    upper: tuple[float, ...]
    velocity: tuple[float, ...]
    acceleration: tuple[float, ...]
    effort: tuple[float, ...]
    validate: InitVar[bool] = True

    def __post_init__(self, validate: bool) -> None:
        if not validate:  # limits read from a foreign URDF, kept as written
            return
        for name in _LIMIT_FIELDS:
            values = getattr(self, name)
            if len(values) != len(JOINT_NAMES):
                raise ParameterError(name, values, f"must hold {len(JOINT_NAMES)} values")
            for joint, value in zip(JOINT_NAMES, values):
                _check_finite(f"{joint}_{name}", value)
                if name not in ("lower", "upper") and value <= 0:
                    raise ParameterError(f"{joint}_{name}", value, "must be > 0")
        for joint, lo, hi in zip(JOINT_NAMES, self.lower, self.upper):
            if not lo < hi:
                raise ParameterError(f"{joint}_lower", lo, f"must be < {joint}_upper = {hi}")


@dataclass(frozen=True)
class RobotParameters:
    """The validated parameters of one robot.

    Attributes:
        name: the robot's name (its config folder's name).
        values: every parameter by flat name (see :func:`parameter_names` of ``kind``), SI units.
        source: the config folder the values were read from.
        kind: ``"scara"`` or ``"palletizer"`` (see :data:`SCHEMAS`).
    """

    name: str
    values: Mapping[str, float]
    source: Path | None = field(default=None, compare=False)
    kind: str = "scara"

    def __post_init__(self) -> None:
        schema = _schema(self.kind)
        names = schema.names
        values = dict(self.values)
        missing = [n for n in names if n not in values]
        if missing:
            raise ParameterError(missing[0], ParameterError.NOTHING, "is required (missing)")
        for key, value in values.items():
            if key not in names:
                raise ParameterError(key, value, f"is not a parameter; known: {', '.join(names)}")
            _check_finite(key, value)
            if key in schema.positive and value <= 0:
                raise ParameterError(key, value, "must be > 0")
        schema.rules(values)
        object.__setattr__(self, "values", MappingProxyType({k: float(values[k]) for k in names}))
        object.__setattr__(self, "limits", self._limits())

    limits: JointLimits = field(init=False, compare=False)

    def _limits(self) -> JointLimits:
        v = self.values
        columns = (tuple(v[f"{j}_{f}"] for j in JOINT_NAMES) for f in _LIMIT_FIELDS)
        lower, upper, velocity, acceleration, effort = columns
        return JointLimits(lower, upper, velocity, acceleration, effort)

    def __getitem__(self, key: str) -> float:
        return self.values[key]

    def with_overrides(self, overrides: Mapping[str, object]) -> RobotParameters:
        """A copy with some parameters replaced.

        Args:
            overrides: flat name -> number, or the text of a number (``"0.25"``); checked before use.

        Raises:
            ParameterError: an unknown name, a value that is not a finite number, or a broken rule.
        """
        names = _schema(self.kind).names
        values = dict(self.values)
        for key, raw in overrides.items():
            if key not in names:
                raise ParameterError(key, raw, f"is not a parameter; known: {', '.join(names)}")
            values[key] = _to_float(key, raw)
        return RobotParameters(self.name, values, self.source, self.kind)

    def xacro_mappings(self, prefix: str = "") -> dict[str, str]:
        """The xacro arguments: each value as ``repr(float(v))``, and the (checked) name prefix."""
        if not _PREFIX_RE.match(prefix):
            raise ParameterError("prefix", prefix, "may hold only letters, digits and '_'")
        mappings = {n: repr(float(self.values[n])) for n in _schema(self.kind).xacro_args}
        mappings["prefix"] = prefix
        return mappings


def _check_finite(name: str, value: object) -> None:
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise ParameterError(name, value, "must be a number")
    if not math.isfinite(value):
        raise ParameterError(name, value, "must be finite")


def _to_float(name: str, raw: object) -> float:
    """A finite float from a number or the text of one (the grammar of :data:`scara_pin.units.NUMBER_TEXT`)."""
    if isinstance(raw, str):
        value = number_text(raw)
        if math.isnan(value):
            if raw.strip().lower().lstrip("+-") in ("nan", "inf", "infinity"):
                raise ParameterError(name, raw, "must be finite")
            raise ParameterError(name, raw, "must be a number such as 0.25, -3, 1.5e-3 (ASCII digits, no _)")
    elif isinstance(raw, bool) or not isinstance(raw, numbers.Real):
        raise ParameterError(name, raw, "must be a number")
    else:
        value = float(raw)
    _check_finite(name, value)
    return value


def _flatten(tree: object, prefix: str, out: dict[str, object]) -> None:
    if isinstance(tree, dict):
        for key, value in tree.items():
            _flatten(value, f"{prefix}_{key}" if prefix else str(key), out)
    else:
        out[prefix] = tree


def _read_yaml_text(path: Path) -> str:
    from ..limits import check_input_file, read_text

    try:
        return read_text(check_input_file(path, "yaml file"), "yaml file")
    except InvalidInputError as exc:
        raise ParameterError(str(path), ParameterError.NOTHING, f"cannot be read ({exc})") from None


_CONFIG_FILES = ("kinematics.yaml", "joint_limits.yaml", "physical_parameters.yaml")


def _config_texts(folder: Path) -> dict[str, str]:
    """The three yaml files of a config folder, read with the bounds of every input (a FIFO is refused)."""
    return {name: _read_yaml_text(folder / name) for name in _CONFIG_FILES}


def _read_config(folder: Path, texts: Mapping[str, str] | None = None) -> tuple[str, dict[str, float]]:
    """(kind, flat values) of a config folder (or of its files' ``texts``); the kind is kinematics.yaml's ``kind:``."""
    from .yaml_units import load_yaml

    texts = _config_texts(folder) if texts is None else texts
    values: dict[str, float] = {}
    schema = SCHEMAS["scara"]
    for filename in _CONFIG_FILES:
        path = folder / filename
        try:
            tree = load_yaml(texts[filename], str(path))  # bounded: an alias bomb is refused
        except YamlError as exc:
            where = f" line {exc.line}" if exc.line is not None else ""
            rule = f"is refused: {exc.problem}" if exc.refused else f"must be valid yaml ({exc.problem})"
            raise ParameterError(f"{path}{where}", ParameterError.NOTHING, rule) from None
        flat: dict[str, object] = {}
        if filename == "kinematics.yaml" and isinstance(tree, dict) and "kind" in tree:
            tree = dict(tree)
            kind = tree.pop("kind")
            try:
                schema = _schema(kind)
            except ParameterError as exc:
                raise ParameterError(f"kind in {path}", kind, exc.rule) from None
        expected = schema.files[filename]
        _flatten(tree if tree is not None else {}, "", flat)
        for key, raw in flat.items():
            if key not in expected:
                raise ParameterError(f"{key} in {path}", raw, f"is not a parameter of {filename}")
            try:
                values[key] = _to_float(key, raw)
            except ParameterError as exc:
                raise ParameterError(f"{key} in {path}", raw, exc.rule) from None
        for key in expected:
            if key not in flat:
                raise ParameterError(f"{key} in {path}", ParameterError.NOTHING, "is required (missing)")
    return schema.kind, values


def _config_folder(robot: str | Path) -> tuple[str, Path]:
    """Resolve a robot name or a config folder path to (name, folder)."""
    text = str(robot)
    folder = Path(text)
    shipped = _NAME_RE.match(text) is not None and (urdf_dir() / "config" / text / "kinematics.yaml").is_file()
    if not shipped and (isinstance(robot, Path) or "/" in text or "\\" in text or folder.is_dir()):
        if (folder / "kinematics.yaml").is_file():
            name = folder.resolve().name
            return (name if _NAME_RE.match(name) else "scara"), folder
        raise UnknownRobotError(text, available_robots())
    if _NAME_RE.match(text):
        folder = urdf_dir() / "config" / text
        if (folder / "kinematics.yaml").is_file():
            return text, folder
    raise UnknownRobotError(text, available_robots())


def config_files(robot: str | Path) -> tuple[Path, ...]:
    """The yaml files of a shipped robot's name or of a config folder (the files its parameters are read from).

    Raises:
        UnknownRobotError: no such robot or folder.
    """
    return tuple(_config_folder(robot)[1] / name for name in _CONFIG_FILES)


def load_parameters(
    robot: str | Path | RobotParameters = "default", overrides: Mapping[str, object] | None = None
) -> RobotParameters:
    """Read and validate a robot's parameters.

    Args:
        robot: a shipped robot's name (see :func:`available_robots`), a config folder holding the three
            yaml files, or parameters already loaded.
        overrides: flat parameter name -> value (a number or its text), applied after reading.

    Returns:
        The validated parameters.

    Raises:
        UnknownRobotError: no such robot or folder.
        ParameterError: a missing, unknown, non-finite or rule-breaking parameter.
    """
    if isinstance(robot, RobotParameters):
        params = robot
    else:
        name, folder = _config_folder(robot)
        kind, values = _read_config(folder)
        params = RobotParameters(name, values, folder, kind)
    return params.with_overrides(overrides) if overrides else params


def configured(
    robot: str | Path | RobotParameters = "default", overrides: Mapping[str, object] | None = None
) -> tuple[RobotParameters, str]:
    """A configured robot's parameters and generated URDF, as :func:`load_parameters` and :func:`generate_urdf`.

    For a shipped robot or a config folder both come from the description cache when nothing they are
    made from has changed (:mod:`scara_pin.description.cache`: the yaml files, the xacro templates, xacro
    itself, the overrides); otherwise they are made and cached.
    """
    if isinstance(robot, RobotParameters):
        params = load_parameters(robot, overrides)
        return params, generate_urdf(params)
    from .cache import DescriptionCache

    name, folder = _config_folder(robot)
    texts = _config_texts(folder)
    values = {k: _to_float(k, v) for k, v in (overrides or {}).items()}
    cache = DescriptionCache.default()
    key = cache.key(name, folder, texts, values, urdf_dir())
    hit = cache.get(key)
    if hit is not None:
        try:
            params = RobotParameters(name, hit["values"], folder, hit["kind"])
            return params, hit["urdf"]
        except (ParameterError, KeyError, TypeError):  # a cache file that does not hold what it should
            pass
    kind, read = _read_config(folder, texts)
    params = RobotParameters(name, read, folder, kind)
    params = params.with_overrides(values) if values else params
    urdf = generate_urdf(params)
    cache.put(key, {"kind": params.kind, "values": dict(params.values), "urdf": urdf})
    return params, urdf


def generate_urdf(
    robot: str | Path | RobotParameters = "default",
    overrides: Mapping[str, object] | None = None,
    *,
    prefix: str = "",
) -> str:
    """Expand the robot kind's entry xacro (``urdf/scara.urdf.xacro``, ``urdf/palletizer.urdf.xacro``).

    Args:
        robot: as in :func:`load_parameters`.
        overrides: as in :func:`load_parameters`.
        prefix: prepended to every link and joint name (letters, digits and ``_`` only).

    Returns:
        The URDF document as a string.
    """
    import xacro

    from .packages import xacro_lock

    params = load_parameters(robot, overrides)
    mappings = params.xacro_mappings(prefix)
    entry = urdf_dir() / _schema(params.kind).entry
    try:
        # xacro keeps (and mutates) the mappings dict it is given: hand it a copy; its state is global
        with xacro_lock:
            doc = xacro.process_file(str(entry), mappings=dict(mappings))
    except Exception as exc:  # xacro raises plain Exceptions too; all mean a broken template here
        raise DescriptionError(f"xacro failed on {entry}: {exc}") from exc
    doc.documentElement.setAttribute("name", params.name)
    return _pretty(doc)


def _pretty(doc: Any) -> str:
    # drop xacro's banner (it names the absolute path of the template, which varies between installs)
    for node in list(doc.childNodes):
        if node.nodeType == node.COMMENT_NODE:
            doc.removeChild(node)
    return str(doc.toprettyxml(indent="  "))
