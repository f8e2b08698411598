"""One exception tree for the whole package.

Every error raised on purpose by scara_pin is a :class:`ScaraError`. Each subclass carries the data that
explains it and an ``exit_code`` that the command line uses: 2 for invalid input, 3 for an infeasible
request, 1 for an internal error (a bug, or a broken installation).
"""

from __future__ import annotations

from pathlib import Path
from typing import ClassVar

_BRIEF_CHARS = 60


def brief(value: object, chars: int = _BRIEF_CHARS) -> str:
    """``value`` as text for a message, at most about ``chars`` characters, whatever its size.

    A string is quoted (``repr``); a number or a NumPy array as ``str`` shows it; a list, dict or other
    container is walked only as far as the text needs (``reprlib``: at most 6 items per level, 3 levels),
    never whole: a value read from a file may stand for billions of items (a yaml alias bomb).
    """
    import reprlib

    class Brief(reprlib.Repr):
        def repr1(self, x: object, level: int) -> str:
            # subclasses of dict, list and tuple (yaml data) too: reprlib dispatches on the exact type's name
            for kind, method in ((dict, self.repr_dict), (list, self.repr_list), (tuple, self.repr_tuple)):
                if isinstance(x, kind):
                    return method(x, level)  # type: ignore[arg-type]
            return super().repr1(x, level)

    if isinstance(value, (int, float)) or type(value).__module__ == "numpy":
        text = str(value)
    else:
        shorten = Brief()
        shorten.maxlevel, shorten.maxstring, shorten.maxother = 3, chars, chars
        shorten.maxlist = shorten.maxtuple = shorten.maxdict = shorten.maxset = 6
        text = shorten.repr(value)
    return text if len(text) <= chars else text[: chars - 3] + "..."

__all__ = [
    "DescriptionError",
    "InfeasibleError",
    "InvalidInputError",
    "JobFileError",
    "JobStepError",
    "NoSolutionError",
    "ParameterError",
    "ScaraError",
    "UnknownRobotError",
    "UrdfError",
    "YamlError",
    "brief",
]


class ScaraError(Exception):
    """Base class of the errors scara_pin raises on purpose.

    Every one survives ``pickle`` (a task's error on a Dask worker travels to the client that way): it is rebuilt
    from its message and its attributes, without calling an ``__init__`` that takes more than ``args`` keeps
    (``ParameterError(name, value, rule)``, ``NoSolutionError(status, reason)``...).
    """

    exit_code: ClassVar[int] = 1

    def __reduce__(self) -> tuple[object, ...]:
        return _rebuild, (type(self), self.args, dict(self.__dict__))


def _rebuild(cls: type[ScaraError], args: tuple[object, ...], state: dict[str, object]) -> ScaraError:
    """A pickled :class:`ScaraError` again: its class, its ``args`` (the message) and its attributes."""
    error = cls.__new__(cls)
    Exception.__init__(error, *args)
    error.__dict__.update(state)
    return error


class InvalidInputError(ScaraError, ValueError):
    """The caller gave something that cannot be used (exit code 2)."""

    exit_code: ClassVar[int] = 2


class ParameterError(InvalidInputError):
    """A robot parameter or a numeric input breaks a rule.

    Attributes:
        name: the parameter, e.g. ``"l1"`` or ``"joint2_velocity"``.
        value: the offending value, as given.
        rule: the rule it breaks, e.g. ``"must be > 0"``.
    """

    NOTHING: ClassVar[object] = object()
    """Pass as ``value`` when there is no value to show (a missing key, an unreadable file)."""

    def __init__(self, name: str, value: object, rule: str, unit: str = "") -> None:
        self.name = name
        self.value = value
        self.rule = rule
        if value is ParameterError.NOTHING:  # nothing to show: a missing or unreadable item
            super().__init__(f"{name} {rule}")
            return
        shown = brief(value)
        super().__init__(f"{name} is {shown}{(' ' + unit) if unit else ''}; it {rule}")


class YamlError(InvalidInputError):
    """A yaml document that is not read: invalid, not plain data, or over a cap (exit code 2).

    Attributes:
        origin: the document, e.g. ``"points file cell.yaml"``.
        line: the line (from 1) where the problem is, or None.
        problem: what is wrong, e.g. ``"did not find expected node content"``.
        refused: True for a document that is valid yaml but over a cap (or recursive); False for invalid yaml.
    """

    def __init__(self, origin: str, line: int | None, problem: str, refused: bool = False) -> None:
        self.origin = origin
        self.line = line
        self.problem = problem
        self.refused = refused
        where = "" if line is None else f" line {line}"
        super().__init__(f"{origin}{where}: {problem}" if refused else f"{origin}{where}: not valid YAML ({problem})")


class UnknownRobotError(InvalidInputError):
    """No robot configuration of that name or path."""

    def __init__(self, robot: str, available: list[str]) -> None:
        self.robot = robot
        self.available = available
        super().__init__(
            f"unknown robot {robot!r}: not a shipped robot ({', '.join(available)}) "
            "nor a folder holding kinematics.yaml, joint_limits.yaml and physical_parameters.yaml"
        )


class UrdfError(InvalidInputError):
    """A URDF that cannot be loaded, or that is not a usable robot."""


class InfeasibleError(ScaraError):
    """A valid request that the robot cannot carry out (exit code 3)."""

    exit_code: ClassVar[int] = 3


class NoSolutionError(InfeasibleError):
    """An IK target without a solution inside the joint limits (exit code 3).

    Attributes:
        status: the stable reason code (``IKStatus`` or ``PalletizerIKStatus``), e.g. ``OUT_OF_REACH``.
        reason: the sentence with the numbers behind it.
    """

    def __init__(self, status: object, reason: str) -> None:
        self.status = status
        self.reason = reason
        super().__init__(f"{getattr(status, 'name', status)}: {reason}")


class DescriptionError(ScaraError):
    """The packaged description templates failed to expand (a bug or a broken install; exit code 1)."""


class _Located(Exception):
    """An error in a job file: the file, the line (or None) and the reason, said in that order."""

    path: Path
    line: int | None
    reason: str

    def __init__(self, path: Path, line: int | None, reason: str) -> None:
        self.path = path
        self.line = line
        self.reason = reason
        super().__init__(f"{path}{f' line {line}' if line is not None else ''}: {reason}")


class JobFileError(_Located, InvalidInputError):
    """A job file that cannot be run as written (exit code 2): what is wrong, and where.

    Attributes:
        path: the job file.
        line: the line (from 1) of the offending value, or None when it has none (the file itself).
        reason: the sentence.
    """


class JobStepError(_Located, InfeasibleError):
    """A step of a job the robot cannot make (exit code 3): a place out of reach, a move the planner cannot plan.

    Attributes:
        path: the job file.
        line: the line (from 1) of the step.
        reason: the sentence.
    """
