"""Headless Chromium for the browser tests: Debian's /usr/bin/chromium driven by Playwright's Python API.

Never downloads a browser (no ``playwright install``): ``executable_path`` points to the system chromium.
WebGL without a GPU comes from ANGLE's SwiftShader (``--use-angle=swiftshader``; ``--use-gl=swiftshader``
renders white). Each launch gets a fresh profile (``user_data_dir``: Playwright refuses a
``--user-data-dir`` argument, so the profile goes through ``launch_persistent_context``).
"""

from __future__ import annotations

import os
import shutil
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

import numpy as np
import pytest

CHROMIUM = os.environ.get("SCARA_PIN_CHROMIUM", "/usr/bin/chromium")

CHROMIUM_ARGS = (
    "--use-angle=swiftshader",
    "--enable-unsafe-swiftshader",
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--disable-dev-shm-usage",
    "--no-first-run",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
)

VIEWPORT = {"width": 800, "height": 600}

ROBOT_ORANGE = (0.95, 0.45, 0.10)
"""The links' colour (urdf/inc/materials.xacro, scara_orange)."""


def in_ci() -> bool:
    """True when the CI variable says so (then browser tests must run, never skip)."""
    return os.environ.get("CI", "").strip().lower() in {"1", "true", "yes"}


def unavailable_reason() -> str | None:
    """Why the browser tests cannot run here (None when they can): no chromium, or no Playwright."""
    if not (Path(CHROMIUM).is_file() or shutil.which(CHROMIUM)):
        return f"no Chromium at {CHROMIUM} (apt-get install chromium)"
    try:
        import playwright.sync_api  # noqa: F401
    except ImportError:
        return "Playwright's Python package is not installed (pip install playwright; no browser download)"
    return None


@contextmanager
def chromium(profile: Path) -> Iterator[Any]:
    """A headless Chromium browser context with a fresh profile in ``profile``; closed on exit."""
    from playwright.sync_api import sync_playwright

    with sync_playwright() as p:
        context = p.chromium.launch_persistent_context(
            str(profile),
            executable_path=CHROMIUM,
            args=list(CHROMIUM_ARGS),
            headless=True,
            viewport=VIEWPORT,
        )
        try:
            yield context
        finally:
            context.close()


def browser_for_tests(tmp_path_factory: Any) -> Iterator[Any]:
    """The body of the ``browser`` fixture: skipped only outside CI when Chromium or Playwright is
    absent; in CI, or when Chromium is there but cannot start, the tests fail."""
    import pytest

    reason = unavailable_reason()
    if reason is not None:
        if in_ci():
            pytest.fail(f"CI is set, so the browser tests must run, but: {reason}")
        pytest.skip(reason)
    with chromium(tmp_path_factory.mktemp("chromium-profile")) as context:
        yield context


def next_frames(page: Any, n: int = 3) -> None:
    """Let the page render ``n`` animation frames (meshcat renders on requestAnimationFrame when dirty)."""
    page.evaluate(
        """(n) => new Promise((done) => {
            const step = (k) => (k === 0 ? done() : requestAnimationFrame(() => step(k - 1)));
            step(n);
        })""",
        n,
    )


def orange_pixels(png: bytes | Path) -> int:
    """The number of pixels of the links' orange, lit or shaded (hue 15-35 degrees, saturated)."""
    import io

    from PIL import Image

    data = png.read_bytes() if isinstance(png, Path) else png
    rgb = np.asarray(Image.open(io.BytesIO(data)).convert("RGB")).astype(float)
    r, g, b = rgb[..., 0], rgb[..., 1], rgb[..., 2]
    # orange: red dominant, green about half of red, a little blue (0.95, 0.45, 0.10 -> g/r 0.47, b/r 0.11).
    # Blue exactly 0 is excluded: meshcat's and Pinocchio's axis lines fade from red to (1, 0.6, 0).
    ratio_g = np.divide(g, r, out=np.zeros_like(g), where=r > 0)
    ratio_b = np.divide(b, r, out=np.ones_like(b), where=r > 0)
    mask = (r > 60) & (ratio_g > 0.30) & (ratio_g < 0.62) & (ratio_b > 0.03) & (ratio_b < 0.30)
    return int(mask.sum())


def slate_pixels(png: bytes) -> int:
    """Pixels of the obstacles' slate blue (0x6A5ACD), lit or shaded, over any background: blue well above red and
    green, red at least green (unlike the tool path's dodger blue and the grey-blue floor), not the triads' blue."""
    import io

    from PIL import Image

    rgb = np.asarray(Image.open(io.BytesIO(png)).convert("RGB")).astype(float)
    r, g, b = rgb[..., 0], rgb[..., 1], rgb[..., 2]
    return int(((b > r + 40) & (b > g + 40) & (r >= g) & (r > 30)).sum())


@pytest.fixture(scope="session")
def browser(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Any]:
    """A headless Chromium context with a fresh profile, launched once per session (per pytest-xdist worker;
    each test gets its own page; conftest.py registers this fixture): see browser_for_tests."""
    yield from browser_for_tests(tmp_path_factory)


@pytest.fixture
def page(browser: Any) -> Iterator[Any]:
    """A new page of :func:`browser`; its uncaught errors collect in ``page.errors``."""
    p = browser.new_page()
    errors: list[str] = []
    p.on("pageerror", lambda exc: errors.append(str(exc)))
    p.errors = errors
    try:
        yield p
    finally:
        p.close()


@contextmanager
def busy_cores(n: int | None = None) -> Iterator[list[Any]]:
    """``n`` (default: every core) processes spinning at normal priority while the block runs, then killed by pid.

    Yields their ``psutil.Process`` objects, so a test can check they really took the CPU (``cpu_times``).
    """
    import subprocess
    import sys

    import psutil

    procs = []
    try:
        for _ in range(n or os.cpu_count() or 2):
            procs.append(subprocess.Popen([sys.executable, "-c", "while True: pass"]))
        yield [psutil.Process(p.pid) for p in procs]
    finally:
        for p in procs:
            p.kill()
        for p in procs:
            p.wait()


SLOW_FRAMES = """(ms) => {
    // every WebGL frame of meshcat's renderer takes at least ms more on the page's thread (a slow GPU)
    const renderer = viewer.renderer, render = renderer.render.bind(renderer);
    window.slowFrames = 0;
    renderer.render = (scene, camera) => {
        const t = performance.now();
        while (performance.now() - t < ms) {}
        render(scene, camera);
        window.slowFrames += 1;
    };
}"""
"""Made every frame slow by ``ms`` milliseconds of busy work on the page's main thread; frames counted in
``window.slowFrames``."""
