"""The package's one yaml loader: safe, bounded, with line numbers, xacro's unit tags and the one number grammar.

Every yaml file scara-pin reads goes through :func:`load_yaml` (a robot's config folder, a D-H table, a
points file; a new format calls it too): ``load_yaml(text, origin)`` returns plain data (mappings, lists,
strings, numbers, booleans, None) and raises one :class:`~scara_pin.errors.YamlError` (exit code 2) naming
``origin`` and the line for anything it will not read.

**Bounded.** A yaml alias (``*a``) stands for a whole subtree, so 520 bytes of nested aliases stand for
9^9 values: nothing is copied while loading, but whatever walks the data afterwards (a message that turns a
value into text, a check of every item) walks them all. The composer counts the nodes as it builds them,
an alias at the full size of what it stands for (merge keys, ``<<: *a``, included), and refuses the
document past :data:`~scara_pin.limits.MAX_YAML_NODES`, or nested deeper than
:data:`~scara_pin.limits.MAX_YAML_DEPTH`; an alias inside its own anchor (a recursive structure) is refused.
The data returned is therefore a tree of at most that many values, however it is walked. (libyaml, when
present, still parses: the counting composer reads its events.)

**Numbers.** A plain scalar is a number only in the grammar of the command line
(:data:`scara_pin.units.NUMBER_TEXT`: ``0.25``, ``-3``, ``1.5e-3``, ``1e-05``), never YAML 1.1's hex
``0x1``, binary ``0b0``, ``0_1`` or base 60 ``0:0.5``: those stay text, and the reader refuses them naming
the item. An integer of more than 18 digits is read as a float (``inf`` past the float range: the reader
refuses it as not finite); dates stay text.

**Units.** The tags and their factors are xacro's own (``xacro.ConstructUnits``: ``!radians``, ``!degrees``,
``!meters``, ``!millimeters``, ``!foot``, ``!inches``), so a value reads here exactly as xacro's
``load_yaml`` reads it in the entry xacro, in SI units. Only the value's evaluation differs, on purpose:
xacro evaluates the tagged text as an expression (``!degrees 90/2``); here it must be a number of the
grammar above, because these files may be the user's and no user string reaches xacro evaluation (a tagged
text that is not a number is kept as the text ``"!tag text"``, for the caller to refuse naming the
parameter). xacro's ``load_yaml`` itself is not used: it reads a file unbounded, by path, and registers its
tags on PyYAML's global ``SafeLoader``.

**Lines.** Every mapping and list of the data knows the line where it starts and where each of its items
does: :func:`yaml_line` (``yaml_line(point, "q")``: the line of a point's ``q``), for messages that name
the line the user wrote.
"""

from __future__ import annotations

import functools
import math
import re
from typing import Any

from ..errors import YamlError
from ..limits import MAX_YAML_DEPTH, MAX_YAML_NODES
from ..units import NUMBER_TEXT, number_text

__all__ = ["Tagged", "load_yaml", "unit_tags", "yaml_line"]

_INT_DIGITS = 18
"""Longest integer (digits) read as an int; a longer one is read as a float (``int()`` of thousands of digits
is slow, and past 4,300 refused by Python)."""
_INTEGER = re.compile(r"[+-]?[0-9]+", re.ASCII)


class Tagged(float):
    """A number written with a unit tag (``!millimeters 150``): a float, already in SI units.

    A reader whose file names its own units (a job's ``units: mm,deg``) scales the plain numbers and leaves
    these as they are.
    """

    __slots__ = ()


class _YamlMap(dict):  # type: ignore[type-arg]
    """A yaml mapping: ``line`` where it starts, ``lines[key]`` where each value starts (from 1)."""

    __slots__ = ("line", "lines")
    line: int
    lines: dict[Any, int]


class _YamlList(list):  # type: ignore[type-arg]
    """A yaml sequence: ``line`` where it starts, ``lines[i]`` where each item starts (from 1)."""

    __slots__ = ("line", "lines")
    line: int
    lines: list[int]


