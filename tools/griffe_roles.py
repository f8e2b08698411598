"""Sphinx roles in docstrings -> mkdocs-autorefs cross-references, when the API reference is built.

The package's docstrings name other objects with Sphinx roles (``:func:`solve```, ``:class:`~scara_pin.model.Robot```,
``:mod:`scara_pin.chain```, ``:meth:`Planar2R.solve_array```, ``:data:``, ``:attr:``, ``:exc:``, ``:obj:``): short
and readable in ``help()`` and in an editor. mkdocstrings does not understand them; this griffe extension
(``mkdocs.yml``: ``extensions: [tools/griffe_roles.py]``) rewrites each one, in every docstring of the package,
to a cross-reference autorefs turns into a link:

- the name is resolved in the docstring's own scope, as Python would (``solve`` in ``scara_pin.kinematics.scara``
  is ``scara_pin.kinematics.scara.solve``; ``Robot`` imported from ``..model`` is ``scara_pin.model.Robot``);
- the text shown is the name as written (``~`` keeps its last part only, as in Sphinx);
- a public object the reference does not render (an internal module) shows as code, its full path on
  hover (autorefs' optional reference);
- a name that does not resolve, or that resolves to a private object (a part starting with ``_``) is a
  warning, and ``mkdocs build --strict`` fails on it: the reference shows no dead role and no private name.

Run as a script, it lists every role of the package and what it becomes (``python tools/griffe_roles.py``).
"""

from __future__ import annotations

import re
import sys
from typing import Any

import griffe

ROLE = re.compile(r":(?:py:)?(?P<kind>class|func|meth|mod|data|attr|exc|obj|const):`(?P<target>[^`]+)`")
"""A Sphinx Python role: ``:kind:`target```, ``target`` possibly ``~dotted.name`` or ``title <dotted.name>``."""

logger = griffe.get_logger("griffe_roles")


def _private(path: str) -> bool:
    return any(part.startswith("_") and not part.startswith("__") for part in path.split("."))


def resolve(obj: griffe.Object | griffe.Alias, name: str) -> str | None:
    """The full path of ``name`` as seen from ``obj``'s docstring (None if it does not resolve)."""
    collection = obj.modules_collection
    first, _, rest = name.partition(".")
    candidates = [name]  # an absolute path first
    scope: Any = obj
    while scope is not None:  # then each enclosing scope, innermost first
        if first in scope.members:
            candidates.append(f"{scope.path}.{name}")
        scope = scope.parent
    try:
        candidates.append(obj.resolve(first) + (f".{rest}" if rest else ""))
    except Exception:  # noqa: BLE001 - griffe's NameResolutionError and alias errors: not in scope
        pass
    for path in candidates:
        try:
            target = collection.get_member(path) if "." in path else collection[path]
        except Exception:  # noqa: BLE001 - KeyError / alias resolution errors: try the next
            continue
        try:
            return str(target.final_target.path if isinstance(target, griffe.Alias) else target.path)
        except Exception:  # noqa: BLE001 - an alias to something outside the package (numpy, pinocchio)
            return str(target.target_path)
    return None


def convert(obj: griffe.Object | griffe.Alias, text: str, where: str) -> tuple[str, list[str]]:
    """``text`` with its roles as autorefs cross-references, and the problems met (one line each)."""
    problems: list[str] = []

    def one(match: re.Match[str]) -> str:
        target = " ".join(match["target"].split())  # a role may break across lines
        explicit = re.fullmatch(r"(?P<title>.+?)\s*<(?P<name>[^>]+)>", target)
        if explicit:
            title, name = explicit["title"], explicit["name"]
        else:
            name = target.replace(" ", "").lstrip("~")
            title = name.rsplit(".", 1)[-1] if target.startswith("~") else name
        path = resolve(obj, name.lstrip("."))
        if path is None:
            problems.append(f"{where}: {match[0]} names nothing the reference knows")
            return f"`{title}`"
        if _private(path):
            problems.append(f"{where}: {match[0]} names the private {path}: the reference shows no private name")
            return f"`{title}`"
        # optional: a public object the reference does not render shows as code (its full path on hover)
        return f'<autoref identifier="{path}" optional><code>{title}</code></autoref>'

    return ROLE.sub(one, text), problems


def _walk(obj: griffe.Object) -> Any:
    yield obj
    for member in obj.members.values():
        if not member.is_alias and member.parent is obj:
            yield from _walk(member)  # type: ignore[arg-type]


class SphinxRoles(griffe.Extension):
    """Rewrite Sphinx roles to autorefs cross-references in every docstring of a package, once it is loaded."""

    def on_package(self, *, pkg: griffe.Module, **kwargs: Any) -> None:  # noqa: D102
        for obj in _walk(pkg):
            if obj.docstring is None:
                continue
            text, problems = convert(obj, obj.docstring.value, obj.path)
            obj.docstring.value = text
            if not _private(obj.path):  # what the reference renders: its roles must become links
                for line in problems:
                    logger.warning(line)


def main(argv: list[str]) -> int:
    """Print every role of the package and what it becomes; exit 1 if one stays unresolved or private."""
    pkg = griffe.load(argv[0] if argv else "scara_pin", search_paths=["."], resolve_aliases=True)
    bad = 0
    for obj in _walk(pkg):
        if obj.docstring is None:
            continue
        for match in ROLE.finditer(obj.docstring.value):
            new, problems = convert(obj, match[0], obj.path)
            print(f"{obj.path}: {match[0]} -> {new}")
            bad += bool(problems) and not _private(obj.path)
            for line in problems:
                print("  " + line)
    print(f"{bad} role(s) the reference cannot show as links", file=sys.stderr)
    return 1 if bad else 0


if __name__ == "__main__":
    raise SystemExit(main(sys.argv[1:]))
