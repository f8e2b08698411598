"""mkdocs hooks of the documentation site (``mkdocs.yml``: ``hooks``): checks that fail ``make docs``.

``on_post_build``: no reStructuredText role survives in the built site (issue 31: the API reference showed
224 ``:class:``/``:func:`` roles as literal text). Every HTML page and the search index are read; a role
(``:func:`solve``` in Markdown, ``:func:<code>solve</code>`` once rendered) anywhere is an error naming the
page and the role.
"""

from __future__ import annotations

import re
from pathlib import Path
from typing import Any

RST_ROLE = re.compile(r"(?<![\w:/]):(?:py:)?(?:class|func|meth|mod|data|attr|exc|obj|const|ref|doc|term|math|any):"
                      r"(?:`|<code>|&lt;code&gt;)")  # fmt: skip
"""A reST role as Markdown leaves it (a backtick) or as it renders (a code element; escaped in the search index)."""


class RoleLeftError(Exception):
    """A reStructuredText role survived into the built site."""


def surviving_roles(site: Path) -> list[str]:
    """``page: role...`` for each role left in the site's HTML pages and search index (at most 3 per page)."""
    found = []
    for path in sorted([*site.rglob("*.html"), *site.rglob("*.json")]):
        text = path.read_text(encoding="utf-8", errors="replace")
        hits = [text[m.start() : m.start() + 40].replace("\n", " ") for m in RST_ROLE.finditer(text)]
        if hits:
            found.append(f"{path.relative_to(site)}: {len(hits)} role(s), e.g. " + "; ".join(hits[:3]))
    return found


def on_post_build(config: Any, **kwargs: Any) -> None:
    """Fail the build if a reST role survived into ``site/``."""
    left = surviving_roles(Path(config["site_dir"]))
    if left:
        raise RoleLeftError("reStructuredText roles in the built site (write cross-references as links):\n"
                            + "\n".join(left))  # fmt: skip