def yaml_line(data: object, key: object = None) -> int | None:
    """The line (from 1) where ``data`` starts, or where its item ``key`` does; None when unknown.

    Args:
        data: a mapping or a list returned by :func:`load_yaml` (anything else: None).
        key: a key of the mapping, or an index of the list; None: the line of ``data`` itself.
    """
    if key is None:
        return getattr(data, "line", None)
    lines = getattr(data, "lines", None)
    try:
        return None if lines is None else int(lines[key])  # type: ignore[index]
    except (KeyError, IndexError, TypeError):
        return None


@functools.cache
def unit_tags() -> dict[str, float]:
    """Xacro's yaml unit tags and their factors to SI (radians, meters)."""
    from xacro import ConstructUnits

    return {u.value.tag: float(u.value.conversion_constant) for u in ConstructUnits}


def _number(text: str, integer: bool) -> int | float | None:
    """``text`` as a number of the grammar (module docstring), or None; ``integer``: an int (long ones: a float)."""
    stripped = text.strip(" \t\n\r")
    if integer:
        if not _INTEGER.fullmatch(stripped):
            return None
        return int(stripped) if len(stripped.lstrip("+-")) <= _INT_DIGITS else float(stripped)
    return float(stripped) if NUMBER_TEXT.fullmatch(stripped) else None


@functools.cache
def _loader() -> type:
    import yaml
    from yaml.composer import Composer, ComposerError
    from yaml.constructor import ConstructorError, SafeConstructor
    from yaml.events import AliasEvent
    from yaml.resolver import Resolver

    if getattr(yaml, "__with_libyaml__", False):  # libyaml parses (about 10x faster); the composer reads its events
        from yaml._yaml import CParser

        parsers: tuple[type, ...] = (CParser,)
    else:  # pragma: no cover - PyYAML without libyaml
        from yaml.parser import Parser
        from yaml.reader import Reader
        from yaml.scanner import Scanner

        parsers = (Reader, Scanner, Parser)

    class Refused(ComposerError):  # type: ignore[misc]
        """A document over a cap, or recursive: valid yaml, not read."""

    class BoundedComposer(Composer):  # type: ignore[misc]
        """PyYAML's composer, counting the nodes as it builds them (module docstring)."""

        def compose_node(self, parent: Any, index: Any) -> Any:
            event = self.peek_event()
            if isinstance(event, AliasEvent):
                node = super().compose_node(parent, index)  # an undefined alias: PyYAML's error
                size = self._sizes.get(id(node))
                if size is None:
                    raise Refused(None, None, f"the alias *{event.anchor[:40]} is inside its own anchor "
                                        "(a recursive structure)", event.start_mark)  # fmt: skip
                self._count(size, event)
                return node
            start = self._nodes
            self._count(1, event)
            self._depth += 1
            if self._depth > MAX_YAML_DEPTH:
                raise Refused(None, None, f"nested more than {MAX_YAML_DEPTH} levels deep, the cap",
                                    event.start_mark)  # fmt: skip
            node = super().compose_node(parent, index)
            self._depth -= 1
            if event.anchor is not None:
                self._sizes[id(node)] = self._nodes - start
            return node

        def _count(self, n: int, event: Any) -> None:
            self._nodes += n
            if self._nodes > MAX_YAML_NODES:
                raise Refused(None, None, f"the document holds more than {MAX_YAML_NODES:,} values (an alias "
                                    "counts as all it stands for), the cap", event.start_mark)  # fmt: skip

    class Loader(BoundedComposer, *parsers, SafeConstructor, Resolver):  # type: ignore[misc]
        """Safe, bounded, with lines, the number grammar and the unit tags (a new class: PyYAML's are untouched)."""

        def __init__(self, stream: str) -> None:
            for k, parser in enumerate(parsers):  # CParser(stream), or Reader(stream), Scanner(), Parser()
                parser.__init__(self, *((stream,) if k == 0 else ()))  # type: ignore[misc]
            Composer.__init__(self)
            SafeConstructor.__init__(self)
            Resolver.__init__(self)
            self._nodes = 0
            self._depth = 0
            self._sizes: dict[int, int] = {}

    int_tag, float_tag = "tag:yaml.org,2002:int", "tag:yaml.org,2002:float"
    dropped = (int_tag, float_tag, "tag:yaml.org,2002:timestamp")
    Loader.yaml_implicit_resolvers = {
        first: [(tag, regexp) for tag, regexp in resolvers if tag not in dropped]
        for first, resolvers in Resolver.yaml_implicit_resolvers.items()
    }
    Loader.add_implicit_resolver(int_tag, re.compile(r"^[+-]?[0-9]+$", re.ASCII), list("+-0123456789"))
    Loader.add_implicit_resolver(float_tag, re.compile(f"^{NUMBER_TEXT.pattern}$", re.ASCII), list("+-.0123456789"))
    # YAML's own words for the non-finite floats: read as such, for the reader to refuse as not finite
    Loader.add_implicit_resolver(float_tag, re.compile(r"^(?:[-+]?\.(?:inf|Inf|INF)|\.(?:nan|NaN|NAN))$"), list("-+."))
    Loader.refused = Refused

    def construct_number(loader: Any, node: Any) -> int | float:
        text = loader.construct_scalar(node)
        if node.tag == float_tag and text.strip().lower().lstrip("+-") in (".inf", ".nan"):
            return SafeConstructor.construct_yaml_float(loader, node)  # type: ignore[no-any-return]
        value = _number(text, node.tag == int_tag)
        if value is None:
            raise ConstructorError(None, None, f"{node.tag.rsplit(':', 1)[-1]} {node.value[:40]!r} is not a plain "
                                   "number such as 0.25, -3, 1.5e-3", node.start_mark)  # fmt: skip
        return value

    def construct_map(loader: Any, node: Any) -> Any:
        data = _YamlMap()
        data.line = node.start_mark.line + 1
        yield data
        data.update(loader.construct_mapping(node))  # merge keys flattened into node.value
        data.lines = {loader.construct_object(k): v.start_mark.line + 1 for k, v in node.value}

    def construct_list(loader: Any, node: Any) -> Any:
        data = _YamlList()
        data.line = node.start_mark.line + 1
        yield data
        data.extend(loader.construct_sequence(node))
        data.lines = [v.start_mark.line + 1 for v in node.value]

    Loader.add_constructor(int_tag, construct_number)
    Loader.add_constructor(float_tag, construct_number)
    Loader.add_constructor("tag:yaml.org,2002:map", construct_map)
    Loader.add_constructor("tag:yaml.org,2002:seq", construct_list)
    for tag, scale in unit_tags().items():

        def construct_unit(loader: Any, node: Any, scale: float = scale) -> float | str:
            text = loader.construct_scalar(node)
            value = number_text(text)
            # left as text: the caller refuses it, naming the parameter and file
            return f"{node.tag} {text}" if math.isnan(value) else Tagged(value * scale)

        Loader.add_constructor(tag, construct_unit)
    return Loader


