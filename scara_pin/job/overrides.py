"""Variants of a job without editing it: a value of the job file replaced by its dotted key (one grammar).

``job --set frames.tray.xyz=[0.30, -0.06, -0.10]`` (or in Python ``job.replace({"frames.tray.xyz": [...]})``)
replaces what the file says at that key before the job is checked, so an override is read exactly as the
file's own value: the same yaml (flow lists, unit tags: ``base.yaw=!degrees 90``), the same units (the job's
``units:``), the same checks and messages (which name the override instead of a line). ``--speed P``,
``--accel P`` and ``--jerk J`` are ``--set speed=P``, ``--set accel=P``, ``--set jerk=J``.

The key is the path of mapping keys from the top of the file, separated by dots (``robot``, ``speed``,
``base.xyz``, ``frames.tray.yaw``, ``jump.rise``, ``pallets.tray.rows``, ``carry.xyz``); a list item is its
index from 0 (``steps.0.speed``). Mappings missing on the way are made (``base.xyz`` in a file without
``base:``); a key the job file does not know is refused by the checks as the file's own would be.
"""

from __future__ import annotations

import copy
import re
from collections.abc import Iterable, Mapping
from dataclasses import dataclass
from typing import Any

from ..errors import InvalidInputError, YamlError

__all__ = ["MAX_OVERRIDES", "Override", "apply_overrides", "as_overrides", "parse_override", "plain"]

MAX_OVERRIDES = 1000
"""The most overrides of one job (a sweep varies a few keys)."""
_KEY = re.compile(r"[A-Za-z0-9_\-]{1,64}(?:\.[A-Za-z0-9_\-]{1,64}){0,15}", re.ASCII)


@dataclass(frozen=True)
class Override:
    """One replaced value of a job file.

    Attributes:
        key: the dotted key (module docstring).
        value: the value, as the job file's yaml reads it (plain data).
        origin: how messages name it (``--set frames.tray.xyz``, ``--speed``, ``replace(speed=...)``).
    """

    key: str
    value: Any
    origin: str

    def __post_init__(self) -> None:
        if not isinstance(self.key, str) or not _KEY.fullmatch(self.key):
            raise InvalidInputError(f"{self.origin}: key {str(self.key)[:80]!r} must be names separated by dots "
                                    "(e.g. frames.tray.xyz, base.yaw, speed)")  # fmt: skip

    @property
    def path(self) -> tuple[str | int, ...]:
        """The key's parts: names, and list indices as numbers."""
        return tuple(int(p) if p.isdigit() else p for p in self.key.split("."))


def parse_override(text: str, origin: str = "--set") -> Override:
    """``KEY=VALUE`` of the command line: the value read by the job file's yaml loader (units tags and all).

    ``origin``: the option that gave it (messages name ``--set KEY``, or the option itself: ``--speed``).

    Raises:
        InvalidInputError: no ``=``, a key that is not dotted names, a value that is not yaml.
    """
    from ..description.yaml_units import load_yaml

    key, sep, value = text.partition("=")
    key = key.strip()
    shown = f"{origin} {text[:80]}"
    if not sep or not key:
        raise InvalidInputError(f"{shown}: an override has the form KEY=VALUE (e.g. frames.tray.xyz=[0.3, 0, -0.1], "
                                "speed=70)")  # fmt: skip
    try:
        parsed = load_yaml(value, f"{origin} {key}")
    except YamlError as exc:
        raise InvalidInputError(f"{shown}: the value is not yaml ({exc.problem})") from None
    return Override(key, plain(parsed), f"--set {key}" if origin == "--set" else origin)


def plain(value: Any) -> Any:
    """``value`` as plain mappings and lists (the yaml loader's line records left out: an override has no line)."""
    if isinstance(value, dict):
        return {k: plain(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [plain(v) for v in value]
    return value


def apply_overrides(tree: Any, overrides: Iterable[Override]) -> tuple[Any, dict[int, dict[Any, str]]]:
    """A copy of the job file's data with each override's value at its key, and where each went.

    Returns:
        (the new data, ``{id(container): {key: origin}}``: for the checks, which name the override in a message
        about a value it set, or about anything inside it).

    Raises:
        InvalidInputError: a key through a value that is neither a mapping nor a list, a list index past its end,
            more than :data:`MAX_OVERRIDES`.
    """
    items = list(overrides)
    if len(items) > MAX_OVERRIDES:
        raise InvalidInputError(f"{len(items):,} overrides of one job: above the cap of {MAX_OVERRIDES:,}")
    out = copy.deepcopy(tree) if items else tree
    placed: dict[int, dict[Any, str]] = {}
    for o in items:
        if not isinstance(out, dict):
            raise InvalidInputError(f"{o.origin}: the job file is not a mapping")
        node: Any = out
        path = o.path
        for depth, part in enumerate(path[:-1]):
            where = ".".join(map(str, path[: depth + 1]))
            if isinstance(node, dict):
                child = node.get(str(part))
                if child is None:
                    child = {}
                    node[str(part)] = child
                node = child
            elif isinstance(node, list) and isinstance(part, int):
                if part >= len(node):
                    raise InvalidInputError(f"{o.origin}: {where}: the list has {len(node)} item(s), numbered from 0")
                node = node[part]
            else:
                raise InvalidInputError(f"{o.origin}: {where} is {type(node).__name__}, not a mapping: no key under it")
        last = path[-1]
        if isinstance(node, list):
            if not isinstance(last, int) or last >= len(node):
                raise InvalidInputError(f"{o.origin}: the list at {'.'.join(map(str, path[:-1]))} has {len(node)} "
                                        "item(s), numbered from 0")  # fmt: skip
        elif isinstance(node, dict):
            last = str(last)
        else:
            raise InvalidInputError(f"{o.origin}: {'.'.join(map(str, path[:-1]))} is not a mapping: no key under it")
        node[last] = plain(o.value)
        placed.setdefault(id(node), {})[last] = o.origin
    return out, placed


def as_overrides(values: Mapping[str, Any] | Iterable[Override] | None, origin: str) -> tuple[Override, ...]:
    """Overrides from a mapping ``{key: value}`` (Python values, the file's units) or given as such."""
    if values is None:
        return ()
    if isinstance(values, Mapping):
        return tuple(Override(str(k), plain(v), f"{origin}({k}=...)") for k, v in values.items())
    return tuple(values)
