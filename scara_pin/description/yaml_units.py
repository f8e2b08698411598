"""The package's one yaml loader: safe yaml with xacro's unit tags (``!degrees 132``, ``!millimeters 200``).

The tags and their factors are xacro's own (``xacro.ConstructUnits``: ``!radians``, ``!degrees``,
``!meters``, ``!millimeters``, ``!foot``, ``!inches``), so a value reads here exactly as xacro's
``load_yaml`` reads it in the entry xacro, in SI units. Only the value's evaluation differs, on purpose:
xacro evaluates the tagged text as an expression (``!degrees 90/2``); here it must be a plain number,
because these files may be the user's and no user string reaches xacro evaluation (a tagged text that is
not a number is kept as the text ``"!tag text"``, for the caller to refuse naming the parameter). xacro's
``load_yaml`` itself is not used: it reads a file unbounded, by path, and registers its tags on PyYAML's
global ``SafeLoader``.
"""

from __future__ import annotations

import functools
from typing import Any

__all__ = ["load_yaml", "unit_tags", "yaml_problem"]


@functools.cache
def unit_tags() -> dict[str, float]:
    """Xacro's yaml unit tags and their factors to SI (radians, meters)."""
    from xacro import ConstructUnits

    return {u.value.tag: float(u.value.conversion_constant) for u in ConstructUnits}


@functools.cache
def _loader() -> type:
    import yaml

    base = getattr(yaml, "CSafeLoader", yaml.SafeLoader)  # libyaml when available: ~10x faster

    class Loader(base):  # type: ignore[valid-type, misc]
        """A safe loader (a subclass: PyYAML's own loaders stay untouched) with the unit tags."""

    for tag, scale in unit_tags().items():

        def construct(loader: Any, node: Any, scale: float = scale) -> float | str:
            text = loader.construct_scalar(node)
            try:
                return float(text) * scale
            except ValueError:  # left as text: the caller refuses it, naming the parameter and file
                return f"{node.tag} {text}"

        Loader.add_constructor(tag, construct)
    return Loader


def load_yaml(text: str) -> Any:
    """Parse yaml text (safe: plain data only), unit tags read in SI units.

    Raises:
        yaml.YAMLError: the text is not valid yaml (the caller says which file and line).
    """
    import yaml

    return yaml.load(text, Loader=_loader())  # noqa: S506 (a SafeLoader subclass)


def yaml_problem(exc: Exception) -> tuple[int | None, str]:
    """(line number from 1, or None; what is wrong) of a ``yaml.YAMLError``, for a one-line message."""
    mark = getattr(exc, "problem_mark", None)
    return (None if mark is None else mark.line + 1), getattr(exc, "problem", None) or type(exc).__name__
