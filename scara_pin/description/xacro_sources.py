"""Where each element of an expanded xacro document was written: file and line, macros and includes included.

xacro builds its output with ``xml.dom.minidom``, which keeps no line numbers, and copies a macro's body
(or an ``<xacro:insert_block>``) into the place of each call. :func:`expand_with_sources` expands a file as
the loader does (:meth:`scara_pin.description.packages.PackagePath.expand_xacro`) while xacro's parser is
replaced, for the duration, by one that tags every URDF element (not the ``xacro:`` ones) of each file it
reads with an attribute ``scara_pin_src="N"``: N indexes a table of (file, line) of the element's start tag.
The tag survives the expansion (a macro body's copies keep their definition's tag), then is read back
from the expanded text, line by line, and removed: the text returned is the loader's, byte for byte.

An element that xacro creates (``<xacro:element>``) has no tag: its line is only a line of the expansion,
and :class:`SourceMap` says so (``None``).

The tag's value is a number: nothing of the user's reaches xacro's evaluation through it.
"""

from __future__ import annotations

import os
import re
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

from ..errors import UrdfError

if TYPE_CHECKING:
    from .packages import PackagePath

__all__ = ["SOURCE_ATTRIBUTE", "SourceMap", "XacroSourceError", "expand_with_sources"]

SOURCE_ATTRIBUTE = "scara_pin_src"
"""The attribute that carries an element's index in the table of sources during the expansion."""
_TAG = re.compile(rf' {SOURCE_ATTRIBUTE}="(\d+)"')
_XACRO_NAMESPACES = ("http://www.ros.org/wiki/xacro", "http://ros.org/wiki/xacro", "http://wiki.ros.org/xacro")


@dataclass(frozen=True)
class SourceMap:
    """Lines of an expanded xacro document -> where their element was written.

    Attributes:
        top: the xacro file expanded.
        lines: per line of the expanded text (1-based, as a dict), (file, line) of the element starting on it.
    """

    top: Path
    lines: dict[int, tuple[Path, int]]

    def where(self, expanded_line: int | None) -> tuple[Path, int] | None:
        """(file, line) where the element on ``expanded_line`` was written; None: a line of the expansion only."""
        return None if expanded_line is None else self.lines.get(expanded_line)


def _tagged(text: str, filename: Path, table: list[tuple[Path, int]]) -> Any:
    """Minidom's document of ``text``, each URDF element tagged with its (file, line) in ``table``."""
    import xml.dom.minidom
    from xml.parsers import expat

    doc = xml.dom.minidom.parseString(text)
    starts: list[int] = []
    parser = expat.ParserCreate()
    parser.StartElementHandler = lambda _tag, _attrs: starts.append(parser.CurrentLineNumber)
    parser.Parse(text, True)
    elements = doc.getElementsByTagName("*")
    if len(elements) != len(starts):  # the two parsers disagree: no tags rather than wrong ones
        return doc
    for el, line in zip(elements, starts):
        if el.tagName.startswith("xacro:") or el.namespaceURI in _XACRO_NAMESPACES:
            continue  # xacro's own elements take no unknown attribute (a macro call would see a parameter)
        el.setAttribute(SOURCE_ATTRIBUTE, str(len(table)))
        table.append((filename, line))
    return doc


class XacroSourceError(UrdfError):
    """xacro's error, with where the element it was evaluating was written (``file``, ``line``; None: unknown)."""

    def __init__(self, reason: str, file: Path | None, line: int | None) -> None:
        where = "" if file is None else f" (in the element written at {file}:{line})" if line else f" (in {file})"
        super().__init__(reason + where)
        self.reason = reason
        self.file = file
        self.line = line

    def __reduce__(self) -> tuple[type, tuple[str, Path | None, int | None]]:
        return (type(self), (self.reason, self.file, self.line))  # pickled from the expansion's child process


@contextmanager
def _tagging_parser(top: Path, table: list[tuple[Path, int]], failed: list[int]) -> Iterator[None]:
    """Xacro's ``parse`` replaced by one that tags elements (the top document's text, and each include).

    And its ``eval_all`` by one that records, when an evaluation fails, the innermost tagged element being
    evaluated (its index in ``table``, or -1) in ``failed``.
    """
    import xacro

    original, original_eval = xacro.parse, xacro.eval_all
    evaluating: list[Any] = []

    def eval_all(node: Any, macros: Any, symbols: Any) -> Any:
        evaluating.append(node)
        try:
            return original_eval(node, macros, symbols)
        except BaseException:
            if not failed:  # the innermost element being evaluated that carries a tag
                tags = [el.getAttribute(SOURCE_ATTRIBUTE) for el in reversed(evaluating) if hasattr(el, "getAttribute")]
                failed.append(next((int(t) for t in tags if t.isdigit()), -1))
            raise
        finally:
            evaluating.pop()

    def parse(inp: Any, filename: str | None = None) -> Any:
        if inp is None and filename is not None:  # an include: read as xacro does (relative to its root_dir)
            path = Path(os.path.join(xacro.root_dir, filename))
            reader = getattr(xacro, "open", open)  # the loader's bounded reader when it installs one
            try:
                with reader(str(path)) as handle:
                    text = handle.read()
            except OSError:
                return original(inp, filename)  # xacro's own error (optional includes handle it)
            except UnicodeDecodeError:
                raise UrdfError(f"{path}: not UTF-8 text") from None
            if isinstance(text, bytes):
                text = text.decode("utf-8")
            return _tagged(text, path.resolve(), table)
        if isinstance(inp, str):
            return _tagged(inp, top, table)
        return original(inp, filename)

    xacro.parse, xacro.eval_all = parse, eval_all
    try:
        yield
    finally:
        xacro.parse, xacro.eval_all = original, original_eval


def expand_with_sources(path: str | Path, packages: PackagePath) -> tuple[str, SourceMap]:
    """The URDF text of a xacro file (the loader's), and where each of its elements was written.

    Under the loader's bounds (:func:`~scara_pin.description.expansion.bounded`: time, memory, size).

    Raises:
        XacroSourceError: as the loader's expansion (a missing package, xacro's own error), with where the
            element xacro was evaluating was written (file and line, when known).
        UrdfError: a bound of the expansion reached.
    """
    from .expansion import bounded

    return bounded(str(path), lambda: _expand_with_sources(Path(path), packages))


def _expand_with_sources(path: Path, packages: PackagePath) -> tuple[str, SourceMap]:
    """:func:`expand_with_sources`'s work (in the child process of the bounded expansion)."""
    import xacro

    table: list[tuple[Path, int]] = []
    failed: list[int] = []
    try:
        with _tagging_parser(path.resolve(), table, failed):
            text = packages.expand_xacro(path)
    except UrdfError as exc:
        if failed and 0 <= failed[0] < len(table):
            file, line = table[failed[0]]
            raise XacroSourceError(str(exc), file, line) from None
        stack = [f for f in (getattr(xacro, "filestack", None) or []) if f]
        if stack and Path(stack[-1]).resolve() != path.resolve():  # an include that does not parse, say
            raise XacroSourceError(str(exc), Path(stack[-1]).resolve(), None) from None
        raise XacroSourceError(str(exc), None, None) from None
    lines: dict[int, tuple[Path, int]] = {}
    out: list[str] = []
    for number, row in enumerate(text.split("\n"), start=1):
        found = _TAG.search(row)
        if found is not None:
            index = int(found.group(1))
            if index < len(table):
                lines[number] = table[index]
            row = _TAG.sub("", row)
        out.append(row)
    return "\n".join(out), SourceMap(path.resolve(), lines)
