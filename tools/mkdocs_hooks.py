"""mkdocs hooks of the documentation site (``mkdocs.yml``: ``hooks``): checks that fail ``make docs``.

``on_post_build``, on the built ``site/``:

- no reStructuredText role survives (issue 31: the API reference showed 224 ``:class:``/``:func:`` roles as
  literal text). Every HTML page and the search index are read; a role (``:func:`solve``` in Markdown,
  ``:func:<code>solve</code>`` once rendered) anywhere is an error naming the page and the role;
- the site works opened from disk: every local link and asset of every page (``href``, ``src``) names a
  FILE of the site (a folder would show a directory listing from ``file://``), anchors aside;
- and without the internet: no page loads a script, a style sheet or an image from another site (issue 34: the
  search's worker shim came from unpkg.com; it is the site's own copy now, ``docs/assets/javascripts``).
"""

from __future__ import annotations

import html
import re
from pathlib import Path
from typing import Any
from urllib.parse import unquote, urlsplit

RST_ROLE = re.compile(r"(?<![\w:/]):(?:py:)?(?:class|func|meth|mod|data|attr|exc|obj|const|ref|doc|term|math|any):"
                      r"(?:`|<code>|&lt;code&gt;)")  # fmt: skip
"""A reST role as Markdown leaves it (a backtick) or as it renders (a code element; escaped in the search index)."""


LINK = re.compile(r"""\b(?:href|src)=["']([^"']*)["']""")
"""A link or an asset of a page."""


class SiteError(Exception):
    """The built site fails a check: a reStructuredText role left, or a link that does not open from disk."""


def surviving_roles(site: Path) -> list[str]:
    """``page: role...`` for each role left in the site's HTML pages and search index (at most 3 per page)."""
    found = []
    for path in sorted([*site.rglob("*.html"), *site.rglob("*.json")]):
        text = path.read_text(encoding="utf-8", errors="replace")
        hits = [text[m.start() : m.start() + 40].replace("\n", " ") for m in RST_ROLE.finditer(text)]
        if hits:
            found.append(f"{path.relative_to(site)}: {len(hits)} role(s), e.g. " + "; ".join(hits[:3]))
    return found


def broken_links(site: Path) -> list[str]:
    """``page: link`` for each local link or asset of an HTML page that is not a file of the site."""
    broken = []
    for page in sorted(site.rglob("*.html")):
        if page == site / "404.html":  # a server's page (its links are absolute): never opened from disk
            continue
        for raw in sorted(set(LINK.findall(page.read_text(encoding="utf-8", errors="replace")))):
            parts = urlsplit(html.unescape(raw))
            if parts.scheme or parts.netloc or not parts.path:  # another site, mailto:, data:, or an anchor
                continue
            target = (page.parent / unquote(parts.path)).resolve()
            if not target.is_file() or not target.is_relative_to(site.resolve()):
                broken.append(f"{page.relative_to(site)}: {raw}")
    return broken


REMOTE = re.compile(r"""<(?:script|img|iframe)\b[^>]*\bsrc=["'](?:https?:)?//|<link\b[^>]*\bhref=["'](?:https?:)?//""")
"""A script, image or frame (``src``), or a style sheet or icon (``link href``), loaded from another site."""


def remote_assets(site: Path) -> list[str]:
    """``page: tag`` for each asset a page of the site loads from another site (a link to read elsewhere is fine)."""
    found = []
    for page in sorted(site.rglob("*.html")):
        text = page.read_text(encoding="utf-8", errors="replace")
        for m in REMOTE.finditer(text):
            found.append(f"{page.relative_to(site)}: {text[m.start() : m.start() + 100].splitlines()[0]}")
    return found


def on_post_build(config: Any, **kwargs: Any) -> None:
    """Fail the build if a reST role survived into ``site/``, or a local link does not open from disk."""
    site = Path(config["site_dir"])
    left = surviving_roles(site)
    if left:
        raise SiteError("reStructuredText roles in the built site (write cross-references as links):\n"
                        + "\n".join(left))  # fmt: skip
    broken = broken_links(site)
    if broken:
        raise SiteError("links that do not open from disk (file://) in the built site:\n" + "\n".join(broken[:50]))
    remote = remote_assets(site)
    if remote:
        raise SiteError("assets loaded from another site (the site must work without the internet):\n"
                        + "\n".join(remote[:50]))  # fmt: skip
