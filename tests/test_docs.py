"""Docs that run (issue 31 item 3): every Python block of docs/ runs, page by page; the site builds, shows no
reStructuredText role, renders the tour notebook with its outputs, and opens from disk (tests/test_site.py,
run by ``make docs`` on the site it builds).

The Python blocks are collected by Sybil (its Markdown parser: ```python blocks and the invisible blocks in
``<!-- invisible-code-block: python -->`` comments), run in order in one namespace per page, in a temporary
folder (the files they write land there). The site's checks (tools/mkdocs_hooks.py) are
shown here to catch what they must.
"""

from __future__ import annotations

import re
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
DOCS = ROOT / "docs"
PAGES = sorted(p for p in DOCS.glob("*.md") if "```python" in p.read_text(encoding="utf-8"))
sys.path.insert(0, str(ROOT / "tools"))  # the site's checks (tools/mkdocs_hooks.py), also run by `make docs`


def test_the_docs_have_python_blocks() -> None:
    assert {p.name for p in PAGES} >= {"python.md", "cycle.md", "jerk.md", "plots.md", "calibration.md"}


@pytest.mark.parametrize("page", PAGES, ids=lambda p: p.name)
def test_every_python_block_of_a_page_runs(page: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    import matplotlib

    matplotlib.use("Agg")
    from sybil import Sybil
    from sybil.parsers.markdown import PythonCodeBlockParser

    monkeypatch.chdir(tmp_path)
    (tmp_path / "docs").symlink_to(ROOT / "docs")  # the pages name their example files from the repository's root
    monkeypatch.setattr("scara_pin.viz.meshcat.Viewer.DEFAULT_TIMEOUT", 30.0)
    document = Sybil(parsers=[PythonCodeBlockParser()]).parse(page)
    examples = list(document.examples())
    visible = len(re.findall(r"^```python$", page.read_text(encoding="utf-8"), flags=re.MULTILINE))
    assert len(examples) >= visible > 0  # no block left out by the parser
    for example in examples:
        example.evaluate()


# ------------------------------------------------------------------------------------------------ the site checks
def test_the_role_check_catches_a_role(tmp_path: Path) -> None:
    from mkdocs_hooks import broken_links, surviving_roles

    (tmp_path / "a.html").write_text('<p>see :func:<code>solve</code></p><a href="cli/">cli</a>')
    (tmp_path / "cli").mkdir()
    assert len(surviving_roles(tmp_path)) == 1
    assert broken_links(tmp_path) == ["a.html: cli/"]  # a folder: a directory listing from file://


def test_the_site_needs_no_internet(tmp_path: Path) -> None:
    """The site's search opened from disk (issue 34): the offline plugin's worker shim is the site's own copy (it
    loads it from unpkg.com unless mkdocs.yml names one), and the build refuses any asset from another site."""
    import yaml
    from mkdocs_hooks import remote_assets

    (tmp_path / "a.html").write_text('<script src="https://unpkg.com/iframe-worker/shim"></script>'
                                     '<a href="https://example.org/">read more</a><script src="assets/x.js"></script>')
    found = remote_assets(tmp_path)  # one: the script; a link to read elsewhere is fine, a local script too
    assert len(found) == 1 and found[0].startswith('a.html: <script src="https://unpkg.com/iframe-worker/shim">')
    config = yaml.load((ROOT / "mkdocs.yml").read_text(), Loader=yaml.BaseLoader)  # its python tags left as text
    shims = [p for p in config["extra"]["polyfills"] if "iframe-worker" in p]
    assert shims and all((DOCS / p).is_file() and not p.startswith(("http:", "https:", "//")) for p in shims)
