"""Shared fixtures: the shipped robots, loaded once per test session.

The robots' ``data`` is overwritten by every kinematics call: tests may share them freely but must not
rely on ``robot.data`` between two calls.
"""

from __future__ import annotations

import numpy as np
import pytest
from browser import browser, page  # noqa: F401 - the headless Chromium fixtures (tests/browser.py), shared

from scara_pin import Robot, load_robot


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

