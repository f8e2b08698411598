"""The numbers users type: the one grammar (:func:`number`, :func:`integer`), its argparse types, ``--set`` and jerk."""

from __future__ import annotations

import argparse
import re
from collections.abc import Callable, Sequence
from typing import TypeVar

from .._checks import NUMBER_TEXT
from ..errors import InvalidInputError, ParameterError
from ..limits import MAX_NUMBER
from ..units import format_number

_INTEGER_TEXT = re.compile(r"[+-]?\d+", re.ASCII)
_T = TypeVar("_T")
MIN_NUMBER = 1e-100
"""Smallest magnitude of a non-zero typed number (below it, 1 / x and x * x leave the float range)."""


def number(name: str, text: str) -> float:
    """The one parser of the numbers users type (arguments, --set values, batch CSV cells).

    Accepted: what a robotics user types, ``0.25``, ``-1.5e-3``, ``+2``, ``.5``, ``3.``, surrounding
    blanks. Refused: ``1_000``, non-ASCII digits, hex, ``nan``, ``inf``, and magnitudes outside
    ``0`` or ``[MIN_NUMBER, MAX_NUMBER]`` (1e-100 .. 1e12).
    """
    stripped = text.strip(" \t") if isinstance(text, str) else ""
    if not NUMBER_TEXT.fullmatch(stripped):
        shown = text if len(text) <= 40 else text[:40] + "..."
        if stripped.lower().lstrip("+-") in ("nan", "inf", "infinity"):
            raise ParameterError(name, shown, "must be finite")
        raise ParameterError(name, shown, "must be a plain number such as 0.25, -3, 1.5e-3 (ASCII digits, "
                             "no _ separators)")  # fmt: skip
    value = float(stripped)
    if not (value == 0.0 or MIN_NUMBER <= abs(value) <= MAX_NUMBER):
        raise ParameterError(name, stripped, f"must be 0 or of magnitude within [{MIN_NUMBER:g}, {MAX_NUMBER:g}]")
    return value


def integer(name: str, text: str, low: int, high: int) -> int:
    """A typed whole number in ``[low, high]`` (ASCII digits, optional sign)."""
    stripped = text.strip(" \t")
    if not _INTEGER_TEXT.fullmatch(stripped) or len(stripped) > 30:
        raise ParameterError(name, text[:40], "must be a whole number (ASCII digits)")
    value = int(stripped)
    if not low <= value <= high:
        raise ParameterError(name, value, f"must be within [{low}, {high}]")
    return value


def number_type(name: str) -> Callable[[str], float]:
    """An argparse ``type=`` that parses with :func:`number` (errors become the one-line usage error)."""
    return _argparse_type(lambda text: number(name, text))


def integer_type(name: str, low: int, high: int) -> Callable[[str], int]:
    """An argparse ``type=`` for a whole number in ``[low, high]``."""
    return _argparse_type(lambda text: integer(name, text, low, high))


def _argparse_type(parse: Callable[[str], _T]) -> Callable[[str], _T]:
    """``parse`` with its ParameterError as argparse's, which names the option: "argument --rate: got 'x'; it ..."."""

    def parsed(text: str) -> _T:
        try:
            return parse(text)
        except ParameterError as exc:
            raise argparse.ArgumentTypeError(f"got {exc.value!r}; it {exc.rule}") from None

    return parsed


def parse_sets(items: Sequence[str] | None, option: str = "--set", form: str = "key=value (e.g. l1=0.25)"
               ) -> dict[str, float]:  # fmt: skip
    """``--set KEY=VALUE`` items (or ``option``'s); each value through :func:`number` (never to xacro as text).

    A key given twice is refused (which one was meant? the last silently winning hid the other).
    """
    overrides: dict[str, float] = {}
    for item in items or ():
        key, sep, value = item.partition("=")
        key = key.strip()
        if not sep or not key:
            raise InvalidInputError(f"{option} {item[:80]!r} must have the form {form}")
        parsed = number(f"{option} {key[:80]}", value)
        if key in overrides:
            raise InvalidInputError(f"{option} {key[:80]} is given twice ({format_number(overrides[key], 9)} and "
                                    f"{format_number(parsed, 9)}); give each once")  # fmt: skip
        overrides[key] = parsed
    return overrides


def parse_locks(items: Sequence[str] | None) -> dict[str, float]:
    """``--lock JOINT=VALUE`` items (SI, as --set)."""
    return parse_sets(items, "--lock", "JOINT=VALUE (e.g. lower_j1=0.5)")
