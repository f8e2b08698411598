"""The built documentation site (issue 31 item 3), checked by ``make docs`` right after ``mkdocs build --strict``
(``pytest -m site tests/test_site.py``; ``make test`` leaves these out: building the site takes half a minute,
and CI runs ``make docs``).

The site is read from ``SCARA_PIN_SITE`` (``make docs``: ``site/``): no reStructuredText role is left, a
docstring's role became a link, the reference has its pages, the tour notebook is a page with its outputs, and
every local link opens from disk (file://).
"""

from __future__ import annotations

import os
import re
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tools"))  # the site's checks (tools/mkdocs_hooks.py), also run by mkdocs' hooks

pytestmark = pytest.mark.site


@pytest.fixture(scope="module")
def site() -> Path:
    out = Path(os.environ.get("SCARA_PIN_SITE", ROOT / "site"))
    if not (out / "index.html").is_file():
        pytest.fail(f"no built site in {out}: run `make docs` (it builds the site, then runs these checks)")
    return out


def test_no_restructuredtext_role_in_the_site(site: Path) -> None:
    from mkdocs_hooks import surviving_roles

    assert surviving_roles(site) == []
    reference = (site / "reference" / "cycle.html").read_text(encoding="utf-8")
    # a role in a docstring became a link: jump_move's docstring names JumpMove
    assert re.search(r'<a class="autorefs autorefs-internal"[^>]*href="#scara_pin\.motion\.jump\.JumpMove"', reference)
    for page in ("calibration", "cycle"):  # the pages the issue missed
        assert (site / "reference" / f"{page}.html").is_file()


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
