"""Docs that run (issue 31 item 3): every Python block of docs/ runs, page by page; the site builds, shows no
reStructuredText role, renders the tour notebook with its outputs, and opens from disk.

The Python blocks are collected by Sybil (its Markdown parser: ```python blocks and the invisible blocks in
``<!-- invisible-code-block: python -->`` comments), run in order in one namespace per page, in a temporary
folder (the files they write land there). The site is built by ``mkdocs build --strict`` with the project's
``mkdocs.yml`` (its hooks fail the build on a role left or a link that does not open from disk), into a
temporary folder; the test then reads the pages itself.
"""

from __future__ import annotations

import os
import re
import subprocess
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


# ------------------------------------------------------------------------------------------------ the site
@pytest.fixture(scope="module")
def site(tmp_path_factory: pytest.TempPathFactory) -> Path:
    out = tmp_path_factory.mktemp("site")
    done = subprocess.run([sys.executable, "-m", "mkdocs", "build", "--strict", "--site-dir", str(out)], cwd=ROOT,
                          capture_output=True, text=True, timeout=600,
                          env={**os.environ, "NO_MKDOCS_2_WARNING": "1"})  # fmt: skip
    assert done.returncode == 0, done.stderr[-3000:]
    return out


def test_no_restructuredtext_role_in_the_site(site: Path) -> None:
    from mkdocs_hooks import surviving_roles

    assert surviving_roles(site) == []
    reference = (site / "reference" / "cycle.html").read_text(encoding="utf-8")
    # a role in a docstring became a link: jump_move's docstring names JumpMove
    assert re.search(r'<a class="autorefs autorefs-internal"[^>]*href="#scara_pin\.motion\.jump\.JumpMove"', reference)
    for page in ("calibration", "cycle"):  # the pages the issue missed
        assert (site / "reference" / f"{page}.html").is_file()


def test_the_role_check_catches_a_role(tmp_path: Path) -> None:
    from mkdocs_hooks import broken_links, surviving_roles

    (tmp_path / "a.html").write_text('<p>see :func:<code>solve</code></p><a href="cli/">cli</a>')
    (tmp_path / "cli").mkdir()
    assert len(surviving_roles(tmp_path)) == 1
    assert broken_links(tmp_path) == ["a.html: cli/"]  # a folder: a directory listing from file://


def test_the_site_opens_from_disk(site: Path) -> None:
    from mkdocs_hooks import broken_links

    assert broken_links(site) == []
    index = (site / "index.html").read_text(encoding="utf-8")
    nav = set(re.findall(r'href="([^"#]+\.html)"', index))
    assert {"cli.html", "python.html", "tour.html", "reference/index.html"} <= nav
    assert all((site / link).is_file() for link in nav)


def test_the_tour_is_a_page_with_its_outputs(site: Path) -> None:
    page = (site / "tour.html").read_text(encoding="utf-8")
    assert "A tour of scara-pin in a notebook" in page
    assert page.count("data:image/png;base64,") >= 2  # the trajectory and the workspace figures, run at build
    assert "iframe" in page and "joint1" in page  # the 3-D view and the robot's table
