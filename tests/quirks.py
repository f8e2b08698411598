"""Helpers of the real-robot quirk tests (issue 21): numbers as typed, the CLI run, poses compared."""

from __future__ import annotations

import math

import numpy as np
import pytest

from scara_pin.cli import main


def texts(values: object) -> list[str]:
    """Numbers as a user types them (repr of a Python float: round-trips exactly)."""
    return [repr(float(v)) for v in values]  # type: ignore[attr-defined]


def run(capsys: pytest.CaptureFixture[str], argv: list[str]) -> tuple[int, str, str]:
    """``scara-pin argv``: (exit code, stdout, stderr); never a traceback."""
    rc = main(argv)
    out, err = capsys.readouterr()
    assert "Traceback" not in err
    return rc, out, err


def assert_pose(got: np.ndarray, expected: np.ndarray, tol: float = 1e-12) -> None:
    """(x, y, z, yaw) equal to ``tol`` [m, rad], the yaw modulo 2 pi."""
    np.testing.assert_allclose(got[:3], expected[:3], rtol=0, atol=tol)
    assert abs(math.remainder(got[3] - expected[3], 2 * math.pi)) <= tol