def load_yaml(text: str, origin: str = "yaml text") -> Any:
    """Parse yaml ``text`` (safe: plain data only; bounded; module docstring), unit tags read in SI units.

    Args:
        text: the document.
        origin: how to name it in errors, e.g. ``"points file cell.yaml"``.

    Returns:
        The data; its mappings and lists know their lines (:func:`yaml_line`).

    Raises:
        YamlError: not valid yaml, a tag that is not plain data (``!!python/...``), more than
            :data:`~scara_pin.limits.MAX_YAML_NODES` values or :data:`~scara_pin.limits.MAX_YAML_DEPTH`
            levels, a recursive alias, an explicitly tagged number (``!!int 0x1``) outside the grammar.
    """
    import yaml

    loader = _loader()(text)
    try:
        return loader.get_single_data()
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        line = None if mark is None else mark.line + 1
        problem = " ".join(str(getattr(exc, "problem", None) or type(exc).__name__).split())
        raise YamlError(origin, line, problem, isinstance(exc, loader.refused)) from None
    except (ValueError, TypeError, OverflowError) as exc:  # a constructor's (e.g. !!binary, !!timestamp text)
        raise YamlError(origin, None, f"a value cannot be read ({type(exc).__name__}: {str(exc)[:80]})") from None
    finally:
        loader.dispose()
