"""Shared fixtures: the shipped robots, loaded once per test session.

The robots' ``data`` is overwritten by every kinematics call: tests may share them freely but must not
rely on ``robot.data`` between two calls.
"""

from __future__ import annotations

import os
import shutil
import tempfile

import numpy as np
import pytest
from browser import browser, page  # noqa: F401 - the headless Chromium fixtures (tests/browser.py), shared

from scara_pin import Robot, load_robot

_CACHE_ENV = ("SCARA_PIN_CACHE_DIR", "SCARA_PIN_NO_CACHE")
_saved_env: dict[str, str | None] = {}


def pytest_configure(config: pytest.Config) -> None:
    """The description cache (scara_pin.description.cache) of this test process in a folder of its own, never
    the user's ~/.cache; commands the tests run as subprocesses inherit it. Set before any test module loads."""
    _saved_env.update({k: os.environ.get(k) for k in _CACHE_ENV})
    os.environ["SCARA_PIN_CACHE_DIR"] = tempfile.mkdtemp(prefix="scara-pin-cache-")
    os.environ.pop("SCARA_PIN_NO_CACHE", None)


def pytest_unconfigure(config: pytest.Config) -> None:
    shutil.rmtree(os.environ["SCARA_PIN_CACHE_DIR"], ignore_errors=True)
    for k, v in _saved_env.items():
        if v is None:
            os.environ.pop(k, None)
        else:
            os.environ[k] = v


@pytest.fixture(autouse=True)
def _own_plan_cache(tmp_path_factory: pytest.TempPathFactory, monkeypatch: pytest.MonkeyPatch) -> None:
    """Each test's jobs in a plan cache of their own (scara_pin.job.cache): what one test planned never makes
    another's moves come from the cache. The description cache stays the session's (robots made once)."""
    from scara_pin.job.cache import PlanStore

    folder = tmp_path_factory.mktemp("plans")
    monkeypatch.setattr(PlanStore, "default", classmethod(lambda cls: cls(folder)))


@pytest.fixture(scope="session")
def robot_default() -> Robot:
    """The ``default`` robot (source S4: l1 = l2 = 0.200 m, tool 50 mm below the reference plane)."""
    return load_robot("default")


@pytest.fixture(scope="session")
def robot_s1() -> Robot:
    """The ``s1`` teaching robot (source S1: d1 = 0.100 m, l1 = 0.050 m, l2 = 0.150 m)."""
    return load_robot("s1")


@pytest.fixture(scope="session")
def robots(robot_default: Robot, robot_s1: Robot) -> dict[str, Robot]:
    """The shipped robots by name, for tests parametrized over robot names."""
    return {"default": robot_default, "s1": robot_s1}


@pytest.fixture
def rng() -> np.random.Generator:
    """A freshly seeded generator (the same numbers in every test that asks for it)."""
    return np.random.default_rng(20240611)

